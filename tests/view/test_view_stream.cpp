// adit view's stream and server: every frame type round-trips through its encoding (to the quantisation
// stated in view_stream.hpp); truncated frames are refused; the WebSocket handshake gives RFC 6455's example
// answer; the server answers 404 to unknown paths, serves its folder's files only, and a client that never
// reads gets its oldest frames dropped (counted, their tags reported) instead of blocking the server.
#include "view/view_stream.hpp"
#include "view/web_server.hpp"

#include "core/base64.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

namespace {

using namespace adit::view;

Eigen::Isometry3d somePose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(512.25, -3.5, 1.75);
  T.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, 0.3, 1).normalized()).toRotationMatrix();
  return T;
}

void expectPose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  EXPECT_NEAR((a.translation() - b.translation()).norm(), 0, 1e-9);
  EXPECT_NEAR(Eigen::AngleAxisd(a.rotation().transpose() * b.rotation()).angle(), 0, 1e-6);  // float quaternion
}

DecodedFrame roundTrip(const std::string& bytes) {
  DecodedFrame f;
  EXPECT_TRUE(decodeFrame(bytes, f));
  return f;
}

TEST(ViewStream, SubmapAndItsMoveRoundTrip) {
  Submap s;
  s.id = 41;
  s.version = 3;
  s.pose = somePose();
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-150.0f, 150.0f);
  for (int i = 0; i < 1000; ++i) s.points.emplace_back(u(rng), u(rng), u(rng) / 10);
  s.points.emplace_back(400.0f, 0.0f, 0.0f);  // beyond the i16 range: left out
  const DecodedFrame f = roundTrip(encodeSubmap(s));
  EXPECT_EQ(f.type, FrameType::Submap);
  EXPECT_EQ(f.id, 41u);
  EXPECT_EQ(f.version, 3u);
  expectPose(f.pose, s.pose);
  ASSERT_EQ(f.points.size(), 1000u);
  for (std::size_t i = 0; i < f.points.size(); ++i)
    EXPECT_LE((f.points[i] - s.points[i]).cwiseAbs().maxCoeff(), kPointScale / 2 + 1e-4f);
  const DecodedFrame m = roundTrip(encodeSubmapPose(s));
  EXPECT_EQ(m.type, FrameType::SubmapPose);
  EXPECT_EQ(m.id, 41u);
  expectPose(m.pose, s.pose);
}

TEST(ViewStream, SweepIsDecimatedToItsBudget) {
  Sweep s;
  s.utime = 1700000001234567;
  for (int i = 0; i < 29000; ++i) {
    s.points.emplace_back(0.01f * static_cast<float>(i % 1000), 1.0f, -0.5f);
    s.intensity.push_back(static_cast<float>(i % 256) / 255.0f);
  }
  const DecodedFrame f = roundTrip(encodeSweep(s, somePose(), 6000));
  EXPECT_EQ(f.type, FrameType::Sweep);
  EXPECT_EQ(f.utime, s.utime);
  expectPose(f.pose, somePose());
  EXPECT_LE(f.points.size(), 6000u);
  EXPECT_GE(f.points.size(), 5000u);
  const std::size_t step = 29000 / f.points.size() + (29000 % f.points.size() ? 1 : 0);
  for (std::size_t k = 0; k < f.points.size(); ++k) {
    const std::size_t i = k * step;
    ASSERT_LT(i, s.points.size());
    EXPECT_LE((f.points[k] - s.points[i]).cwiseAbs().maxCoeff(), kPointScale / 2 + 1e-4f);
    EXPECT_EQ(f.intensity[k], i % 256);
  }
}

TEST(ViewStream, TrajectoryLoopsRobotInfoReset) {
  std::vector<TimedPose> poses;
  for (int i = 0; i < 50; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(i * 0.1, std::sin(i * 0.1), 0.25);
    poses.push_back({i * 100000, T});
  }
  const DecodedFrame t = roundTrip(encodeTrajectory(TrajectoryKind::Corrected, false, poses, 20));
  EXPECT_EQ(t.kind, TrajectoryKind::Corrected);
  EXPECT_FALSE(t.replace);
  ASSERT_EQ(t.points.size(), 30u);
  EXPECT_NEAR((t.points[0].cast<double>() - poses[20].pose.translation()).norm(), 0, 1e-5);
  EXPECT_NEAR((t.points[29].cast<double>() - poses[49].pose.translation()).norm(), 0, 1e-5);

  const DecodedFrame l = roundTrip(encodeLoops({{Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(-4, 5, -6)}}));
  ASSERT_EQ(l.segments.size(), 1u);
  EXPECT_EQ(l.segments[0].second, Eigen::Vector3f(-4, 5, -6));

  const DecodedFrame r = roundTrip(encodeRobot({42, somePose()}));
  EXPECT_EQ(r.utime, 42);
  expectPose(r.pose, somePose());

  EXPECT_EQ(roundTrip(encodeInfo(R"({"loops":2})")).json, R"({"loops":2})");
  EXPECT_EQ(roundTrip(encodeReset()).type, FrameType::Reset);
}

TEST(ViewStream, TruncatedOrUnknownFramesAreRefused) {
  Submap s;
  s.points = {{1, 2, 3}, {4, 5, 6}};
  const std::string whole = encodeSubmap(s);
  DecodedFrame f;
  for (std::size_t n = 0; n < whole.size(); ++n) EXPECT_FALSE(decodeFrame(whole.substr(0, n), f)) << n;
  EXPECT_FALSE(decodeFrame(whole + "x", f));
  EXPECT_FALSE(decodeFrame(std::string(1, '\x63'), f));
  std::string unknown_kind = encodeTrajectory(TrajectoryKind::Odometry, true, {}, 0);
  unknown_kind[1] = 9;
  EXPECT_FALSE(decodeFrame(unknown_kind, f));
}

TEST(Base64, Rfc4648Vectors) {
  EXPECT_EQ(adit::base64(""), "");
  EXPECT_EQ(adit::base64("f"), "Zg==");
  EXPECT_EQ(adit::base64("fo"), "Zm8=");
  EXPECT_EQ(adit::base64("foo"), "Zm9v");
  EXPECT_EQ(adit::base64("foob"), "Zm9vYg==");
  EXPECT_EQ(adit::base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(adit::base64("foobar"), "Zm9vYmFy");
}

TEST(WebSocket, HandshakeAnswerOfRfc6455) {
  EXPECT_EQ(webSocketAccept("dGhlIHNhbXBsZSBub25jZQ=="), "s3pPLMBiTxaQ9kYGzzhZRbK+xOo=");
  EXPECT_EQ(webSocketFrame("abc").substr(0, 2), std::string("\x82\x03", 2));
  EXPECT_EQ(webSocketFrame(std::string(300, 'x')).substr(0, 4), std::string("\x82\x7e\x01\x2c", 4));
  EXPECT_EQ(webSocketFrame(std::string(70000, 'x')).size(), 70000u + 10u);
}

// A blocking TCP client for the server under test (the server runs in this thread through poll()).
class Client {
 public:
  explicit Client(int port) {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<std::uint16_t>(port));
    ::inet_pton(AF_INET, "127.0.0.1", &a.sin_addr);
    EXPECT_EQ(::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof(a)), 0);
    const int small = 4096;  // a slow reader: a small receive window
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &small, sizeof(small));
  }
  ~Client() { ::close(fd_); }
  int fd() const { return fd_; }
  void shutdownBoth() { ::shutdown(fd_, SHUT_RDWR); }
  void send(const std::string& s) { EXPECT_EQ(::send(fd_, s.data(), s.size(), 0), static_cast<ssize_t>(s.size())); }
  std::string receiveSome(WebServer& server) {
    std::string got;
    for (int i = 0; i < 50 && got.find("\r\n\r\n") == std::string::npos; ++i) {
      server.poll(10);
      char buf[4096];
      const ssize_t n = ::recv(fd_, buf, sizeof(buf), MSG_DONTWAIT);
      if (n > 0) got.append(buf, static_cast<std::size_t>(n));
    }
    return got;
  }

 private:
  int fd_ = -1;
};

WebServerOptions localOptions(const std::string& root) {
  WebServerOptions o;
  o.port = 0;
  o.web_root = root;
  return o;
}

struct WebRoot {
  WebRoot() {
    path = std::filesystem::temp_directory_path() / ("adit_view_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(path);
    std::ofstream(path / "index.html") << "<html>adit</html>";
  }
  ~WebRoot() { std::filesystem::remove_all(path); }
  std::filesystem::path path;
};

TEST(WebServer, ServesItsFolderAnd404sTheRest) {
  WebRoot root;
  WebServer server(localOptions(root.path.string()));
  {
    Client c(server.port());
    c.send("GET / HTTP/1.1\r\nHost: x\r\n\r\n");
    const std::string r = c.receiveSome(server);
    EXPECT_EQ(r.rfind("HTTP/1.1 200 OK", 0), 0u) << r;
  }
  for (const char* path : {"/nope.js", "/../index.html", "/.hidden", "/a/b"}) {
    Client c(server.port());
    c.send(std::string("GET ") + path + " HTTP/1.1\r\n\r\n");
    EXPECT_EQ(c.receiveSome(server).rfind("HTTP/1.1 404", 0), 0u) << path;
  }
  Client post(server.port());
  post.send("POST / HTTP/1.1\r\n\r\n");
  EXPECT_EQ(post.receiveSome(server).rfind("HTTP/1.1 405", 0), 0u);
  EXPECT_EQ(server.counters().not_found, 4);
}

// A client that sends pings and reads nothing: pongs are not dropped like frames, so its connection is closed
// once its queue holds more than max_queue_bytes (pongs used to be queued without bound: memory growing as fast
// as one browser on the LAN could send).
TEST(WebServer, AClientThatPingsWithoutReadingIsClosed) {
  WebRoot root;
  WebServerOptions options = localOptions(root.path.string());
  options.max_queue_bytes = 1u << 20;
  WebServer server(options);
  Client c(server.port());
  c.send("GET /ws HTTP/1.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n");
  ASSERT_NE(c.receiveSome(server).find("101 Switching Protocols"), std::string::npos);
  ASSERT_EQ(server.clients().size(), 1u);
  const int id = server.clients()[0];
  // Masked (key 0) pings of 60000 bytes, 300 of them (18 MB), sent by a thread while this one serves.
  const std::string ping = std::string("\x89\xfe\xea\x60\0\0\0\0", 8) + std::string(60000, 'p');
  std::atomic<bool> sending{true};
  std::thread sender([&] {
    for (int i = 0; i < 300; ++i)
      if (::send(c.fd(), ping.data(), ping.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(ping.size())) break;
    sending = false;
  });
  std::size_t most_queued = 0;
  for (int i = 0; i < 20000 && (sending || i < 100) && !server.clients().empty(); ++i) {
    server.poll(1);
    most_queued = std::max(most_queued, server.queuedBytes(id));
  }
  c.shutdownBoth();  // ends a send still blocked
  sender.join();
  EXPECT_TRUE(server.clients().empty());
  EXPECT_LE(most_queued, options.max_queue_bytes + 2 * 65536);
  EXPECT_GE(server.counters().bad_requests, 1);
}

TEST(WebServer, ASlowClientLosesItsOldestFramesNotTheServer) {
  WebRoot root;
  WebServerOptions options = localOptions(root.path.string());
  options.max_queue_frames = 8;
  WebServer server(options);
  Client c(server.port());
  c.send("GET /ws HTTP/1.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n");
  const std::string answer = c.receiveSome(server);
  ASSERT_NE(answer.find("101 Switching Protocols"), std::string::npos) << answer;
  ASSERT_EQ(server.clients().size(), 1u);
  const int id = server.clients()[0];
  // 200 frames of 64 kB to a client that reads nothing: the server must go on, keeping at most 8 queued.
  for (int i = 0; i < 200; ++i) {
    server.send(id, std::string(65536, 'x'), i);
    server.poll(0);
  }
  const auto dropped = server.takeDropped();
  EXPECT_GT(server.counters().frames_dropped, 150);
  EXPECT_EQ(static_cast<std::int64_t>(dropped.size()), server.counters().frames_dropped);
  // Oldest first (the kernel took the first ones), never the newest.
  for (std::size_t i = 1; i < dropped.size(); ++i) EXPECT_LT(dropped[i - 1].second, dropped[i].second);
  EXPECT_NE(dropped.back().second, 199);
  EXPECT_LT(server.bytesSent(id), 200 * 65536);
  // A client frame without the mask bit (RFC 6455: clients mask) closes that client.
  c.send(std::string("\x81\x02hi", 4));
  for (int i = 0; i < 20; ++i) server.poll(5);
  EXPECT_TRUE(server.clients().empty());
  EXPECT_EQ(server.takeClosed(), std::vector<int>{id});
}

}  // namespace
