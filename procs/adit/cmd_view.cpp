// adit view [--lcm-url URL] [--port 8080] [--bind 127.0.0.1] [--log run.lcmlog ...] [--allow-commands]:
// a web page (three.js, served from build/share/adit/view) showing the run live from LCM or from logs with a
// time slider. The server and the stream: lib/view/. Read-only unless --allow-commands (then save_map only).
#include "commands.hpp"

#include "foxglove/foxglove_ws.hpp"
#include "msg/encode.hpp"
#include "runtime/command_auth.hpp"
#include "runtime/command_message.hpp"
#include "runtime/process.hpp"
#include "runtime/run_folder.hpp"
#include "view/log_player.hpp"
#include "view/page_command.hpp"
#include "view/view_session.hpp"

#include <adit/command_t.hpp>
#include <fmt/format.h>
#include <lcm/lcm-cpp.hpp>
#include <spdlog/spdlog.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <sstream>

namespace {

struct ViewArgs {
  std::string lcm_url;
  std::vector<std::string> logs;
  std::string bind = "127.0.0.1";
  int port = 8080;
  std::string web_root;
  double speed = 1.0;
  bool paused = false;
  bool allow_commands = false;
  std::string key_path;  // signs the page's commands (--command-key, else $ADIT_COMMAND_KEY)
  double duration_s = 0;
  adit::view::ViewOptions view;
  bool foxglove = false;
  int foxglove_sweep_every = 10;
};

using Clock = std::chrono::steady_clock;

void onMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel, adit::view::RunConsumer* consumer) {
  consumer->apply(channel, static_cast<const std::uint8_t*>(rbuf->data), rbuf->data_size, rbuf->recv_utime);
}

// save_map [NAME] from the page, only with --allow-commands and only a plain file name (the receiver's rule).
// Signed with the key at key_path when there is one (processes started with a command key obey only those).
std::string saveMap(lcm::LCM* lcm, const std::vector<std::string>& arguments, const std::string& key_path) {
  if (!lcm) return "save_map needs a live run (not --log)";
  if (arguments.size() > 1) return "save_map takes one plain file name, got " + std::to_string(arguments.size()) + " words";
  const std::string name = arguments.empty() ? "" : arguments.front();
  if (!name.empty())
    if (const std::string problem = adit::runtime::plainFileNameProblem(name); !problem.empty())
      return "save_map '" + name + "': " + problem;
  const adit::command_t c =
      adit::runtime::makeCommand("MAPPER_COMMAND", "save_map", name, key_path, adit::runtime::wallUtime());
  const auto bytes = adit::msg::encode(c);
  lcm->publish("MAPPER_COMMAND", bytes.data(), static_cast<unsigned int>(bytes.size()));
  return "";
}

void handleCommands(adit::view::WebServer& server, adit::view::RunConsumer& consumer, adit::view::LogPlayer* player,
                    adit::foxglove::FoxgloveWs* foxglove, lcm::LCM* lcm, bool allow_commands,
                    const std::string& key_path) {
  for (const auto& [client, text] : server.takeMessages()) {
    if (foxglove && foxglove->message(client, text)) continue;  // a Foxglove client's subscriptions
    if (player && player->command(text, consumer)) continue;   // playback of the viewer's own log
    const auto save_map = allow_commands ? adit::view::saveMapArguments(text) : std::nullopt;
    if (save_map) {
      const std::string error = saveMap(lcm, *save_map, key_path);
      if (error.empty()) {
        spdlog::info("client {}: sent {}", client, text);
      } else {
        spdlog::warn("client {}: {}", client, error);
      }
      continue;
    }
    spdlog::warn("client {}: command refused ('{}'): {}", client, text.substr(0, 80),
                 allow_commands ? "unknown command" : "the page is read-only (start with --allow-commands)");
  }
}

void runView(const ViewArgs& a) {
  adit::view::WebServerOptions web;
  web.bind = a.bind;
  web.port = a.port;
  web.web_root = a.web_root.empty() ? executableDir() + "/../share/adit/view" : a.web_root;
  if (!std::filesystem::exists(web.web_root + "/three.module.js"))
    spdlog::warn("three.js is missing from {} (the build installs it with npm): the page cannot draw", web.web_root);
  if (a.foxglove) web.subprotocols.push_back(adit::foxglove::kFoxgloveSubprotocol);
  adit::view::WebServer server(web);
  adit::view::ViewSession session(server, a.view);
  adit::view::Fanout consumers;
  consumers.add(session);
  std::unique_ptr<adit::foxglove::FoxgloveWs> foxglove;
  if (a.foxglove) {
    adit::foxglove::ExportOptions options;
    options.sweep_every = a.foxglove_sweep_every;
    foxglove = std::make_unique<adit::foxglove::FoxgloveWs>(server, options);
    consumers.add(*foxglove);
  }
  std::unique_ptr<adit::view::LogPlayer> player;
  std::unique_ptr<lcm::LCM> lcm;
  if (!a.logs.empty()) {
    player = std::make_unique<adit::view::LogPlayer>(a.logs, a.speed, !a.paused);
  } else {
    lcm = std::make_unique<lcm::LCM>(a.lcm_url);
    if (!lcm->good()) throw std::runtime_error("cannot open LCM '" + a.lcm_url + "'");
    lcm->subscribeFunction(".*", &onMessage, static_cast<adit::view::RunConsumer*>(&consumers));
  }
  spdlog::info("adit view on http://{}:{}/ ({}{})", a.bind, server.port(),
               player ? fmt::format("{} log(s), {:.1f} s", a.logs.size(), player->duration()) : "live LCM",
               a.bind == "127.0.0.1" ? "; this computer only: --bind 0.0.0.0 serves the LAN" : "; read-only");
  // The key is read now, so a bad key file is an error at start, not when the operator presses save.
  const std::string key_path = a.allow_commands ? adit::runtime::commandKeyPath(a.key_path) : std::string();
  if (!key_path.empty()) {
    adit::runtime::readCommandKey(key_path);
    spdlog::info("the page's commands are signed with {}", key_path);
  }
  adit::runtime::installStopHandlers();
  const std::string commands_json = a.allow_commands ? "\"commands_allowed\":true" : "";
  const auto start = Clock::now();
  auto last = start, last_report = start;
  while (!adit::runtime::stopRequested()) {
    const bool lcm_ready = server.poll(20, lcm ? lcm->getFileno() : -1);
    if (lcm_ready)
      while (lcm->handleTimeout(0) > 0) {
      }
    const auto now = Clock::now();
    const double dt = std::chrono::duration<double>(now - last).count(), elapsed = std::chrono::duration<double>(now - start).count();
    last = now;
    if (player) player->advance(dt, consumers);
    for (const int client : server.takeClosed()) {
      session.forget(client);
      if (foxglove) foxglove->forget(client);
    }
    if (foxglove) foxglove->tick();
    handleCommands(server, consumers, player.get(), foxglove.get(), lcm.get(), a.allow_commands, key_path);
    session.tick(elapsed, player ? player->infoJson() : commands_json);
    if (now - last_report >= std::chrono::seconds(10)) {
      const auto& c = server.counters();
      spdlog::info("{} client(s); sent {:.2f} MB ({:.3f} MB/s since start), {} frame(s) dropped; {} malformed message(s)",
                   server.clients().size(), static_cast<double>(c.bytes_sent) / 1e6,
                   static_cast<double>(c.bytes_sent) / 1e6 / elapsed, c.frames_dropped, session.decodeCounts().malformed);
      last_report = now;
    }
    if (a.duration_s > 0 && elapsed >= a.duration_s) break;
  }
  const auto& c = server.counters();
  const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  fmt::print("adit view: {} client(s) served, {:.2f} MB sent in {:.1f} s ({:.3f} MB/s), {} frame(s) dropped, {} HTTP "
             "request(s) ({} not found), {} malformed message(s) skipped\n",
             c.clients_total, static_cast<double>(c.bytes_sent) / 1e6, elapsed,
             static_cast<double>(c.bytes_sent) / 1e6 / elapsed, c.frames_dropped, c.http_requests, c.not_found,
             session.decodeCounts().malformed);
}

}  // namespace

void registerViewCommand(CLI::App& app) {
  auto a = std::make_shared<ViewArgs>();
  auto* cmd = app.add_subcommand("view", "Watch a run in a web browser (map, sweep, trajectories, loops, STATUS), live or from logs");
  cmd->add_option("--lcm-url", a->lcm_url, "LCM provider (default: $LCM_DEFAULT_URL or udpm)");
  auto* log = cmd->add_option("--log", a->logs, "Play these LCM logs (merged by time) instead of listening; repeatable")
                  ->check(CLI::ExistingFile);
  cmd->add_option("--port", a->port, "HTTP port")->check(CLI::Range(0, 65535))->capture_default_str();
  cmd->add_option("--bind", a->bind, "Address to serve on: 127.0.0.1 this computer only, 0.0.0.0 every network")
      ->capture_default_str();
  cmd->add_option("--speed", a->speed, "With --log: playback speed")->check(CLI::Range(0.1, 50.0))->needs(log)->capture_default_str();
  cmd->add_flag("--paused", a->paused, "With --log: start paused")->needs(log);
  cmd->add_flag("--allow-commands", a->allow_commands, "Let the page send save_map NAME (a plain file name) on MAPPER_COMMAND");
  cmd->add_option("--command-key", a->key_path,
                  "With --allow-commands: sign them with this key file (default: $ADIT_COMMAND_KEY, else unsigned)");
  cmd->add_option("--sweep-points", a->view.sweep_points, "Points of a sweep sent to the page")->capture_default_str();
  cmd->add_option("--sweep-rate", a->view.sweep_rate_hz, "Sweeps sent per second at most")->check(CLI::Range(0.1, 50.0))->capture_default_str();
  cmd->add_option("--web-root", a->web_root, "Folder of the page (default: <bin>/../share/adit/view)");
  cmd->add_option("--duration", a->duration_s, "Stop after this many seconds (measurements, tests)");
  cmd->add_flag("--foxglove", a->foxglove,
                "Also speak the Foxglove WebSocket protocol on the same port (Foxglove / Lichtblick: open ws://HOST:PORT/ws)");
  cmd->add_option("--foxglove-sweep-every", a->foxglove_sweep_every, "With --foxglove: send every n-th sweep (JSON sweeps are ~0.6 MB)")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  cmd->callback([a] { runView(*a); });
}
