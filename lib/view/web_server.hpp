// The small HTTP + WebSocket server of adit view (RFC 6455's handshake and framing on POSIX sockets, one
// thread, poll; the bytes are parsed by view/web_protocol.hpp): GET of the files in one folder (the page and
// three.js), 404 for any other path, and WebSocket clients on /ws that receive binary frames and may send
// short text messages. Nothing blocks on a
// client: sockets are non-blocking and each client's queue is bounded; when it is full the oldest frame
// not yet begun is dropped and counted (its tag is reported so that the caller can resend what it held).
#pragma once

#include "view/web_protocol.hpp"

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace adit::view {

struct WebServerOptions {
  std::string bind = "127.0.0.1";
  int port = 8080;                          // 0: any free port (tests)
  std::string web_root;                     // files served: plain names only, no sub-folders
  std::size_t max_queue_frames = 256;       // per client
  std::size_t max_queue_bytes = 8u << 20;   // per client
  std::size_t max_message_bytes = 1u << 16; // a client's text message; larger closes the connection
  std::vector<std::string> subprotocols;    // WebSocket subprotocols accepted (e.g. foxglove.websocket.v1)
};

struct WebServerCounters {
  std::int64_t http_requests = 0, not_found = 0, bad_requests = 0;
  std::int64_t clients_total = 0, frames_sent = 0, frames_dropped = 0, bytes_sent = 0;
};

class WebServer {
 public:
  explicit WebServer(WebServerOptions options);  // binds and listens; throws std::runtime_error
  ~WebServer();
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  int port() const { return port_; }

  // Serves for up to timeout_ms (accepts, reads requests and client frames, writes queues). Returns true when
  // `extra_fd` (e.g. LCM's socket) became readable.
  bool poll(int timeout_ms, int extra_fd = -1);

  // WebSocket clients connected now, by id (ids are never reused).
  std::vector<int> clients() const;
  // Queues a frame (binary, or text with opcode 1) for a client; `tag` comes back from takeDropped() if the
  // frame is dropped.
  void send(int client, const std::string& payload, int tag = -1, int opcode = 2);
  // The subprotocol the client chose among WebServerOptions::subprotocols ("" for none: adit's own page).
  std::string subprotocol(int client) const;
  // Bytes sent to the client so far (WebSocket frames, headers included), and bytes waiting in its queue.
  std::int64_t bytesSent(int client) const;
  std::size_t queuedBytes(int client) const;
  std::vector<std::pair<int, std::string>> takeMessages();  // (client, text) received
  std::vector<std::pair<int, int>> takeDropped();           // (client, tag) of dropped frames
  std::vector<int> takeClosed();                            // clients gone since the last call
  const WebServerCounters& counters() const { return counters_; }

 private:
  struct Connection;
  void accept();
  void readFrom(Connection& c);
  void handleHttp(Connection& c);
  void handleWebSocket(Connection& c);
  void respond(Connection& c, int status, const std::string& type, const std::string& body);
  void queue(Connection& c, std::string bytes, int tag, bool frame);
  void writeTo(Connection& c);
  void close(int fd);

  WebServerOptions options_;
  int listen_fd_ = -1;
  int port_ = 0;
  int next_client_ = 1;
  std::map<int, std::unique_ptr<Connection>> connections_;  // by fd
  std::vector<std::pair<int, std::string>> messages_;
  std::vector<std::pair<int, int>> dropped_;
  std::vector<int> closed_;
  WebServerCounters counters_;
};

}  // namespace adit::view
