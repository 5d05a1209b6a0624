#include "view/web_server.hpp"

#include "core/base64.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <openssl/evp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace adit::view {
namespace {

constexpr std::size_t kMaxRequestBytes = 16384;

struct Outgoing {
  std::string bytes;
  int tag = -1;
  bool frame = false;  // a WebSocket frame (counted), not an HTTP response
};

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

std::string contentType(const std::string& name) {
  const auto dot = name.rfind('.');
  const std::string ext = dot == std::string::npos ? "" : name.substr(dot + 1);
  if (ext == "html") return "text/html; charset=utf-8";
  if (ext == "js" || ext == "mjs") return "text/javascript; charset=utf-8";
  if (ext == "css") return "text/css; charset=utf-8";
  if (ext == "png") return "image/png";
  return "application/octet-stream";
}

const char* statusText(int status) {
  switch (status) {
    case 101: return "Switching Protocols";
    case 200: return "OK";
    case 400: return "Bad Request";
    case 404: return "Not Found";
    case 405: return "Method Not Allowed";
    default: return "Error";
  }
}

void setNonBlocking(int fd) { ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL, 0) | O_NONBLOCK); }

}  // namespace

struct WebServer::Connection {
  int fd = -1;
  int client = 0;  // > 0 once a WebSocket
  std::string subprotocol;
  bool close_after_write = false;
  std::string in;
  std::string fragments;  // a fragmented client message so far
  std::deque<Outgoing> out;
  std::size_t out_offset = 0;  // bytes of out.front() already sent
  std::size_t queued_bytes = 0;
  std::int64_t bytes_sent = 0;
};

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

WebServer::WebServer(WebServerOptions options) : options_(std::move(options)) {
  listen_fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
  if (listen_fd_ < 0) throw std::runtime_error(std::string("socket: ") + std::strerror(errno));
  const int one = 1;
  ::setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(options_.port));
  if (::inet_pton(AF_INET, options_.bind.c_str(), &addr.sin_addr) != 1) {
    ::close(listen_fd_);
    throw std::runtime_error("--bind '" + options_.bind + "' is not an IPv4 address");
  }
  if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0 || ::listen(listen_fd_, 16) != 0) {
    const std::string why = std::strerror(errno);
    ::close(listen_fd_);
    throw std::runtime_error("cannot listen on " + options_.bind + ":" + std::to_string(options_.port) + ": " + why);
  }
  socklen_t len = sizeof(addr);
  ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len);
  port_ = ntohs(addr.sin_port);
  setNonBlocking(listen_fd_);
}

WebServer::~WebServer() {
  for (const auto& [fd, c] : connections_) ::close(fd);
  if (listen_fd_ >= 0) ::close(listen_fd_);
}

bool WebServer::poll(int timeout_ms, int extra_fd) {
  std::vector<pollfd> fds;
  fds.push_back({listen_fd_, POLLIN, 0});
  for (const auto& [fd, c] : connections_)
    fds.push_back({fd, static_cast<short>(POLLIN | (c->out.empty() ? 0 : POLLOUT)), 0});
  if (extra_fd >= 0) fds.push_back({extra_fd, POLLIN, 0});
  if (::poll(fds.data(), fds.size(), timeout_ms) <= 0) return false;
  bool extra = false;
  for (const pollfd& p : fds) {
    if (!p.revents) continue;
    if (p.fd == extra_fd) {
      extra = true;
    } else if (p.fd == listen_fd_) {
      accept();
    } else if (auto it = connections_.find(p.fd); it != connections_.end()) {
      Connection& c = *it->second;
      if (p.revents & (POLLERR | POLLHUP | POLLNVAL)) {
        close(p.fd);
        continue;
      }
      if (p.revents & POLLIN) readFrom(c);
      if (connections_.count(p.fd) && (p.revents & POLLOUT)) writeTo(c);
    }
  }
  return extra;
}

void WebServer::accept() {
  for (;;) {
    const int fd = ::accept(listen_fd_, nullptr, nullptr);
    if (fd < 0) return;
    setNonBlocking(fd);
    const int one = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
    auto c = std::make_unique<Connection>();
    c->fd = fd;
    connections_[fd] = std::move(c);
  }
}

void WebServer::readFrom(Connection& c) {
  char buf[65536];
  const ssize_t n = ::recv(c.fd, buf, sizeof(buf), 0);
  if (n <= 0) {
    if (n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK)) close(c.fd);
    return;
  }
  c.in.append(buf, static_cast<std::size_t>(n));
  const int fd = c.fd;
  if (c.client == 0) handleHttp(c);
  if (connections_.count(fd) && c.client > 0) handleWebSocket(c);
}

void WebServer::respond(Connection& c, int status, const std::string& type, const std::string& body) {
  std::ostringstream r;
  r << "HTTP/1.1 " << status << ' ' << statusText(status) << "\r\nContent-Type: " << type
    << "\r\nContent-Length: " << body.size() << "\r\nCache-Control: no-cache\r\nConnection: close\r\n\r\n" << body;
  c.close_after_write = true;
  queue(c, r.str(), -1, false);
}

void WebServer::handleHttp(Connection& c) {
  const auto end = c.in.find("\r\n\r\n");
  if (end == std::string::npos) {
    if (c.in.size() > kMaxRequestBytes) {
      ++counters_.bad_requests;
      respond(c, 400, "text/plain", "request too large\n");
    }
    return;
  }
  ++counters_.http_requests;
  std::istringstream request(c.in.substr(0, end + 2));
  c.in.erase(0, end + 4);
  std::string line, method, path, version;
  std::getline(request, line);
  std::istringstream(line) >> method >> path >> version;
  std::map<std::string, std::string> headers;
  while (std::getline(request, line)) {
    const auto colon = line.find(':');
    if (colon != std::string::npos) headers[lower(trim(line.substr(0, colon)))] = trim(line.substr(colon + 1));
  }
  if (method != "GET" || version.rfind("HTTP/1.", 0) != 0) {
    ++counters_.bad_requests;
    return respond(c, method.empty() ? 400 : 405, "text/plain", "only GET\n");
  }
  path = path.substr(0, path.find('?'));
  if (path == "/ws") {
    const std::string key = headers["sec-websocket-key"];
    if (lower(headers["upgrade"]) != "websocket" || key.empty()) {
      ++counters_.bad_requests;
      return respond(c, 400, "text/plain", "WebSocket upgrade expected\n");
    }
    // A subprotocol the client offers and we speak (Sec-WebSocket-Protocol: a comma-separated list).
    std::istringstream offered(headers["sec-websocket-protocol"]);
    for (std::string p; std::getline(offered, p, ',');)
      if (c.subprotocol.empty() && std::count(options_.subprotocols.begin(), options_.subprotocols.end(), trim(p)))
        c.subprotocol = trim(p);
    queue(c,
          "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Accept: " +
              webSocketAccept(key) + "\r\n" +
              (c.subprotocol.empty() ? "" : "Sec-WebSocket-Protocol: " + c.subprotocol + "\r\n") + "\r\n",
          -1, false);
    c.client = next_client_++;
    ++counters_.clients_total;
    return;
  }
  const std::string name = path == "/" ? "index.html" : path.substr(1);
  std::ifstream file(options_.web_root + "/" + name, std::ios::binary);
  if (!plainName(name) || !file) {
    ++counters_.not_found;
    return respond(c, 404, "text/plain", "not found\n");
  }
  std::ostringstream body;
  body << file.rdbuf();
  respond(c, 200, contentType(name), body.str());
}

void WebServer::handleWebSocket(Connection& c) {
  for (;;) {
    const std::string& b = c.in;
    if (b.size() < 2) return;
    const auto b0 = static_cast<std::uint8_t>(b[0]), b1 = static_cast<std::uint8_t>(b[1]);
    const bool fin = b0 & 0x80, masked = b1 & 0x80;
    const int opcode = b0 & 0x0F;
    std::uint64_t length = b1 & 0x7F;
    std::size_t pos = 2;
    if (length == 126 || length == 127) {
      const std::size_t bytes = length == 126 ? 2 : 8;
      if (b.size() < pos + bytes) return;
      length = 0;
      for (std::size_t i = 0; i < bytes; ++i) length = (length << 8) | static_cast<std::uint8_t>(b[pos + i]);
      pos += bytes;
    }
    if (!masked || length > options_.max_message_bytes || c.fragments.size() + length > options_.max_message_bytes) {
      ++counters_.bad_requests;  // RFC 6455: a client's frames are masked; ours are short
      return close(c.fd);
    }
    if (b.size() < pos + 4 + length) return;
    const std::string mask = b.substr(pos, 4);
    std::string payload = b.substr(pos + 4, static_cast<std::size_t>(length));
    for (std::size_t i = 0; i < payload.size(); ++i) payload[i] = static_cast<char>(payload[i] ^ mask[i % 4]);
    c.in.erase(0, pos + 4 + static_cast<std::size_t>(length));
    if (opcode == 0x8) {  // close: answer and end
      queue(c, webSocketFrame("", 0x8), -1, false);
      c.close_after_write = true;
      return;
    }
    if (opcode == 0x9) {
      queue(c, webSocketFrame(payload, 0xA), -1, false);
    } else if (opcode == 0x1 || opcode == 0x2 || opcode == 0x0) {
      c.fragments += payload;
      if (fin) {
        messages_.emplace_back(c.client, std::move(c.fragments));
        c.fragments.clear();
      }
    }
  }
}

void WebServer::queue(Connection& c, std::string bytes, int tag, bool frame) {
  c.queued_bytes += bytes.size();
  c.out.push_back({std::move(bytes), tag, frame});
  // Bounded: drop the oldest frames not yet begun (never the one half-written, never HTTP or control bytes).
  while (c.out.size() > options_.max_queue_frames || c.queued_bytes > options_.max_queue_bytes) {
    auto victim = std::find_if(c.out.begin() + (c.out_offset > 0 ? 1 : 0), c.out.end(), [](const Outgoing& o) { return o.frame; });
    if (victim == c.out.end() || &*victim == &c.out.back()) break;
    ++counters_.frames_dropped;
    if (victim->tag >= 0) dropped_.emplace_back(c.client, victim->tag);
    c.queued_bytes -= victim->bytes.size();
    c.out.erase(victim);
  }
  // Written by poll() when the socket can take it (writing here could close the connection under the caller).
}

void WebServer::send(int client, const std::string& payload, int tag, int opcode) {
  for (auto& [fd, c] : connections_)
    if (c->client == client && !c->close_after_write) return queue(*c, webSocketFrame(payload, opcode), tag, true);
}

std::string WebServer::subprotocol(int client) const {
  for (const auto& [fd, c] : connections_)
    if (c->client == client) return c->subprotocol;
  return "";
}

void WebServer::writeTo(Connection& c) {
  while (!c.out.empty()) {
    const std::string& bytes = c.out.front().bytes;
    const ssize_t n = ::send(c.fd, bytes.data() + c.out_offset, bytes.size() - c.out_offset, MSG_NOSIGNAL);
    if (n < 0) {
      if (errno != EAGAIN && errno != EWOULDBLOCK) close(c.fd);
      return;
    }
    c.out_offset += static_cast<std::size_t>(n);
    c.bytes_sent += n;
    counters_.bytes_sent += n;
    if (c.out_offset < bytes.size()) return;
    counters_.frames_sent += c.out.front().frame;
    c.queued_bytes -= bytes.size();
    c.out.pop_front();
    c.out_offset = 0;
  }
  if (c.close_after_write) close(c.fd);
}

void WebServer::close(int fd) {
  const auto it = connections_.find(fd);
  if (it == connections_.end()) return;
  if (it->second->client > 0) closed_.push_back(it->second->client);
  ::close(fd);
  connections_.erase(it);
}

std::vector<int> WebServer::clients() const {
  std::vector<int> ids;
  for (const auto& [fd, c] : connections_)
    if (c->client > 0 && !c->close_after_write) ids.push_back(c->client);
  std::sort(ids.begin(), ids.end());
  return ids;
}

std::int64_t WebServer::bytesSent(int client) const {
  for (const auto& [fd, c] : connections_)
    if (c->client == client) return c->bytes_sent;
  return 0;
}

std::size_t WebServer::queuedBytes(int client) const {
  for (const auto& [fd, c] : connections_)
    if (c->client == client) return c->queued_bytes;
  return 0;
}

std::vector<std::pair<int, std::string>> WebServer::takeMessages() { return std::exchange(messages_, {}); }
std::vector<std::pair<int, int>> WebServer::takeDropped() { return std::exchange(dropped_, {}); }
std::vector<int> WebServer::takeClosed() { return std::exchange(closed_, {}); }

}  // namespace adit::view
