#include "view/web_server.hpp"


#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
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

struct Outgoing {
  std::string bytes;
  int tag = -1;
  bool frame = false;  // a WebSocket frame (counted), not an HTTP response
};

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
  explicit Connection(std::size_t max_message) : frames(max_message) {}
  int fd = -1;
  int client = 0;  // > 0 once a WebSocket
  std::string subprotocol;
  bool close_after_write = false;  // answered for the last time: what the client sends now is ignored
  std::string in;
  ClientFrameReader frames;
  std::deque<Outgoing> out;
  std::size_t out_offset = 0;  // bytes of out.front() already sent
  std::size_t queued_bytes = 0;
  std::int64_t bytes_sent = 0;
};

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
    auto c = std::make_unique<Connection>(options_.max_message_bytes);
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
  if (c.close_after_write) return;  // answered for the last time (an error, a close): input is dropped
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
  c.in.clear();
  queue(c, r.str(), -1, false);
}

void WebServer::handleHttp(Connection& c) {
  HttpRequest request;
  const Parse parsed = takeHttpRequest(c.in, request);
  if (parsed == Parse::kIncomplete) return;
  if (parsed == Parse::kBad) {
    ++counters_.bad_requests;
    return respond(c, 400, "text/plain", "request too large\n");
  }
  ++counters_.http_requests;
  const HttpAnswer answer = answerRequest(request, options_.subprotocols);
  if (answer.status == 101) {
    c.subprotocol = answer.subprotocol;
    queue(c, answer.handshake, -1, false);
    c.client = next_client_++;
    ++counters_.clients_total;
    return;
  }
  std::ifstream file;
  if (answer.status == 200) file.open(options_.web_root + "/" + answer.file, std::ios::binary);
  if (answer.status == 404 || (answer.status == 200 && !file)) {
    ++counters_.not_found;
    return respond(c, 404, "text/plain", "not found\n");
  }
  if (answer.status != 200) {
    ++counters_.bad_requests;
    return respond(c, answer.status, "text/plain", answer.text);
  }
  std::ostringstream body;
  body << file.rdbuf();
  respond(c, 200, contentType(answer.file), body.str());
}

void WebServer::handleWebSocket(Connection& c) {
  ClientEvent event;
  for (;;) {
    const Parse parsed = c.frames.next(c.in, event);
    if (parsed == Parse::kIncomplete) return;
    if (parsed == Parse::kBad) {
      ++counters_.bad_requests;
      return close(c.fd);
    }
    if (event.kind == ClientEvent::kClose) {  // answer and end
      queue(c, webSocketFrame("", 0x8), -1, false);
      c.close_after_write = true;
      c.in.clear();
      return;
    }
    if (event.kind == ClientEvent::kPing) {
      // Pongs are not dropped like frames: a client that pings without reading is closed instead.
      if (c.queued_bytes > options_.max_queue_bytes) {
        ++counters_.bad_requests;
        return close(c.fd);
      }
      queue(c, webSocketFrame(event.payload, 0xA), -1, false);
    } else {
      messages_.emplace_back(c.client, std::move(event.payload));
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
