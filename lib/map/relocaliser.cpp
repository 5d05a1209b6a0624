#include "map/relocaliser.hpp"

#include "core/geometry.hpp"
#include "loop/loop_consensus.hpp"
#include "loop/odometry_chain.hpp"
#include "loop/place_match.hpp"
#include "loop/se3.hpp"
#include "loop/voxel_filter.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>

namespace adit {

const ConfigTable<RelocaliserConfig>& relocaliserConfigTable() {
  using R = RelocaliserConfig;
  static const ConfigTable<R> table = [] {
    ConfigTable<R> t("reloc");
    t.add("candidates", &R::candidates, between(1, 1000), "", "ring-key neighbours ranked by Scan Context distance per query")
     .add("max_verifications", &R::max_verifications, between(1, 100), "", "best candidates verified by ICP per query")
     .add("query_sweeps", &R::query_sweeps, between(1, 100), "sweeps", "newest sweeps merged into the cloud ICP aligns")
     .add("submap_neighbors", &R::submap_neighbors, between(0, 1000), "keyframes", "bundle keyframes each side of a candidate in its submap")
     .add("submap_radius", &R::submap_radius, atLeast(0), "m", "bundle keyframes within this of a candidate also in its submap")
     .add("query_distance", &R::query_distance, above(0), "m", "driving between two queries while relocalising")
     .add("query_interval_s", &R::query_interval_s, above(0), "s", "or this much sensor time between queries")
     .add("query_backoff_after", &R::query_backoff_after, between(0, 100000), "queries", "queries in a row without a candidate fix after which their spacing doubles (again after as many more; 0 = never)")
     .add("query_backoff_max", &R::query_backoff_max, between(1, 1000), "", "largest factor the spacing of queries grows to")
     .add("ambiguity_distance", &R::ambiguity_distance, above(0), "m", "fits farther apart than this are different places")
     .add("ambiguity_margin", &R::ambiguity_margin, between(0, 1), "", "a fit elsewhere with an inlier ratio within this of the best makes the query ambiguous")
     .add("min_consistent_fixes", &R::min_consistent_fixes, between(1, 100), "", "verified unambiguous queries that must agree before a fix")
     .add("consistency_window_m", &R::consistency_window_m, above(0), "m", "pending fixes older than this much driving are dropped")
     .add("track_distance", &R::track_distance, above(0), "m", "driving between tracking verifications once localised")
     .add("max_track_correction", &R::max_track_correction, above(0), "m", "a tracking fit moving the pose more than this is refused")
     .add("max_track_failures", &R::max_track_failures, between(1, 100000), "", "failed tracking verifications in a row that make the run lost")
     .add("max_stall_s", &R::max_stall_s, above(0), "s", "a gap in the input longer than this makes the run lost")
     .add("refuse_self_similar", &R::refuse_self_similar, anyValue(), "", "refuse a fix where the map's own keyframe also fits tightly at another mapped place")
     .add("self_similar_candidates", &R::self_similar_candidates, between(1, 10000), "", "Scan Context candidates ranked when looking for that other place")
     .add("self_similar_samples", &R::self_similar_samples, between(1, 1000), "keyframes", "keyframes spread over the map checked to judge whether the whole map repeats itself")
     .add("self_similar_map_ratio", &R::self_similar_map_ratio, between(0, 1), "", "share of them that must repeat for every fix in the map to be refused")
     .add("lost_search_distance", &R::lost_search_distance, atLeast(0), "m", "lost after a fix: driving during which the search stays near the last fix carried on (0 = the whole map at once)")
     .nest(&R::axial, axialSearchConfigTable())
     .nest(&R::start, poseHintConfigTable());
    return t;
  }();
  return table;
}

const ConfigTable<PoseHintConfig>& poseHintConfigTable() {
  using H = PoseHintConfig;
  static const ConfigTable<H> table = [] {
    ConfigTable<H> t("reloc.start");
    t.add("given", &H::given, anyValue(), "", "the run starts near the pose below (x, y, z, heading_deg in the bundle's frame): relocalise only there")
     .add("x", &H::x, anyValue(), "m", "start position in the map frame")
     .add("y", &H::y, anyValue(), "m", "start position in the map frame")
     .add("z", &H::z, anyValue(), "m", "start position in the map frame")
     .add("heading_deg", &H::heading_deg, between(-360, 360), "deg", "start heading (yaw about the map's z axis)")
     .add("radius", &H::radius, above(0), "m", "how far from the start pose (and, when lost, from the last fix carried on) the robot may be")
     .add("yaw_tolerance_deg", &H::yaw_tolerance_deg, between(0, 180), "deg", "heading error the start pose's seeds cover");
    return t;
  }();
  return table;
}

const char* toString(RelocState state) {
  return state == RelocState::kLocalised ? "localised" : "relocalising";
}

Relocaliser::Relocaliser(MapBundle bundle, const LoopCloserConfig& loop, const RelocaliserConfig& config)
    : bundle_(std::move(bundle)),
      loop_(loop),
      config_(config),
      database_(config.candidates),
      alias_database_(config.self_similar_candidates),
      self_similar_(bundle_.keyframes.size(), -1) {
  for (const BundleKeyframe& k : bundle_.keyframes) {
    database_.add(k.context, k.utime);
    alias_database_.add(k.context, k.utime);
  }
  // The judgement reads only the bundle, the databases and the configuration, none of which change from here.
  if (config_.start.given)
    setPoseHint(poseFromHeading(Eigen::Vector3d(config_.start.x, config_.start.y, config_.start.z), config_.start.heading_deg));
  if (config_.refuse_self_similar) map_judgement_ = std::async(std::launch::async, [this] { return judgeMap(); });
}

Relocaliser::~Relocaliser() {
  if (map_judgement_.valid()) map_judgement_.wait();
}

Eigen::Isometry3d poseFromHeading(const Eigen::Vector3d& position, double heading_deg) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = position;
  pose.linear() = Eigen::AngleAxisd(heading_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return pose;
}

void Relocaliser::setPoseHint(const Eigen::Isometry3d& T_map_lidar, std::optional<double> radius) {
  next_hint_ = std::make_pair(T_map_lidar, radius.value_or(config_.start.radius));
}

Relocaliser::Result Relocaliser::process(const PoseEstimate& session, const std::vector<Eigen::Vector3f>& cloud,
                                         bool registration_failed) {
  Result result;
  if (!session.pose.matrix().allFinite()) {
    result.state = state_;
    return result;
  }
  const bool stalled = have_last_ && static_cast<double>(session.utime - last_utime_) * 1e-6 > config_.max_stall_s;
  if (have_last_) travelled_ += translationNorm(last_pose_.inverse() * session.pose);
  have_last_ = true;
  last_pose_ = session.pose;
  last_utime_ = session.utime;
  if (next_hint_) {  // a given place: relocalise there from this sweep, whatever the state
    if (state_ == RelocState::kLocalised) loseFix(), result.lost_now = true;
    hint_ = Hint{next_hint_->first * session.pose.inverse(), next_hint_->second, std::numeric_limits<double>::infinity(),
                 std::numeric_limits<int>::max()};
    next_hint_.reset();
    pending_.clear();
    fruitless_queries_ = 0;  // a new place to look at: at full pace
  }
  if (stalled || registration_failed) recent_.clear();  // the session's motion across the gap is not trusted
  recent_.emplace_back(session.pose, cloud);
  while (static_cast<int>(recent_.size()) > config_.query_sweeps) recent_.pop_front();
  if (state_ == RelocState::kLocalised && (stalled || registration_failed)) {
    loseFix();
    result.lost_now = true;
  }
  if (state_ == RelocState::kRelocalising) {
    relocalise(session, result);
  } else {
    result.anchored_now = track(session);
    if (state_ == RelocState::kRelocalising) result.lost_now = true;
  }
  result.state = state_;
  if (state_ == RelocState::kLocalised) result.T_map_lidar = T_map_session_ * session.pose;
  return result;
}

void Relocaliser::loseFix() {
  state_ = RelocState::kRelocalising;
  // Near where the last fix, carried on by the odometry, puts the robot: searched there first.
  if (config_.lost_search_distance > 0)
    hint_ = Hint{T_map_session_, config_.start.radius, travelled_ + config_.lost_search_distance,
                 static_cast<int>(std::ceil(config_.lost_search_distance / config_.query_distance))};
  pending_.clear();
  track_failures_ = 0;
  last_query_travelled_ = -1e9;
  ++stats_.lost;
}

void Relocaliser::relocalise(const PoseEstimate& session, Result& result) {
  // Not found near it within its distance or queries (standing still): the whole map again.
  if (hint_ && (travelled_ > hint_->until_travelled || hint_->queries_left <= 0)) hint_.reset();
  const double spacing = config_.query_backoff_after > 0
                             ? std::min(config_.query_backoff_max, std::pow(2.0, fruitless_queries_ / config_.query_backoff_after))
                             : 1.0;
  const bool due = travelled_ - last_query_travelled_ >= config_.query_distance * spacing ||
                   static_cast<double>(session.utime - last_query_utime_) * 1e-6 >= config_.query_interval_s * spacing;
  if (!due) return;
  last_query_travelled_ = travelled_;
  last_query_utime_ = session.utime;
  const std::optional<Fix> fix = query(session, recent_.back().second);
  pending_.erase(std::remove_if(pending_.begin(), pending_.end(),
                                [&](const Fix& p) { return travelled_ - p.travelled > config_.consistency_window_m; }),
                 pending_.end());
  fruitless_queries_ = fix ? 0 : fruitless_queries_ + 1;
  if (!fix) return;
  // A fix agreed by enough queries and by more than contradict them (see loop/loop_consensus.hpp).
  Consensus<Fix> c = seekConsensus(pending_, *fix, config_.min_consistent_fixes,
                                   [this](const Fix& a, const Fix& b) { return consistent(a, b); });
  if (c.accepted.empty()) {
    if (c.contradicted) ++stats_.rejected_inconsistent;
    pending_ = std::move(c.pending);
    return;
  }
  T_map_session_ = orthonormal(bundle_.keyframes[static_cast<std::size_t>(fix->match)].pose * fix->T_match_query *
                               session.pose.inverse());
  state_ = RelocState::kLocalised;
  pending_.clear();
  hint_.reset();
  track_failures_ = 0;
  fruitless_queries_ = 0;
  ++stats_.fixes;
  result.fixed_now = true;
  result.anchored_now = true;
}

// The newest sweeps in the current sweep's frame, downsampled as a keyframe's cloud.
CompactCloud Relocaliser::queryCloud(const Eigen::Isometry3d& session) const {
  std::vector<Eigen::Vector3f> merged;
  const Eigen::Isometry3d T_now_world = session.inverse();
  for (const auto& [pose, points] : recent_) {
    const Eigen::Isometry3f T = (T_now_world * pose).cast<float>();
    for (const Eigen::Vector3f& p : points) merged.push_back(T * p);
  }
  return CompactCloud::encode(voxelDownsample(merged, loop_.keyframe_voxel), static_cast<float>(loop_.keyframe_cloud_step));
}

// The candidate's neighbours along the mapping drive and, from other passes (a revisit, a parallel roadway's
// cross-cut), every keyframe within reloc.submap_radius: the search along a roadway then sees the roadway's
// repeats there, whichever pass mapped them.
CandidateNeighbourhood Relocaliser::neighbourhood(int m) const {
  CandidateNeighbourhood n;
  const int last = static_cast<int>(bundle_.keyframes.size()) - 1;
  const Eigen::Isometry3d& T_map_m = bundle_.keyframes[static_cast<std::size_t>(m)].pose;
  const double r2 = config_.submap_radius * config_.submap_radius;
  for (int j = 0; j <= last; ++j) {
    const BundleKeyframe& k = bundle_.keyframes[static_cast<std::size_t>(j)];
    const bool along = std::abs(j - m) <= config_.submap_neighbors;
    if (!along && (k.pose.translation() - T_map_m.translation()).squaredNorm() > r2) continue;
    n.clouds.push_back(k.cloud);
    n.T_match_cloud.push_back(T_map_m.inverse() * k.pose);
  }
  return n;
}

// One query: Scan Context candidates, ICP verification (a fit weak along the roadway searched along it),
// ambiguity test. The verified, unambiguous fit or none.
std::optional<Relocaliser::Fix> Relocaliser::query(const PoseEstimate& session, const std::vector<Eigen::Vector3f>& cloud) {
  ++stats_.queries;
  RelocQueryRecord record;
  record.utime = session.utime;
  const std::optional<Fix> fix = bestFix(session, cloud, record);
  if (query_log_.size() < kMaxQueryLog) query_log_.push_back(record);
  return fix;
}

// A candidate's verification. A tight fit is then searched along its least constrained translation (the
// roadway's axis on a straight) against the same target, and kept only if that pins it: the loop closer's
// degeneracy test refuses nearly every single-sweep fit on a straight, and a fit it accepts can still be one of
// several along a repeating roadway.
LoopVerification Relocaliser::verify(const PlaneTarget& target, const std::vector<Eigen::Vector3f>& source,
                                     const std::vector<Eigen::Isometry3d>& seeds, const AxialSearchConfig& axial,
                                     AxialSearchResult& search, RelocStats& stats) const {
  ++stats.verified;
  LoopVerification v = verifyLoopAgainst(target, source, seeds, loop_.verifier);
  const bool tight = v.verdict == LoopVerdict::kDegenerate || v.verdict == LoopVerdict::kAccepted;
  if (!tight || !axial.enabled) return v;
  ++stats.axial_searches;
  search = searchWeakDirection(target, source, v.icp, loop_.verifier, axial);
  if (std::string(search.refusal) == "ambiguous") ++stats.axial_ambiguous;
  if (!search.resolved) {
    // Refused, but its line's best place is what another candidate's fit must beat (the ambiguity test).
    v.verdict = LoopVerdict::kDegenerate;
    if (search.icp.inlier_ratio > v.icp.inlier_ratio) {
      v.icp = search.icp;
      v.T_match_query = search.T_target_source;
    }
    return v;
  }
  ++stats.axial_resolved;
  v.verdict = LoopVerdict::kAccepted;
  v.icp = search.icp;
  v.T_match_query = search.T_target_source;
  return v;
}

// The best Scan Context candidates, each seeded by its yaw.
std::vector<Relocaliser::Candidate> Relocaliser::scanContextCandidates(const PoseEstimate& session,
                                                                       const std::vector<Eigen::Vector3f>& cloud) const {
  std::vector<Candidate> out;
  const ScanContext context = keyframeScanContext(cloud, session.pose, loop_.level_scan_context, loop_.scan_context);
  if (context.empty()) return out;
  for (const ScanContextCandidate& c : database_.query(context, 0)) {
    if (c.distance > loop_.max_scan_context_distance || static_cast<int>(out.size()) >= config_.max_verifications) break;
    const BundleKeyframe& match = bundle_.keyframes[static_cast<std::size_t>(c.index)];
    out.push_back({c.index, {scanContextSeed(session.pose, match.pose, c.yaw, loop_.level_scan_context)}});
  }
  return out;
}

// The bundle keyframes within the hint's radius of the guess, nearest first, seeded by the guess and the guess
// turned by +-yaw_tolerance_deg.
std::vector<Relocaliser::Candidate> Relocaliser::hintedCandidates(const Eigen::Isometry3d& guess) const {
  std::vector<std::pair<double, int>> near;
  for (std::size_t k = 0; k < bundle_.keyframes.size(); ++k) {
    const double d = (bundle_.keyframes[k].pose.translation() - guess.translation()).norm();
    if (d <= hint_->radius) near.emplace_back(d, static_cast<int>(k));
  }
  std::sort(near.begin(), near.end());
  const double tolerance = config_.start.yaw_tolerance_deg * M_PI / 180.0;
  std::vector<Candidate> out;
  for (const auto& [distance, k] : near) {
    if (static_cast<int>(out.size()) >= config_.max_verifications) break;
    Candidate c{k, {}};
    for (const double yaw : {0.0, tolerance, -tolerance}) {
      Eigen::Isometry3d turned = guess;
      turned.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * guess.linear();
      c.seeds.push_back(bundle_.keyframes[static_cast<std::size_t>(k)].pose.inverse() * turned);
      if (tolerance <= 0.0) break;
    }
    out.push_back(std::move(c));
  }
  return out;
}

std::optional<Relocaliser::Fix> Relocaliser::bestFix(const PoseEstimate& session, const std::vector<Eigen::Vector3f>& cloud,
                                                     RelocQueryRecord& record) {
  record.outcome = "no_candidate";
  if (database_.size() == 0) return std::nullopt;
  // Near a given place the search along a roadway stays within its radius: no twin of the place is that close.
  const std::optional<Eigen::Isometry3d> guess =
      hint_ ? std::optional<Eigen::Isometry3d>(hint_->T_map_session * session.pose) : std::nullopt;
  AxialSearchConfig axial = config_.axial;
  if (guess) {
    axial.range = std::min(axial.range, hint_->radius);
    ++stats_.hinted_queries;
    --hint_->queries_left;
  }
  const std::vector<Candidate> candidates = guess ? hintedCandidates(*guess) : scanContextCandidates(session, cloud);
  if (candidates.empty()) return std::nullopt;
  const std::vector<Eigen::Vector3f> source = querySource(queryCloud(session.pose).decode(), loop_.verifier);
  struct Tried {
    Fix fix;
    LoopVerification v;
    AxialSearchResult search;
  };
  const auto mapPose = [this](const Fix& f) { return bundle_.keyframes[static_cast<std::size_t>(f.match)].pose * f.T_match_query; };
  // A candidate on a line already searched (the same straight, Scan Context ranks its keyframes alike) adds
  // nothing but compute.
  const auto searched = [&](const std::vector<Tried>& done, const Eigen::Vector3d& at) {
    return std::any_of(done.begin(), done.end(), [&](const Tried& t) {
      if (t.search.axis.isZero()) return false;
      const Eigen::Isometry3d& match = bundle_.keyframes[static_cast<std::size_t>(t.fix.match)].pose;
      const Eigen::Vector3d line = match.linear() * t.search.axis, d = at - mapPose(t.fix).translation();
      const double along = d.dot(line);
      return std::abs(along) < axial.range - config_.ambiguity_distance &&
             (d - along * line).norm() < config_.ambiguity_distance;
    });
  };
  std::vector<Tried> tried;
  for (const Candidate& c : candidates) {
    const BundleKeyframe& match = bundle_.keyframes[static_cast<std::size_t>(c.match)];
    if (searched(tried, match.pose.translation())) continue;
    const std::unique_ptr<PlaneTarget> target = candidateTarget(neighbourhood(c.match), loop_.verifier);
    Tried t;
    t.v = verify(*target, source, c.seeds, axial, t.search, stats_);
    t.fix = {c.match, t.v.T_match_query, session.pose, travelled_};
    tried.push_back(t);
  }
  const Tried* best = nullptr;
  for (const Tried& t : tried)
    if (t.v.verdict == LoopVerdict::kAccepted && (!best || t.v.icp.inlier_ratio > best->v.icp.inlier_ratio)) best = &t;
  if (!best) {
    const bool degenerate = std::any_of(tried.begin(), tried.end(),
                                        [](const Tried& t) { return t.v.verdict == LoopVerdict::kDegenerate; });
    if (degenerate) ++stats_.rejected_degenerate;
    else if (!tried.empty()) ++stats_.rejected_fit;
    record.outcome = degenerate ? "degenerate" : "fit";
    for (const Tried& t : tried)
      if (t.v.verdict == LoopVerdict::kDegenerate && t.v.icp.inlier_ratio > record.inlier_ratio) {
        record.T_map_lidar = mapPose(t.fix);
        record.inlier_ratio = t.v.icp.inlier_ratio;
        record.runner_up = t.search.runner_up;
      }
    return std::nullopt;
  }
  record.T_map_lidar = mapPose(best->fix);
  record.inlier_ratio = best->v.icp.inlier_ratio;
  record.runner_up = best->search.runner_up;
  const Eigen::Vector3d at = mapPose(best->fix).translation();
  for (const Tried& t : tried) {
    if (&t == best || t.v.seed < 0) continue;
    const bool elsewhere = (mapPose(t.fix).translation() - at).norm() > config_.ambiguity_distance;
    if (elsewhere && t.v.icp.inlier_ratio >= best->v.icp.inlier_ratio - config_.ambiguity_margin) {
      ++stats_.rejected_ambiguous;
      record.outcome = "ambiguous";
      record.runner_up = std::max(record.runner_up, t.v.icp.inlier_ratio);
      return std::nullopt;
    }
  }
  if (guess && (mapPose(best->fix).translation() - guess->translation()).norm() > hint_->radius) {
    ++stats_.rejected_far_from_hint;
    record.outcome = "far_from_hint";
    return std::nullopt;
  }
  // Near a given place a twin of it elsewhere in the map does not matter: the place was given.
  if (!guess && config_.refuse_self_similar && (mapSelfSimilar() || selfSimilar(mapPose(best->fix)))) {
    ++stats_.rejected_self_similar;
    record.outcome = "self_similar";
    return std::nullopt;
  }
  record.outcome = "candidate";
  return best->fix;
}

// Whether the map repeats the place of a fix. The bundle keyframe nearest the fix is queried as a relocalising
// query would be (its own Scan Context, its cloud verified by ICP with the search along the roadway), against
// every candidate whose submap does not hold that keyframe itself; a tight fit that lands more than
// reloc.ambiguity_distance away is an alias. The query's own ambiguity test cannot see this when the alias the
// robot stands at is outside the mapped part: the map then holds one copy, and the fit to it is unambiguous
// (room-and-pillar: starts outside a 167 m map fixed 120 m off, turned 180 deg). Checked once per keyframe.
bool Relocaliser::selfSimilar(const Eigen::Isometry3d& T_map_lidar) {
  const int m = nearestKeyframe(T_map_lidar.translation());
  return m >= 0 && keyframeSelfSimilar(m);
}

// The bundle keyframe nearest a map position; -1 for an empty bundle.
int Relocaliser::nearestKeyframe(const Eigen::Vector3d& position) const {
  int nearest = -1;
  double best = 1e18;
  for (std::size_t k = 0; k < bundle_.keyframes.size(); ++k) {
    const double d = (bundle_.keyframes[k].pose.translation() - position).squaredNorm();
    if (d < best) best = d, nearest = static_cast<int>(k);
  }
  return nearest;
}

// The share of keyframes spread evenly over the map that repeat elsewhere in it, against
// reloc.self_similar_map_ratio: the judgement started at construction, taken over once.
bool Relocaliser::mapSelfSimilar() {
  if (stats_.self_similar_map >= 0) return stats_.self_similar_map == 1;
  const MapJudgement judged = map_judgement_.valid() ? map_judgement_.get() : judgeMap();
  int repeated = 0;
  for (std::size_t i = 0; i < judged.samples.size(); ++i) {
    self_similar_[static_cast<std::size_t>(judged.samples[i])] = judged.repeated[i] ? 1 : 0;
    repeated += judged.repeated[i] ? 1 : 0;
  }
  const RelocStats& c = judged.counts;
  stats_.verified += c.verified;
  stats_.axial_searches += c.axial_searches;
  stats_.axial_resolved += c.axial_resolved;
  stats_.axial_ambiguous += c.axial_ambiguous;
  stats_.self_similarity_checks += static_cast<int>(judged.samples.size());
  const auto samples = static_cast<double>(judged.samples.size());
  stats_.self_similar_map = samples > 0 && repeated >= config_.self_similar_map_ratio * samples ? 1 : 0;
  return stats_.self_similar_map == 1;
}

Relocaliser::MapJudgement Relocaliser::judgeMap() const {
  MapJudgement out;
  const int n = static_cast<int>(bundle_.keyframes.size());
  const int samples = std::min(n, config_.self_similar_samples);
  for (int i = 0; i < samples; ++i) {
    const int k = static_cast<int>((2 * static_cast<std::int64_t>(i) + 1) * n / (2 * samples));
    out.samples.push_back(k);
    out.repeated.push_back(repeatsElsewhere(k, out.counts));
  }
  return out;
}

// A keyframe's check, cached (the map's sampled keyframes come from the judgement).
bool Relocaliser::keyframeSelfSimilar(int m) {
  mapSelfSimilar();  // takes the judgement's results into the cache first: each keyframe is checked once
  signed char& known = self_similar_[static_cast<std::size_t>(m)];
  if (known < 0) {
    ++stats_.self_similarity_checks;
    known = repeatsElsewhere(m, stats_) ? 1 : 0;
  }
  return known == 1;
}

// Keyframe m's own cloud and Scan Context, queried as a relocalising query would be against every candidate whose
// submap does not hold m itself: a tight fit that lands more than reloc.ambiguity_distance from m is a twin.
bool Relocaliser::repeatsElsewhere(int m, RelocStats& stats) const {
  const BundleKeyframe& keyframe = bundle_.keyframes[static_cast<std::size_t>(m)];
  const std::vector<Eigen::Vector3f> source = querySource(keyframe.cloud.decode(), loop_.verifier);
  const double r2 = config_.submap_radius * config_.submap_radius;
  int verified = 0;
  for (const ScanContextCandidate& c : alias_database_.query(keyframe.context, 0)) {
    if (c.distance > loop_.max_scan_context_distance || verified >= config_.max_verifications) break;
    const BundleKeyframe& other = bundle_.keyframes[static_cast<std::size_t>(c.index)];
    const bool holds_itself = std::abs(c.index - m) <= config_.submap_neighbors ||
                              (other.pose.translation() - keyframe.pose.translation()).squaredNorm() <= r2;
    if (holds_itself) continue;  // its fit would find the keyframe's own place
    ++verified;
    const std::unique_ptr<PlaneTarget> target = candidateTarget(neighbourhood(c.index), loop_.verifier);
    AxialSearchResult search;
    const LoopVerification v = verify(*target, source, {scanContextSeed(keyframe.pose, other.pose, c.yaw, loop_.level_scan_context)},
                                      config_.axial, search, stats);
    const Eigen::Isometry3d at = other.pose * v.T_match_query;
    if (v.verdict == LoopVerdict::kAccepted &&
        (at.translation() - keyframe.pose.translation()).norm() > config_.ambiguity_distance)
      return true;
  }
  return false;
}

// The loop closer's pairwise cycle test: the two fits and the session's motion between the queries must close.
bool Relocaliser::consistent(const Fix& a, const Fix& b) const {
  const Eigen::Isometry3d T_ma_mb = bundle_.keyframes[static_cast<std::size_t>(a.match)].pose.inverse() *
                                    bundle_.keyframes[static_cast<std::size_t>(b.match)].pose;
  const Eigen::Isometry3d T_qa_qb = a.session.inverse() * b.session;
  const double driven = std::abs(b.travelled - a.travelled);
  const Matrix6d cov = odometryDriftCovariance(loop_, driven) +
                       odometryDriftCovariance(loop_, translationNorm(T_ma_mb)) + 2.0 * loopMeasurementCovariance(loop_);
  return pairChi2(a.T_match_query, b.T_match_query, T_ma_mb, T_qa_qb, cov) <= loop_.max_pair_chi2;
}

// Localised: verify the sweep against the bundle keyframes nearest its predicted map pose and refine the offset.
bool Relocaliser::track(const PoseEstimate& session) {
  if (travelled_ - last_query_travelled_ < config_.track_distance) return false;
  last_query_travelled_ = travelled_;
  const Eigen::Isometry3d predicted = T_map_session_ * session.pose;
  const int nearest = nearestKeyframe(predicted.translation());
  bool ok = false;
  if (nearest >= 0) {
    const Eigen::Isometry3d& match = bundle_.keyframes[static_cast<std::size_t>(nearest)].pose;
    const LoopVerification v = verifyCandidate(queryCloud(session.pose), neighbourhood(nearest), {match.inverse() * predicted},
                                               loop_.verifier);
    const Eigen::Isometry3d refined = match * v.T_match_query;
    const bool small = translationNorm(predicted.inverse() * refined) <= config_.max_track_correction;
    // A tight fit along a featureless stretch says the map still fits but not where along it: keep the pose.
    if (v.verdict == LoopVerdict::kDegenerate && small) {
      ++stats_.track_degenerate;
      track_failures_ = 0;
      return false;
    }
    ok = v.verdict == LoopVerdict::kAccepted && small;
    if (ok) T_map_session_ = orthonormal(refined * session.pose.inverse());
  }
  if (ok) {
    ++stats_.track_verified;
    track_failures_ = 0;
  } else {
    ++stats_.track_failed;
    if (++track_failures_ >= config_.max_track_failures) loseFix();
  }
  return ok;
}

}  // namespace adit
