#include "view/view_session.hpp"

#include "core/json_writer.hpp"
#include "view/view_stream.hpp"

namespace adit::view {
namespace {

// Tags of queued frames (web_server.hpp reports dropped ones): what to resend.
enum Stream : int { kSubmapStream = 0, kOdometryStream = 1, kCorrectedStream = 2, kGroundTruthStream = 3, kLoopsStream = 4 };
int tag(Stream s, int id = 0) { return (id << 3) | s; }

void statusRow(JsonWriter& j, const StatusRow& r) {
  j.beginObject().field("process", r.process).field("state", r.state).field("rate_hz", r.input_rate_hz);
  j.field("p95_ms", r.proc_ms_p95).field("busy", r.busy_fraction).field("inputs", r.inputs).field("drops", r.drops);
  j.field("errors", r.errors).field("last_error", r.last_error).key("counters").beginObject();
  for (const auto& [name, value] : r.counters) j.field(name, value);
  j.endObject().endObject();
}

}  // namespace

void ViewSession::apply(const std::string& channel, const std::uint8_t* data, std::size_t size, std::int64_t) {
  const unsigned changed = decoder_.apply(channel, data, size, model_);
  if (changed & kKeyframesChanged) ++keyframes_version_;
  if (changed & (kKeyframesChanged | kLoopsChanged)) ++loops_version_;
  if (changed & kSweepChanged) ++sweeps_;
  // The ground truth is shown in the odometry's frame: its placement is known once both have begun.
  if (!ground_truth_aligned_ && !model_.odometry.empty() && !model_.ground_truth.empty() &&
      !model_.groundTruthAlignment().isApprox(Eigen::Isometry3d::Identity(), 0.0)) {
    ground_truth_aligned_ = true;
    ++ground_truth_version_;
  }
}

void ViewSession::reset() {
  model_ = RunModel{};
  ground_truth_aligned_ = false;
  for (auto& [client, state] : clients_) {
    state = ClientState{};
    server_.send(client, encodeReset());
  }
}

void ViewSession::forgetDropped() {
  for (const auto& [client, t] : server_.takeDropped()) {
    auto it = clients_.find(client);
    if (it == clients_.end()) continue;
    ClientState& s = it->second;
    switch (t & 7) {
      case kSubmapStream: s.submaps.erase(t >> 3); break;
      case kOdometryStream: s.odometry = 0; break;
      case kCorrectedStream: s.keyframes_version = ~0ull; break;
      case kGroundTruthStream: s.ground_truth_version = ~0ull; break;
      case kLoopsStream: s.loops_version = ~0ull; break;
      default: break;
    }
  }
}

void ViewSession::tick(double now_s, const std::string& extra_json) {
  forgetDropped();
  for (const int client : server_.clients()) {
    if (!server_.subprotocol(client).empty()) continue;  // another protocol's client (Foxglove)
    ClientState& s = clients_[client];
    sendMap(client, s);
    sendTrajectories(client, s);
    if (model_.has_robot && model_.robot.utime != s.robot_utime) {
      server_.send(client, encodeRobot(model_.robot));
      s.robot_utime = model_.robot.utime;
    }
    if (model_.sweep.utime != s.sweep_utime && !model_.sweep.points.empty() &&
        now_s - s.last_sweep_s >= 1.0 / options_.sweep_rate_hz) {
      const Eigen::Isometry3d pose = model_.has_robot ? model_.robot.pose : Eigen::Isometry3d::Identity();
      server_.send(client, encodeSweep(model_.sweep, pose, options_.sweep_points));
      s.sweep_utime = model_.sweep.utime;
      s.last_sweep_s = now_s;
    }
    if (now_s - s.last_info_s >= 1.0 / options_.info_rate_hz) {
      sendInfo(client, extra_json);
      s.last_info_s = now_s;
    }
  }
}

void ViewSession::sendMap(int client, ClientState& s) {
  // New submaps go out as the client drains them (a late joiner to a large map is not flooded into drops).
  std::size_t bytes = server_.queuedBytes(client);
  for (const auto& [id, submap] : model_.submaps) {
    const auto have = s.submaps.find(id);
    if (have == s.submaps.end()) {
      if (bytes >= options_.submap_bytes_per_tick) continue;  // the rest next tick
      const std::string frame = encodeSubmap(submap);
      bytes += frame.size();
      server_.send(client, frame, tag(kSubmapStream, id));
    } else if (have->second != submap.version) {
      server_.send(client, encodeSubmapPose(submap), tag(kSubmapStream, id));
    } else {
      continue;
    }
    s.submaps[id] = submap.version;
  }
}

void ViewSession::sendTrajectories(int client, ClientState& s) {
  if (model_.odometry.size() != s.odometry) {
    const bool replace = s.odometry == 0 || s.odometry > model_.odometry.size();
    server_.send(client, encodeTrajectory(TrajectoryKind::Odometry, replace, model_.odometry, replace ? 0 : s.odometry),
                 tag(kOdometryStream));
    s.odometry = model_.odometry.size();
  }
  if (s.keyframes_version != keyframes_version_) {
    std::vector<TimedPose> keyframes;
    for (const auto& [utime, pose] : model_.keyframes) keyframes.push_back({utime, pose});
    server_.send(client, encodeTrajectory(TrajectoryKind::Keyframes, true, keyframes, 0), tag(kCorrectedStream));
  }
  if (s.keyframes_version != keyframes_version_ || model_.odometry.size() != s.corrected) {
    const bool replace = s.keyframes_version != keyframes_version_ || s.corrected > model_.odometry.size();
    const auto corrected = model_.correctedTrajectory();
    server_.send(client, encodeTrajectory(TrajectoryKind::Corrected, replace, corrected, replace ? 0 : s.corrected),
                 tag(kCorrectedStream));
    s.corrected = corrected.size();
    s.keyframes_version = keyframes_version_;
  }
  if (s.ground_truth_version != ground_truth_version_ || model_.ground_truth.size() != s.ground_truth) {
    const bool replace = s.ground_truth_version != ground_truth_version_ || s.ground_truth > model_.ground_truth.size();
    const auto truth = model_.groundTruthInWorld();
    server_.send(client, encodeTrajectory(TrajectoryKind::GroundTruth, replace, truth, replace ? 0 : s.ground_truth),
                 tag(kGroundTruthStream));
    s.ground_truth = truth.size();
    s.ground_truth_version = ground_truth_version_;
  }
  if (s.loops_version != loops_version_) {
    server_.send(client, encodeLoops(model_.loopSegments()), tag(kLoopsStream));
    s.loops_version = loops_version_;
  }
}

void ViewSession::sendInfo(int client, const std::string& extra_json) {
  const DecodeCounts& counts = decoder_.counts();
  std::int64_t ignored = 0;
  for (const auto& [channel, n] : counts.ignored) ignored += n;
  JsonWriter j;
  j.beginObject().field("distance_m", model_.distance()).field("loops", static_cast<std::int64_t>(model_.loops.size()));
  j.field("map_points", static_cast<std::int64_t>(model_.mapPointCount()));
  j.field("submaps", static_cast<std::int64_t>(model_.submaps.size())).field("sweeps", sweeps_);
  j.field("poses", static_cast<std::int64_t>(model_.odometry.size()));
  j.field("sensor_utime", model_.has_robot ? model_.robot.utime : model_.sweep.utime);
  j.key("server").beginObject().field("malformed", counts.malformed).field("out_of_order", counts.out_of_order);
  j.field("ignored", ignored).field("frames_dropped", server_.counters().frames_dropped);
  j.field("bytes_sent", server_.bytesSent(client)).field("last_error", counts.last_error).endObject();
  j.key("status").beginArray();
  for (const auto& [name, row] : model_.status) statusRow(j, row);
  j.endArray().endObject();
  std::string json = j.str();
  if (!extra_json.empty()) json.insert(json.size() - 1, "," + extra_json);
  server_.send(client, encodeInfo(json));
}

}  // namespace adit::view
