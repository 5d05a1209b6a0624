// A minimal WebSocket client for the view tests: connects to the server under test (which the test drives
// through WebServer::poll in the same thread), upgrades on /ws and reads the server's unmasked binary frames.
#pragma once

#include "view/web_server.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <string>
#include <vector>

namespace adit::test {

class WsClient {
 public:
  WsClient(view::WebServer& server, int port) : server_(server) {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<std::uint16_t>(port));
    ::inet_pton(AF_INET, "127.0.0.1", &a.sin_addr);
    ok_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof(a)) == 0;
    const std::string request =
        "GET /ws HTTP/1.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n";
    ok_ = ok_ && ::send(fd_, request.data(), request.size(), 0) == static_cast<ssize_t>(request.size());
    for (int i = 0; i < 100 && ok_ && buffer_.find("\r\n\r\n") == std::string::npos; ++i) pump(10);
    const auto end = buffer_.find("\r\n\r\n");
    ok_ = ok_ && end != std::string::npos && buffer_.find("101") != std::string::npos;
    if (ok_) buffer_.erase(0, end + 4);
  }
  ~WsClient() { ::close(fd_); }
  bool ok() const { return ok_; }

  // Serves and reads for `ms`, returning the whole frames' payloads received.
  std::vector<std::string> frames(int ms) {
    pump(ms);
    std::vector<std::string> out;
    for (;;) {
      if (buffer_.size() < 2) break;
      std::uint64_t n = static_cast<std::uint8_t>(buffer_[1]) & 0x7F;
      std::size_t pos = 2;
      if (n >= 126) {
        const std::size_t bytes = n == 126 ? 2 : 8;
        if (buffer_.size() < pos + bytes) break;
        n = 0;
        for (std::size_t i = 0; i < bytes; ++i) n = (n << 8) | static_cast<std::uint8_t>(buffer_[pos + i]);
        pos += bytes;
      }
      if (buffer_.size() < pos + n) break;
      out.push_back(buffer_.substr(pos, static_cast<std::size_t>(n)));
      buffer_.erase(0, pos + static_cast<std::size_t>(n));
    }
    return out;
  }

 private:
  void pump(int ms) {
    for (int i = 0; i < ms; ++i) {
      server_.poll(1);
      char buf[65536];
      ssize_t n;
      while ((n = ::recv(fd_, buf, sizeof(buf), MSG_DONTWAIT)) > 0) buffer_.append(buf, static_cast<std::size_t>(n));
    }
  }
  view::WebServer& server_;
  int fd_ = -1;
  bool ok_ = false;
  std::string buffer_;
};

}  // namespace adit::test
