#include "view/web_protocol.hpp"

#include "core/base64.hpp"

#include <openssl/evp.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <sstream>
#include <stdexcept>

namespace adit::view {
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t"), e = s.find_last_not_of(" \t\r");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

// A file name the server may serve: letters, digits, '.', '-', '_', not starting with '.'.
bool plainName(const std::string& name) {
  if (name.empty() || name.size() > 64 || name[0] == '.') return false;
  return std::all_of(name.begin(), name.end(), [](unsigned char c) { return std::isalnum(c) || c == '.' || c == '-' || c == '_'; });
}

HttpAnswer error(int status, const std::string& text) {
  HttpAnswer a;
  a.status = status;
  a.text = text;
  return a;
}

}  // namespace

Parse takeHttpRequest(std::string& in, HttpRequest& request) {
  const auto end = in.find("\r\n\r\n");
  if (end == std::string::npos) return in.size() > kMaxRequestBytes ? Parse::kBad : Parse::kIncomplete;
  if (end > kMaxRequestBytes) return Parse::kBad;
  std::istringstream head(in.substr(0, end + 2));
  in.erase(0, end + 4);
  request = HttpRequest{};
  std::string line;
  std::getline(head, line);
  std::istringstream(line) >> request.method >> request.path >> request.version;
  while (std::getline(head, line)) {
    const auto colon = line.find(':');
    if (colon != std::string::npos) request.headers[lower(trim(line.substr(0, colon)))] = trim(line.substr(colon + 1));
  }
  return Parse::kDone;
}

HttpAnswer answerRequest(const HttpRequest& request, const std::vector<std::string>& subprotocols) {
  if (request.method != "GET" || request.version.rfind("HTTP/1.", 0) != 0)
    return error(request.method.empty() ? 400 : 405, "only GET\n");
  const std::string path = request.path.substr(0, request.path.find('?'));
  const auto header = [&](const char* name) {
    const auto it = request.headers.find(name);
    return it == request.headers.end() ? std::string() : it->second;
  };
  if (path == "/ws") {
    const std::string key = header("sec-websocket-key");
    if (lower(header("upgrade")) != "websocket" || key.empty()) return error(400, "WebSocket upgrade expected\n");
    HttpAnswer a;
    a.status = 101;
    // A subprotocol the client offers and we speak (Sec-WebSocket-Protocol: a comma-separated list).
    std::istringstream offered(header("sec-websocket-protocol"));
    for (std::string p; std::getline(offered, p, ',');)
      if (a.subprotocol.empty() && std::count(subprotocols.begin(), subprotocols.end(), trim(p))) a.subprotocol = trim(p);
    a.handshake = "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Accept: " +
                  webSocketAccept(key) + "\r\n" +
                  (a.subprotocol.empty() ? "" : "Sec-WebSocket-Protocol: " + a.subprotocol + "\r\n") + "\r\n";
    return a;
  }
  const std::string name = path == "/" ? "index.html" : path.substr(std::min<std::size_t>(1, path.size()));
  if (path.empty() || path[0] != '/' || !plainName(name)) return error(404, "not found\n");
  HttpAnswer a;
  a.status = 200;
  a.file = name;
  return a;
}

Parse ClientFrameReader::next(std::string& in, ClientEvent& event) {
  for (;;) {
    if (in.size() < 2) return Parse::kIncomplete;
    const auto b0 = static_cast<std::uint8_t>(in[0]), b1 = static_cast<std::uint8_t>(in[1]);
    const bool fin = b0 & 0x80, masked = b1 & 0x80;
    const int opcode = b0 & 0x0F;
    std::uint64_t length = b1 & 0x7F;
    std::size_t pos = 2;
    if (length == 126 || length == 127) {
      const std::size_t bytes = length == 126 ? 2 : 8;
      if (in.size() < pos + bytes) return Parse::kIncomplete;
      length = 0;
      for (std::size_t i = 0; i < bytes; ++i) length = (length << 8) | static_cast<std::uint8_t>(in[pos + i]);
      pos += bytes;
    }
    // RFC 6455: a client's frames are masked; ours are short (checked before the length is used).
    if (!masked || length > max_message_ || fragments_.size() + length > max_message_) return Parse::kBad;
    if (in.size() < pos + 4 + length) return Parse::kIncomplete;
    const std::string mask = in.substr(pos, 4);
    std::string payload = in.substr(pos + 4, static_cast<std::size_t>(length));
    for (std::size_t i = 0; i < payload.size(); ++i) payload[i] = static_cast<char>(payload[i] ^ mask[i % 4]);
    in.erase(0, pos + 4 + static_cast<std::size_t>(length));
    if (opcode == 0x8 || opcode == 0x9) {
      event.kind = opcode == 0x8 ? ClientEvent::kClose : ClientEvent::kPing;
      event.payload = std::move(payload);
      return Parse::kDone;
    }
    if (opcode != 0x0 && opcode != 0x1 && opcode != 0x2) continue;  // pong and reserved opcodes: skipped
    fragments_ += payload;
    if (fin) {
      event.kind = ClientEvent::kMessage;
      event.payload = std::move(fragments_);
      fragments_.clear();
      return Parse::kDone;
    }
  }
}

std::string webSocketAccept(const std::string& key) {
  const std::string text = key + "258EAFA5-E914-47DA-95CA-C5AB0DC85B11";
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int length = 0;
  if (EVP_Digest(text.data(), text.size(), digest, &length, EVP_sha1(), nullptr) != 1)
    throw std::runtime_error("SHA-1 failed");
  return base64(std::string(reinterpret_cast<const char*>(digest), length));
}

std::string webSocketFrame(const std::string& payload, int opcode) {
  std::string f;
  f += static_cast<char>(0x80 | (opcode & 0x0F));
  const std::uint64_t n = payload.size();
  if (n < 126) {
    f += static_cast<char>(n);
  } else if (n <= 0xFFFF) {
    f += static_cast<char>(126);
    f += static_cast<char>((n >> 8) & 0xFF);
    f += static_cast<char>(n & 0xFF);
  } else {
    f += static_cast<char>(127);
    for (int i = 7; i >= 0; --i) f += static_cast<char>((n >> (8 * i)) & 0xFF);
  }
  return f + payload;
}

}  // namespace adit::view
