// What adit view sends to each browser: the run model (view/run_model.hpp) as binary frames
// (view/view_stream.hpp), only what that browser lacks: a submap's points once, then only its pose when a
// loop moves it; trajectories appended, resent whole only when a loop correction moved them; the newest
// sweep at a bounded rate, decimated; STATUS and the run's facts once a second. A frame the server dropped
// from a full queue is resent whole later (its stream is marked unsent). Sending never waits for a browser.
#pragma once

#include "view/run_consumer.hpp"
#include "view/run_decoder.hpp"
#include "view/web_server.hpp"

#include <cstdint>
#include <map>
#include <string>

namespace adit::view {

struct ViewOptions {
  std::size_t sweep_points = 6000;         // points of a sweep sent (every k-th)
  double sweep_rate_hz = 5.0;              // sweeps sent per second at most
  double info_rate_hz = 1.0;               // STATUS / facts frames per second
  std::size_t submap_bytes_per_tick = 256u << 10;  // new submaps wait while a client has this much queued
};

class ViewSession : public RunConsumer {
 public:
  ViewSession(WebServer& server, ViewOptions options) : server_(server), options_(options) {}

  // One LCM message of the run.
  void apply(const std::string& channel, const std::uint8_t* data, std::size_t size, std::int64_t utime = 0) override;
  // Sends each client what it lacks. now_s: a monotonic clock (rates); extra_json: members added to the
  // info frame (e.g. "\"log\":{...}"), may be empty.
  void tick(double now_s, const std::string& extra_json);
  // Forget the run (a log rewound): every client is told to clear.
  void reset() override;
  // A client disconnected.
  void forget(int client) { clients_.erase(client); }

  const RunModel& model() const { return model_; }
  const DecodeCounts& decodeCounts() const { return decoder_.counts(); }

 private:
  struct ClientState {
    std::map<int, std::uint32_t> submaps;  // id -> version the client has
    std::size_t odometry = 0, corrected = 0, ground_truth = 0;  // poses the client has
    std::uint64_t keyframes_version = ~0ull, loops_version = ~0ull, ground_truth_version = ~0ull;
    std::int64_t robot_utime = -1, sweep_utime = -1;
    double last_sweep_s = -1e9, last_info_s = -1e9;
  };
  void sendMap(int client, ClientState& state);
  void sendTrajectories(int client, ClientState& state);
  void sendInfo(int client, const std::string& extra_json);
  void forgetDropped();

  WebServer& server_;
  ViewOptions options_;
  RunModel model_;
  RunDecoder decoder_;
  std::map<int, ClientState> clients_;
  std::uint64_t keyframes_version_ = 0, loops_version_ = 0, ground_truth_version_ = 0;
  bool ground_truth_aligned_ = false;
  std::int64_t sweeps_ = 0;
};

}  // namespace adit::view
