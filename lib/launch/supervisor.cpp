#include "launch/supervisor.hpp"

#include "runtime/process.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <signal.h>
#include <sys/statvfs.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <thread>

namespace adit::launch {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// Seconds as a Clock duration (steady_clock arithmetic with duration<double> yields a different time_point type).
Clock::duration seconds(double s) { return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s)); }

namespace {

struct Child {
  ProcessSpec spec;
  pid_t pid = -1;
  int fd = -1;  // read end of the child's stdout+stderr
  std::string partial;
  std::ofstream log;
  RestartPolicy policy;
  int restarts = 0;  // starts after the first (ADIT_RESTART_COUNT)
  bool recorder = false;  // its last argument is replaced by the next free record*.lcmlog on each start
  Clock::time_point started, next_start;
  bool finished = false;  // exited and will not be restarted
};

void say(const std::string& line) {
  std::fprintf(stdout, "[launch] %s\n", line.c_str());
  std::fflush(stdout);
}

std::string resolve(const std::string& program, const std::string& bin_dir) {
  if (program.find('/') == std::string::npos && (program == "adit" || program.rfind("adit-", 0) == 0)) {
    const fs::path candidate = fs::path(bin_dir) / program;
    if (fs::exists(candidate)) return candidate.string();
  }
  return program;
}

bool start(Child& c, const LaunchSpec& spec, const SupervisorOptions& options) {
  if (c.recorder) c.spec.command.back() = nextRecordPath(options.run_dir);
  int fds[2];
  if (::pipe(fds) != 0) return false;
  const pid_t pid = ::fork();
  if (pid < 0) return false;
  if (pid == 0) {
    ::setpgid(0, 0);  // own process group: the terminal's Ctrl-C reaches only the supervisor, which stops us in order
    ::dup2(fds[1], STDOUT_FILENO);
    ::dup2(fds[1], STDERR_FILENO);
    ::close(fds[0]);
    ::close(fds[1]);
    if (!spec.lcm_url.empty()) ::setenv("LCM_DEFAULT_URL", spec.lcm_url.c_str(), 1);
    ::setenv("ADIT_RUN_DIR", options.run_dir.c_str(), 1);
    ::setenv("ADIT_PROCESS_NAME", c.spec.name.c_str(), 1);
    ::setenv("ADIT_RESTART_COUNT", std::to_string(c.restarts).c_str(), 1);
    // adit's own programs first, also for commands run through a shell.
    const char* path = std::getenv("PATH");
    ::setenv("PATH", (options.bin_dir + ":" + (path ? path : "/usr/bin:/bin")).c_str(), 1);
    std::vector<std::string> argv = c.spec.command;
    argv[0] = resolve(argv[0], options.bin_dir);
    std::vector<char*> cargv;
    for (auto& a : argv) cargv.push_back(a.data());
    cargv.push_back(nullptr);
    ::execvp(cargv[0], cargv.data());
    std::fprintf(stderr, "cannot start '%s': %s\n", cargv[0], std::strerror(errno));
    ::_exit(127);
  }
  ::close(fds[1]);
  ::fcntl(fds[0], F_SETFL, O_NONBLOCK);
  c.pid = pid;
  c.fd = fds[0];
  c.started = Clock::now();
  say(fmt::format("started {} (pid {}{}{})", c.spec.name, pid,
                  c.restarts > 0 ? fmt::format(", restart {}", c.restarts) : "",
                  c.recorder ? ", writing " + fs::path(c.spec.command.back()).filename().string() : ""));
  return true;
}

void emitLine(Child& c, const std::string& line, bool echo) {
  c.log << line << '\n';
  c.log.flush();
  if (echo) std::fprintf(stdout, "[%s] %s\n", c.spec.name.c_str(), line.c_str());
}

void drain(Child& c, bool echo) {
  char buf[4096];
  while (c.fd >= 0) {
    const ssize_t n = ::read(c.fd, buf, sizeof buf);
    if (n > 0) {
      c.partial.append(buf, static_cast<std::size_t>(n));
      std::size_t nl;
      while ((nl = c.partial.find('\n')) != std::string::npos) {
        emitLine(c, c.partial.substr(0, nl), echo);
        c.partial.erase(0, nl + 1);
      }
    } else if (n == 0 || (errno != EAGAIN && errno != EINTR)) {
      if (!c.partial.empty()) emitLine(c, c.partial, echo);
      c.partial.clear();
      ::close(c.fd);
      c.fd = -1;
    } else {
      break;
    }
  }
  std::fflush(stdout);
}

std::string describe(int status) {
  if (WIFEXITED(status)) return "exited with code " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return std::string("killed by signal ") + ::strsignal(WTERMSIG(status));
  return "stopped";
}

// Free space of the run folder's file system, for the message when the recorder ends (a full disk is the
// usual reason it cannot go on).
std::string diskNote(const std::string& dir) {
  struct statvfs st {};
  if (::statvfs(dir.c_str(), &st) != 0) return "";
  const double free_mb = static_cast<double>(st.f_bavail) * static_cast<double>(st.f_frsize) / 1e6;
  return free_mb < 1.0 ? fmt::format(" (the run folder's disk is full: {:.2f} MB free)", free_mb)
                       : fmt::format(" ({:.0f} MB free in the run folder)", free_mb);
}

bool wantsRestart(const Child& c, int status) {
  const bool clean = WIFEXITED(status) && WEXITSTATUS(status) == 0;
  switch (c.spec.restart) {
    case Restart::Never: return false;
    case Restart::OnFailure: return !clean;
    case Restart::Always: return true;
  }
  return false;
}

void stopAll(std::vector<Child>& children, const SupervisorOptions& options) {
  // Reverse start order: the recorder (started first) stops last and sees everything.
  for (auto it = children.rbegin(); it != children.rend(); ++it) {
    Child& c = *it;
    if (c.pid <= 0) continue;
    ::kill(c.pid, SIGINT);
    const auto deadline = Clock::now() + seconds(options.stop_timeout_s);
    int status = 0;
    while (::waitpid(c.pid, &status, WNOHANG) == 0) {
      drain(c, options.echo);
      if (Clock::now() > deadline) {
        say(fmt::format("{} did not stop within {:g} s: killing it", c.spec.name, options.stop_timeout_s));
        ::kill(c.pid, SIGKILL);
        ::waitpid(c.pid, &status, 0);
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    drain(c, options.echo);
    say("stopped " + c.spec.name + " (" + describe(status) + ")");
    c.pid = -1;
  }
}

}  // namespace

std::string nextRecordPath(const std::string& run_dir) {
  for (int i = 0;; ++i) {
    const fs::path p = fs::path(run_dir) / (i == 0 ? std::string("record.lcmlog") : fmt::format("record.{}.lcmlog", i));
    std::error_code ec;
    if (!fs::exists(p, ec)) return p.string();
  }
}

namespace {

bool isStopWhenExit(const LaunchSpec& spec, const std::string& name) {
  return std::find(spec.stop_when_exit.begin(), spec.stop_when_exit.end(), name) != spec.stop_when_exit.end();
}

bool cleanExit(int status) { return WIFEXITED(status) && WEXITSTATUS(status) == 0; }

// Decides what follows the exit of `c`; returns a failure of the run to report at the end, or "".
std::string onExit(Child& c, int status, const LaunchSpec& spec, const SupervisorOptions& options,
                   std::optional<Clock::time_point>& stop_at, Clock::time_point run_start) {
  const auto now = Clock::now();
  const double ran_s = std::chrono::duration<double>(now - c.started).count();
  const std::string how = describe(status) + (c.recorder ? diskNote(options.run_dir) : "");
  if (isStopWhenExit(spec, c.spec.name)) {
    say(fmt::format("{} {}: ending the run in {:g} s", c.spec.name, how, spec.grace_s));
    c.finished = true;
    const auto end = now + seconds(spec.grace_s);
    if (!stop_at || end < *stop_at) stop_at = end;
    return cleanExit(status) ? "" : fmt::format("{} {}, which ends the run", c.spec.name, how);
  }
  if (!wantsRestart(c, status)) {
    say(c.spec.name + " " + how + ": not restarting");
    c.finished = true;
    return cleanExit(status) ? "" : fmt::format("{} {} (restart: never)", c.spec.name, how);
  }
  const auto delay = c.policy.onExit(std::chrono::duration<double>(now - run_start).count(), ran_s);
  if (!delay) {
    const auto& l = c.policy.limits();
    const std::string why = fmt::format("{} gave up: {} exits within {:g} s (max_restarts {}), the last one {}",
                                        c.spec.name, c.policy.exitsInWindow(), l.window_s, l.max_restarts, how);
    say(why + "; the other processes keep running");
    c.finished = true;
    return why;
  }
  say(fmt::format("{} {}: restarting in {:g} s ({} of at most {} exits within {:g} s)", c.spec.name, how, *delay,
                  c.policy.exitsInWindow(), c.policy.limits().max_restarts, c.policy.limits().window_s));
  c.next_start = now + seconds(*delay);
  ++c.restarts;
  return "";
}

}  // namespace

int supervise(const LaunchSpec& spec, const SupervisorOptions& options) {
  fs::create_directories(options.run_dir);
  std::vector<Child> children;
  if (!spec.record_channels.empty()) {
    Child rec;
    // -f is never given: the path is always new (nextRecordPath), and lcm-logger refuses to overwrite.
    rec.spec.name = "recorder";
    rec.spec.command = {"lcm-logger", "-q", "-c", spec.record_channels, "record.lcmlog"};
    rec.spec.restart = Restart::OnFailure;
    rec.policy = RestartPolicy(spec.recorder_limits);
    rec.recorder = true;
    children.push_back(std::move(rec));
  }
  for (const auto& p : spec.processes) {
    Child c;
    c.spec = p;
    c.policy = RestartPolicy(p.limits);
    children.push_back(std::move(c));
  }
  runtime::installStopHandlers();
  for (auto& c : children) {
    if (c.spec.delay_s > 0) std::this_thread::sleep_for(seconds(c.spec.delay_s));
    c.log.open(fs::path(options.run_dir) / (c.spec.name + ".log"), std::ios::app);
    if (!start(c, spec, options)) {
      say("cannot start " + c.spec.name + ": " + std::strerror(errno));
      stopAll(children, options);
      return kRunCannotStart;
    }
    if (c.recorder) std::this_thread::sleep_for(std::chrono::milliseconds(300));  // subscribed before data flows
  }

  const auto run_start = Clock::now();
  std::optional<Clock::time_point> stop_at;
  if (options.duration_s > 0) stop_at = run_start + seconds(options.duration_s);
  std::vector<std::string> failures;
  while (!runtime::stopRequested() && !(stop_at && Clock::now() >= *stop_at)) {
    std::vector<pollfd> pfds;
    for (auto& c : children)
      if (c.fd >= 0) pfds.push_back({c.fd, POLLIN, 0});
    ::poll(pfds.data(), pfds.size(), 100);
    for (auto& c : children) drain(c, options.echo);

    int status = 0;
    pid_t pid;
    while ((pid = ::waitpid(-1, &status, WNOHANG)) > 0) {
      auto it = std::find_if(children.begin(), children.end(), [pid](const Child& c) { return c.pid == pid; });
      if (it == children.end()) continue;
      drain(*it, options.echo);
      it->pid = -1;
      if (auto failure = onExit(*it, status, spec, options, stop_at, run_start); !failure.empty())
        failures.push_back(std::move(failure));
    }
    for (auto& c : children)
      if (c.pid < 0 && !c.finished && Clock::now() >= c.next_start && c.fd < 0) start(c, spec, options);
  }
  say(runtime::stopRequested() ? "interrupted: stopping" : "run complete: stopping");
  stopAll(children, options);
  if (failures.empty()) {
    say("run ended as planned");
    return kRunOk;
  }
  for (std::size_t i = 0; i + 1 < failures.size(); ++i) say("failed: " + failures[i]);
  say(fmt::format("run failed ({} problem{}): {}", failures.size(), failures.size() > 1 ? "s" : "", failures.back()));
  return kRunFailed;
}

}  // namespace adit::launch
