// The byte-level half of adit view's web server (lib/view/web_server.*): a browser's HTTP request head, the
// answer it gets, and its WebSocket frames (RFC 6455), parsed from what a connection has received so far.
// No sockets here, so that the fuzz harness (tests/fuzz/fuzz_web_server.cpp) can feed it any bytes: any
// browser on the LAN can send them.
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace adit::view {

enum class Parse { kIncomplete, kDone, kBad };

constexpr std::size_t kMaxRequestBytes = 16384;  // a request head larger than this is refused

struct HttpRequest {
  std::string method, path, version;
  std::map<std::string, std::string> headers;  // names in lower case, values trimmed
};

// Takes one request head (through its blank line) from the front of `in`. kBad: no blank line within
// kMaxRequestBytes.
Parse takeHttpRequest(std::string& in, HttpRequest& request);

struct HttpAnswer {
  int status = 404;         // 101: WebSocket upgrade, 200: serve `file`, else an error with `text`
  std::string file;         // 200: a plain file name of the web root (no separators, no leading dot)
  std::string subprotocol;  // 101: the one chosen among those offered, "" for none
  std::string handshake;    // 101: the whole response head
  std::string text;         // errors: a one-line body
};

// What to answer: GET of a plain file name ("/" is index.html), GET /ws with an upgrade, else an error.
HttpAnswer answerRequest(const HttpRequest& request, const std::vector<std::string>& subprotocols);

struct ClientEvent {
  enum Kind { kMessage, kPing, kClose } kind = kMessage;
  std::string payload;  // unmasked; a message's fragments joined
};

// A connection's client frames as events: data frames (text, binary, continuation) joined into messages of
// at most `max_message` bytes, pings and closes passed on, other opcodes skipped.
class ClientFrameReader {
 public:
  explicit ClientFrameReader(std::size_t max_message) : max_message_(max_message) {}
  // The next event from the front of `in`: kIncomplete (wait for more bytes), kDone (event filled) or kBad
  // (an unmasked frame, RFC 6455 5.1, or a message over max_message: close the connection).
  Parse next(std::string& in, ClientEvent& event);

 private:
  std::size_t max_message_;
  std::string fragments_;  // a fragmented message so far
};

// Sec-WebSocket-Accept for a Sec-WebSocket-Key (RFC 6455 4.2.2: base64 of SHA-1 of key + the fixed GUID).
std::string webSocketAccept(const std::string& key);
// A server-to-client frame (unmasked, FIN) with opcode 2 (binary), 1 (text), 8 (close), 10 (pong).
std::string webSocketFrame(const std::string& payload, int opcode = 2);

}  // namespace adit::view
