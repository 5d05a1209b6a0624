#include "nodes/relocaliser_node.hpp"

#include "eval/trajectory_io.hpp"
#include "io/atomic_file.hpp"
#include "map/relocaliser.hpp"
#include "msg/convert.hpp"
#include "nodes/node_config.hpp"
#include "nodes/products.hpp"
#include "nodes/registry.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <adit/command_t.hpp>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <sstream>

namespace adit::nodes {
namespace {

class RelocaliserNode : public runtime::Node, public WritesProducts {
 public:
  explicit RelocaliserNode(const Config& config) : Node("relocaliser") {
    subscribe<adit::odometry_t>("mapped", "ODOM_MAPPED", [this](const adit::odometry_t& m) { onMapped(m); });
    subscribe<adit::command_t>("command", "RELOC_COMMAND", [this](const adit::command_t& m) { onCommand(m); },
                               runtime::InputKind::Requests);
    advertise("pose", "POSE_IN_MAP");
    const RelocNodeConfig node = relocNodeConfigTable().read(config);
    if (node.prior_map.empty()) return;  // no bundle asked for: the run maps from scratch
    try {
      MapBundle bundle = loadMapBundle(node.prior_map);
      const std::string mismatch = bundleSensorMismatch(bundle.summary, pipelineConfigKeys(config));
      if (!mismatch.empty()) throw BundleError(node.prior_map + ": " + mismatch);
      relocaliser_.emplace(std::move(bundle), loopCloserConfigFrom(config), relocaliserConfigTable().read(config));
      spdlog::info("[relocaliser] map bundle {}: {} keyframes, {:.0f} m of roadway", node.prior_map,
                   relocaliser_->bundle().summary.keyframes, relocaliser_->bundle().summary.roadway_length_m);
    } catch (const BundleError& e) {
      reportError("bundle_refused", std::string(e.what()) + "; mapping from scratch");
    }
  }

  std::string state() const override {
    return relocaliser_ ? toString(relocaliser_->state()) : "mapping_from_scratch";
  }

  std::vector<std::string> writeProducts(const std::string& out_dir) override {
    namespace fs = std::filesystem;
    const std::string trajectory = (fs::path(out_dir) / "map_trajectory.tum").string();
    const std::string summary = (fs::path(out_dir) / "relocalisation.json").string();
    const std::string queries = (fs::path(out_dir) / "reloc_queries.txt").string();
    eval::writeTum(trajectory, in_map_);
    io::writeFileAtomically(summary, summaryJson());
    io::writeFileAtomically(queries, queryLogText());
    return {trajectory, summary, queries};
  }

 private:
  // set_pose "X Y Z HEADING_DEG [RADIUS]": the robot is near this pose of the map now (the operator's guess);
  // relocalise only within RADIUS of it (default reloc.start.radius). Anyone on the bus can send it: signed
  // commands only, with a key (README "Commands are safe to receive").
  void onCommand(const adit::command_t& m) {
    if (!commandAuthentic("command", m)) return;
    if (m.command != "set_pose") {
      reportError("unknown_command", "unknown command '" + runtime::printableText(m.command) + "' (known: set_pose)");
      return;
    }
    std::vector<double> v;
    bool numbers = true;
    std::istringstream in(m.argument);
    for (std::string word; in >> word;) {
      char* end = nullptr;
      v.push_back(std::strtod(word.c_str(), &end));
      numbers = numbers && end != word.c_str() && *end == '\0' && std::isfinite(v.back());
    }
    const std::optional<double> radius = v.size() == 5 ? std::optional<double>(v[4]) : std::nullopt;
    if (!numbers || (v.size() != 4 && v.size() != 5) || (radius && *radius <= 0)) {
      reportError("command_refused", "set_pose '" + runtime::printableText(m.argument) +
                                         "' refused: expected X Y Z HEADING_DEG [RADIUS], finite, RADIUS > 0");
      return;
    }
    if (!relocaliser_) {
      reportError("command_refused", "set_pose: no map bundle to place the pose in");
      return;
    }
    relocaliser_->setPoseHint(poseFromHeading(Eigen::Vector3d(v[0], v[1], v[2]), v[3]), radius);
    count("poses_set");
    spdlog::info("[relocaliser] told it is near ({:.1f}, {:.1f}, {:.1f}), heading {:.0f} deg", v[0], v[1], v[2], v[3]);
  }

  void onMapped(const adit::odometry_t& m) {
    if (!relocaliser_) return;
    const PoseEstimate session = msg::fromMessage(m);
    if (first_utime_ < 0) first_utime_ = session.utime;
    std::vector<Eigen::Vector3f> cloud;
    for (const LidarPoint& p : msg::featuresOf(m).cloud.points)
      if (p.p.allFinite()) cloud.push_back(p.p);
    // Wall time until the first fix: measurement only (relocalisation.json), never part of a decision.
    const auto start = std::chrono::steady_clock::now();
    const Relocaliser::Result r =
        relocaliser_->process(session, cloud, (m.flags & adit::odometry_t::FLAG_REGISTRATION_FAILED) != 0);
    if (!first_fix_) compute_ms_ += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (r.fixed_now) {
      if (!first_fix_) first_fix_ = session.utime;
      spdlog::info("[relocaliser] localised in the map after {:.1f} s of sensor time",
                   static_cast<double>(session.utime - first_utime_) * 1e-6);
    }
    if (r.lost_now) spdlog::warn("[relocaliser] lost at {:.1f} s: relocalising", static_cast<double>(session.utime - first_utime_) * 1e-6);
    if (r.T_map_lidar) {
      in_map_.push_back({session.utime, *r.T_map_lidar});
      PoseEstimate in_map;
      in_map.utime = session.utime;
      in_map.pose = *r.T_map_lidar;
      adit::odometry_t out = msg::toMessage(in_map, nullptr);
      out.header = msg::makeHeader(session.utime, "map");
      if (r.anchored_now) out.flags |= adit::odometry_t::FLAG_MAP_MEASURED;  // what an extending run ties to the map
      publish("pose", out);
    }
    const RelocStats& s = relocaliser_->stats();
    setCount("queries", s.queries);
    setCount("fixes", s.fixes);
    setCount("lost", s.lost);
    setCount("rejected_fit", s.rejected_fit);
    setCount("rejected_degenerate", s.rejected_degenerate);
    setCount("rejected_ambiguous", s.rejected_ambiguous);
    setCount("rejected_inconsistent", s.rejected_inconsistent);
    setCount("rejected_self_similar", s.rejected_self_similar);
    setCount("self_similar_map", s.self_similar_map);
    setCount("track_failed", s.track_failed);
    setCount("hinted_queries", s.hinted_queries);
    setCount("rejected_far_from_hint", s.rejected_far_from_hint);
  }

  // Every relocalising query: its outcome and best fit in the map frame (TUM pose), for diagnosis.
  std::string queryLogText() const {
    std::string out = "# sensor_s outcome x y z qx qy qz qw inlier_ratio runner_up\n";
    if (!relocaliser_) return out;
    for (const RelocQueryRecord& r : relocaliser_->queryLog()) {
      const Eigen::Vector3d t = r.T_map_lidar.translation();
      const Eigen::Quaterniond q(r.T_map_lidar.linear());
      out += fmt::format("{:.6f} {} {:.4f} {:.4f} {:.4f} {:.6f} {:.6f} {:.6f} {:.6f} {:.3f} {:.3f}\n",
                         static_cast<double>(r.utime) * 1e-6, r.outcome, t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w(),
                         r.inlier_ratio, r.runner_up);
    }
    return out;
  }

  std::string summaryJson() const {
    const RelocStats s = relocaliser_ ? relocaliser_->stats() : RelocStats{};
    const double fix_s = first_fix_ ? static_cast<double>(*first_fix_ - first_utime_) * 1e-6 : -1.0;
    return fmt::format(
        "{{\n  \"state\": \"{}\",\n  \"first_fix_sensor_s\": {:.3f},\n  \"first_fix_utime\": {},\n"
        "  \"first_fix_compute_ms\": {:.1f},\n  \"poses_in_map\": {},\n  \"queries\": {},\n  \"fixes\": {},\n"
        "  \"lost\": {},\n  \"rejected_fit\": {},\n  \"rejected_degenerate\": {},\n  \"rejected_ambiguous\": {},\n  \"rejected_inconsistent\": {},\n"
        "  \"rejected_self_similar\": {},\n  \"self_similarity_checks\": {},\n  \"self_similar_map\": {},\n  \"axial_searches\": {},\n  \"axial_resolved\": {},\n  \"axial_ambiguous\": {},\n"
        "  \"track_verified\": {},\n  \"track_failed\": {},\n  \"track_degenerate\": {},\n  \"hinted_queries\": {},\n"
        "  \"rejected_far_from_hint\": {}\n}}\n",
        state(), fix_s, first_fix_.value_or(0), compute_ms_, in_map_.size(), s.queries, s.fixes, s.lost, s.rejected_fit, s.rejected_degenerate,
        s.rejected_ambiguous, s.rejected_inconsistent, s.rejected_self_similar, s.self_similarity_checks, s.self_similar_map, s.axial_searches, s.axial_resolved, s.axial_ambiguous, s.track_verified, s.track_failed, s.track_degenerate, s.hinted_queries, s.rejected_far_from_hint);
  }

  std::optional<Relocaliser> relocaliser_;
  Trajectory in_map_;
  std::int64_t first_utime_ = -1;
  std::optional<std::int64_t> first_fix_;
  double compute_ms_ = 0.0;  // wall time of the sweeps up to the first fix (varies run to run)
};

}  // namespace

std::unique_ptr<runtime::Node> makeRelocaliserNode(const Config& config) {
  return std::make_unique<RelocaliserNode>(config);
}

}  // namespace adit::nodes
