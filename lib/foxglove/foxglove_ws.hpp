// adit view --foxglove: the run's Foxglove channels (foxglove_run.hpp) over the Foxglove WebSocket protocol
// (subprotocol foxglove.websocket.v1), so that Foxglove and Lichtblick connect to a live robot: on connect a
// serverInfo and an advertise of every channel known (JSON text frames); new channels advertised as they
// appear; the client subscribes and unsubscribes; each message goes to its subscribers as a binary frame
// (opcode 1, u32 subscription id, u64 log time in ns, the JSON message). Same queues and drops as the page.
#pragma once

#include "foxglove/foxglove_run.hpp"
#include "view/run_consumer.hpp"
#include "view/web_server.hpp"

#include <map>
#include <memory>
#include <string>

namespace adit::foxglove {

constexpr const char* kFoxgloveSubprotocol = "foxglove.websocket.v1";

class FoxgloveWs : public view::RunConsumer, private FoxgloveSink {
 public:
  FoxgloveWs(view::WebServer& server, ExportOptions options);

  void apply(const std::string& channel, const std::uint8_t* data, std::size_t size, std::int64_t utime) override;
  void reset() override;
  // Greets new Foxglove clients; forgets closed ones (call with WebServer::takeClosed()'s ids).
  void tick();
  void forget(int client) { clients_.erase(client); }
  // A text message of a Foxglove client: subscribe / unsubscribe (others are ignored). False if not ours.
  bool message(int client, const std::string& text);

 private:
  struct Channel {
    int id = 0;
    SchemaText schema;
  };
  struct Client {
    std::map<std::uint32_t, int> subscriptions;  // subscription id -> channel id
  };
  void publish(const std::string& topic, const SchemaText& schema, const std::string& json, std::uint64_t log_ns) override;
  std::string advertise(const std::string& topic, const Channel& channel) const;

  view::WebServer& server_;
  ExportOptions options_;
  std::unique_ptr<FoxgloveRun> run_;
  std::map<std::string, Channel> channels_;  // by topic
  std::map<int, Client> clients_;
};

}  // namespace adit::foxglove
