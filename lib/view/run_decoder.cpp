#include "view/run_decoder.hpp"

#include "core/geometry.hpp"
#include "msg/sweep_codec.hpp"
#include "msg/validate.hpp"
#include "msg/wire_check.hpp"

#include <adit/loop_closure_t.hpp>
#include <adit/map_update_t.hpp>
#include <adit/odometry_t.hpp>
#include <adit/odometry_v1_t.hpp>
#include <adit/pose_graph_t.hpp>
#include <adit/status_t.hpp>

#include <algorithm>
#include <cmath>

namespace adit::view {
namespace {

// Layout first (bounded allocations), then lcm-gen's decoder. "" on success, else why not.
template <class Msg>
std::string decodeChecked(const std::uint8_t* data, std::size_t size, Msg& m) {
  const msg::WireCheck check = msg::checkWire<Msg>(data, size);
  if (!check.ok()) return check.reason;
  if (m.decode(data, 0, static_cast<int>(size)) < 0) return "undecodable";
  return "";
}

template <class Msg>
std::string decodeValid(const std::uint8_t* data, std::size_t size, Msg& m) {
  std::string why = decodeChecked(data, size, m);
  if (why.empty())
    if (const msg::Validation v = msg::validate(m, msg::InputLimits{})) why = v->reason;
  return why;
}

// odometry_t, or the layout of logs recorded before it carried the accelerometer's preintegration and gravity
// (odometry_v1_t): the pose fields the viewer shows are in both.
std::string decodeOdometry(const std::uint8_t* data, std::size_t size, adit::odometry_t& m) {
  const std::string why = decodeValid(data, size, m);
  if (why.empty()) return why;
  adit::odometry_v1_t old;
  if (!decodeValid(data, size, old).empty()) return why;
  m = adit::odometry_t{};
  m.header = old.header;
  std::copy(old.position, old.position + 3, m.position);
  std::copy(old.orientation, old.orientation + 4, m.orientation);
  std::copy(old.loop_correction_position, old.loop_correction_position + 3, m.loop_correction_position);
  std::copy(old.loop_correction_orientation, old.loop_correction_orientation + 4, m.loop_correction_orientation);
  m.flags = old.flags;
  return "";
}

bool finitePose(const Eigen::Isometry3d& T) { return T.matrix().allFinite(); }

bool appendPose(std::vector<TimedPose>& poses, std::int64_t utime, const Eigen::Isometry3d& pose) {
  if (!poses.empty() && utime <= poses.back().utime) return false;
  poses.push_back({utime, pose});
  return true;
}

bool validSubmap(const adit::map_submap_t& s) {
  if (s.num_points < 0 || s.points.size() != static_cast<std::size_t>(s.num_points)) return false;
  if (!finitePose(makePose(s.position, s.orientation))) return false;
  return std::all_of(s.points.begin(), s.points.end(), [](const std::vector<float>& p) {
    return p.size() == 3 && std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
  });
}

}  // namespace

unsigned RunDecoder::refuse(const std::string& channel, const std::string& why) {
  ++counts_.malformed;
  counts_.last_error = channel + ": " + why;
  return kNoChange;
}

unsigned RunDecoder::apply(const std::string& channel, const std::uint8_t* data, std::size_t size, RunModel& model) {
  unsigned changed = kNoChange;
  const auto before = counts_.malformed + counts_.out_of_order;
  if (channel == "LIDAR_POINTS") {
    changed = sweep(data, size, model);
  } else if (channel == "ODOM_MAPPED") {
    changed = mapped(data, size, model);
  } else if (channel == "GROUND_TRUTH") {
    changed = groundTruth(data, size, model);
  } else if (channel == "POSE_GRAPH") {
    changed = poseGraph(data, size, model);
  } else if (channel == "LOOP_CLOSURE") {
    changed = loopClosure(data, size, model);
  } else if (channel == "MAP_UPDATE") {
    changed = mapUpdate(data, size, model);
  } else if (channel.rfind("STATUS_", 0) == 0) {
    changed = status(data, size, model);
  } else {
    ++counts_.ignored[channel];
    return kNoChange;
  }
  if (counts_.malformed + counts_.out_of_order == before) ++counts_.used;
  return changed;
}

unsigned RunDecoder::sweep(const std::uint8_t* data, std::size_t size, RunModel& model) {
  const msg::WireCheck check = msg::checkWire<msg::SweepMessage>(data, size, {});
  if (!check.ok()) return refuse("LIDAR_POINTS", check.reason);
  msg::SweepMessage m;
  if (m.decode(data, 0, static_cast<int>(size)) < 0) return refuse("LIDAR_POINTS", "undecodable");
  if (!m.error.empty()) return refuse("LIDAR_POINTS", m.error);
  if (const msg::Validation v = msg::validate(m, msg::InputLimits{})) return refuse("LIDAR_POINTS", v->reason);
  Sweep s;
  s.utime = m.header.utime;
  float max_intensity = 0;
  for (const LidarPoint& p : m.scan.points)
    if (p.p.allFinite() && std::isfinite(p.intensity)) max_intensity = std::max(max_intensity, p.intensity);
  for (const LidarPoint& p : m.scan.points) {
    if (!p.p.allFinite() || !std::isfinite(p.intensity)) continue;  // raw sweeps may hold NaNs: not shown
    s.points.push_back(p.p);
    s.intensity.push_back(max_intensity > 0 ? p.intensity / max_intensity : 0.0f);
  }
  model.sweep = std::move(s);
  return kSweepChanged;
}

unsigned RunDecoder::mapped(const std::uint8_t* data, std::size_t size, RunModel& model) {
  adit::odometry_t m;
  if (const std::string why = decodeOdometry(data, size, m); !why.empty()) return refuse("ODOM_MAPPED", why);
  const Eigen::Isometry3d pose = makePose(m.position, m.orientation);
  const Eigen::Isometry3d correction = makePose(m.loop_correction_position, m.loop_correction_orientation);
  if (!appendPose(model.odometry, m.header.utime, correction.inverse() * pose)) {
    ++counts_.out_of_order;
    return kNoChange;
  }
  model.robot = {m.header.utime, pose};
  model.has_robot = true;
  return kOdometryChanged;
}

unsigned RunDecoder::groundTruth(const std::uint8_t* data, std::size_t size, RunModel& model) {
  adit::odometry_t m;
  if (const std::string why = decodeOdometry(data, size, m); !why.empty()) return refuse("GROUND_TRUTH", why);
  if (!appendPose(model.ground_truth, m.header.utime, makePose(m.position, m.orientation))) {
    ++counts_.out_of_order;
    return kNoChange;
  }
  return kGroundTruthChanged;
}

unsigned RunDecoder::poseGraph(const std::uint8_t* data, std::size_t size, RunModel& model) {
  adit::pose_graph_t m;
  if (const std::string why = decodeValid(data, size, m); !why.empty()) return refuse("POSE_GRAPH", why);
  model.keyframes.clear();
  for (int i = 0; i < m.num_nodes; ++i) {
    const auto k = static_cast<std::size_t>(i);
    model.keyframes[m.node_utime[k]] = makePose(m.position[k].data(), m.orientation[k].data());
  }
  unsigned changed = kKeyframesChanged;
  const Loop newest{m.newest_loop.query_utime, m.newest_loop.match_utime};
  if (m.num_loops > 0 && std::find(model.loops.begin(), model.loops.end(), newest) == model.loops.end()) {
    model.loops.push_back(newest);
    changed |= kLoopsChanged;
  }
  return changed;
}

unsigned RunDecoder::loopClosure(const std::uint8_t* data, std::size_t size, RunModel& model) {
  adit::loop_closure_t m;
  if (const std::string why = decodeValid(data, size, m); !why.empty()) return refuse("LOOP_CLOSURE", why);
  const Loop loop{m.query_utime, m.match_utime};
  if (std::find(model.loops.begin(), model.loops.end(), loop) != model.loops.end()) return kNoChange;
  model.loops.push_back(loop);
  return kLoopsChanged;
}

unsigned RunDecoder::mapUpdate(const std::uint8_t* data, std::size_t size, RunModel& model) {
  adit::map_update_t m;
  if (const std::string why = decodeChecked(data, size, m); !why.empty()) return refuse("MAP_UPDATE", why);
  const auto n_moved = static_cast<std::size_t>(std::max(0, m.num_moved));
  if (m.num_new < 0 || m.new_submaps.size() != static_cast<std::size_t>(m.num_new) || m.moved_id.size() != n_moved ||
      m.moved_position.size() != n_moved || m.moved_orientation.size() != n_moved)
    return refuse("MAP_UPDATE", "counts do not match the arrays");
  for (const auto& s : m.new_submaps)
    if (!validSubmap(s)) return refuse("MAP_UPDATE", "submap " + std::to_string(s.id) + " is not finite");
  unsigned changed = kNoChange;
  for (const auto& s : m.new_submaps) {
    Submap& out = model.submaps[s.id];  // a restarted loop closer resends its submaps: replace
    out.id = s.id;
    out.utime = s.utime;
    out.pose = makePose(s.position, s.orientation);
    out.points.clear();
    for (const auto& p : s.points) out.points.emplace_back(p[0], p[1], p[2]);
    ++out.version;
    changed |= kSubmapsAdded;
  }
  for (std::size_t i = 0; i < n_moved; ++i) {
    const auto it = model.submaps.find(m.moved_id[i]);
    const Eigen::Isometry3d pose = makePose(m.moved_position[i].data(), m.moved_orientation[i].data());
    if (it == model.submaps.end() || !finitePose(pose)) continue;  // joined late: never saw it
    it->second.pose = pose;
    ++it->second.version;
    changed |= kSubmapsMoved;
  }
  model.map_loops = m.num_loops;
  return changed;
}

unsigned RunDecoder::status(const std::uint8_t* data, std::size_t size, RunModel& model) {
  adit::status_t m;
  if (const std::string why = decodeValid(data, size, m); !why.empty()) return refuse("STATUS", why);
  StatusRow r;
  r.process = m.process;
  r.state = m.state;
  r.last_error = m.last_error;
  r.wall_utime = m.header.utime;
  r.uptime_s = m.uptime_s;
  r.inputs = m.inputs;
  r.outputs = m.outputs;
  r.drops = m.drops;
  r.errors = m.errors;
  r.proc_ms_p50 = m.proc_ms_p50;
  r.proc_ms_p95 = m.proc_ms_p95;
  r.proc_ms_max = m.proc_ms_max;
  r.busy_fraction = m.busy_fraction;
  r.input_rate_hz = m.input_rate_hz;
  for (int i = 0; i < m.num_counters; ++i)
    r.counters.emplace_back(m.counter_names[static_cast<std::size_t>(i)], m.counter_values[static_cast<std::size_t>(i)]);
  model.newest_status = r.process;
  model.status[r.process] = std::move(r);
  return kStatusChanged;
}

}  // namespace adit::view
