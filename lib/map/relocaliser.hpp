// Relocalisation on a saved map (issue 18): a run that starts with no initial guess finds its pose in a map
// bundle's frame, keeps it while it drives, and finds it again when lost.
//
// Relocalising: every reloc.query_distance of driving (or reloc.query_interval_s standing still) the current
// sweep becomes a query keyframe; its Scan Context is searched among the bundle's keyframes and the best
// candidates are verified by ICP against each candidate's neighbourhood at its map pose: the loop closer's own
// steps (loop/place_match.hpp) and acceptance tests (tight fit, all 6 directions constrained). A verified fit
// is then refused when ambiguous (a fit at another place within reloc.ambiguity_margin of its inlier ratio),
// and becomes the fix only once reloc.min_consistent_fixes queries agree (the loop closer's pairwise cycle
// test with the session's odometry between them) and outnumber the waiting queries that contradict them
// (loop/loop_consensus.hpp). Roadways repeat: refusing is better than guessing.
// Localised: the pose in the map is T_map_session * session pose, every sweep; every reloc.track_distance the
// sweep is verified against the nearest bundle keyframes (seeded by that pose) and the offset refined. Lost
// (back to relocalising) after reloc.max_track_failures failed verifications in a row, a registration failure
// or a sensor stall longer than reloc.max_stall_s. The bundle is never changed and memory does not grow.
#pragma once

#include "core/config_table.hpp"
#include "core/types.hpp"
#include "loop/loop_closer.hpp"
#include "loop/place_match.hpp"
#include "map/axial_search.hpp"
#include "map/map_bundle.hpp"

#include <deque>
#include <future>
#include <optional>
#include <vector>

namespace adit {

// A place the robot is known to be near: the operator's start pose (the shaft bottom, the charging bay), or
// where the robot was when it got lost. While one is set, relocalising verifies only the bundle keyframes
// within `radius` of it, from its heading (and +-yaw_tolerance_deg), and searches along a roadway only that
// far: a map that repeats itself (a pillar grid) has no twin of a place that close, so such a fix is not
// refused as self-similar. A fix farther than `radius` from it is refused.
struct PoseHintConfig {
  bool given = false;  // reloc.start.given: the start pose below is where the run starts (its first sweep)
  double x = 0.0, y = 0.0, z = 0.0;  // m, map frame
  double heading_deg = 0.0;          // yaw about the map's z axis
  double radius = 5.0;               // m: how far from it the robot may be
  double yaw_tolerance_deg = 20.0;   // the heading's error the seeds cover
};

const ConfigTable<PoseHintConfig>& poseHintConfigTable();

// A pose in the map frame from a position and a heading (yaw about the map's z axis, degrees): how an operator
// gives one (reloc.start.*, the set_pose command).
Eigen::Isometry3d poseFromHeading(const Eigen::Vector3d& position, double heading_deg);

struct RelocaliserConfig {
  int candidates = 25;           // ring-key neighbours ranked by Scan Context distance per query
  int max_verifications = 4;     // best candidates verified by ICP per query
  // Sweeps merged (at their session poses) into the cloud ICP aligns: a 16-beam sweep leaves gaps between its
  // rings that a few consecutive sweeps fill, which constrains the fit along a roadway of arches and bolts.
  int query_sweeps = 5;
  // Bundle keyframes each side of a candidate in its submap (the loop closer uses loop.verifier.submap_neighbors,
  // 5): a straight roadway constrains a fit along its axis only through what lies tens of metres away (niches,
  // equipment, junctions), which a single sweep sees and a +-5 m submap does not hold.
  int submap_neighbors = 20;
  double submap_radius = 20.0;   // m: ... and keyframes of other passes this close to the candidate
  double query_distance = 0.5;   // m driven between two queries while relocalising
  double query_interval_s = 1.0; // ... or this much sensor time
  // After this many queries in a row without a fit worth keeping (a run outside the map: new roadway being
  // extended, or a place the map cannot tell), the spacing doubles, and again after as many more, up to
  // query_backoff_max times: a query costs ~1 s of CPU, which a live run cannot spend every 0.5 m for long.
  int query_backoff_after = 20;  // 0 = never
  double query_backoff_max = 8.0;
  double ambiguity_distance = 3.0;  // m: two fits farther apart than this are different places
  double ambiguity_margin = 0.15;   // a fit elsewhere with an inlier ratio within this of the best: ambiguous
  int min_consistent_fixes = 2;     // verified, unambiguous queries that must agree before the first fix
  double consistency_window_m = 15.0;  // pending fixes older than this much driving are dropped
  double track_distance = 1.0;      // m driven between tracking verifications once localised
  double max_track_correction = 1.0;  // m: a tracking fit moving the pose more than this is refused
  int max_track_failures = 8;       // failed tracking verifications in a row: lost
  double max_stall_s = 1.0;         // a gap in the input longer than this: lost
  // A fix at a place the map itself repeats is refused: the map's own keyframe there, queried like a
  // relocalising query, also fits tightly somewhere else. A pillar grid or a run of identical cross-cuts is
  // locally the same from many places, and a robot outside the mapped part sees the same as one inside it.
  // A map most of whose places repeat (a regular pillar grid: every place there has a twin, mapped or not)
  // cannot place a robot that may have started outside it: every fix is refused. Judged from
  // self_similar_samples keyframes spread over the map, on a thread started when the bundle is loaded.
  bool refuse_self_similar = true;
  int self_similar_candidates = 100;  // Scan Context candidates ranked when looking for the keyframe's alias
  int self_similar_samples = 12;      // keyframes checked to judge the whole map
  double self_similar_map_ratio = 0.5;  // share of them that must repeat for the map to count as self-similar
  // A query's fit that is tight but weak along the roadway is searched along it (map/axial_search.hpp).
  AxialSearchConfig axial;
  PoseHintConfig start;
  // Lost after a fix: for this much driving the search stays within start.radius of where the odometry says
  // the robot is (the last fix carried on), then covers the whole map again (0: the whole map at once).
  double lost_search_distance = 20.0;
};

const ConfigTable<RelocaliserConfig>& relocaliserConfigTable();

enum class RelocState { kRelocalising, kLocalised };
const char* toString(RelocState state);

struct RelocStats {
  int queries = 0;
  int verified = 0;             // candidates verified by ICP
  int rejected_fit = 0;         // no candidate fitted tightly
  int rejected_degenerate = 0;  // the best fit left a direction unconstrained (a featureless stretch)
  int axial_searches = 0;       // degenerate fits searched along their weak direction
  int axial_resolved = 0;       // ... that the search pinned
  int axial_ambiguous = 0;      // ... where a fit elsewhere along the line came within the margin
  int rejected_ambiguous = 0;   // a fit elsewhere nearly as good
  int rejected_inconsistent = 0;// disagreed with the pending fixes
  int rejected_self_similar = 0;// the fix's place is repeated elsewhere in the map
  int self_similarity_checks = 0;  // bundle keyframes checked for an alias (each once)
  int self_similar_map = -1;       // the whole map judged self-similar: 1 yes, 0 no, -1 not judged yet
  int fixes = 0;                // times localised (first fix and each relocalisation after being lost)
  int lost = 0;
  int track_verified = 0, track_failed = 0;
  int track_degenerate = 0;     // fits but constrains too few directions: kept, not a failure
  int hinted_queries = 0;       // queries searched near a given place (the start pose, the pose when lost)
  int rejected_far_from_hint = 0;  // ... whose fit landed farther than its radius from it
};

// One relocalising query, for the benchmark's diagnosis (relocaliser's products): what it found and why it was
// or was not taken. Kept only while relocalising, at most kMaxQueryLog.
struct RelocQueryRecord {
  std::int64_t utime = 0;
  const char* outcome = "";        // candidate, no_candidate, fit, degenerate, ambiguous, self_similar
  Eigen::Isometry3d T_map_lidar = Eigen::Isometry3d::Identity();  // the best fit, when there was one
  double inlier_ratio = 0.0, runner_up = 0.0;
};

class Relocaliser {
 public:
  Relocaliser(MapBundle bundle, const LoopCloserConfig& loop, const RelocaliserConfig& config);
  // The map's self-similarity is judged on a thread that refers to this object: it is neither copied nor moved.
  Relocaliser(const Relocaliser&) = delete;
  Relocaliser& operator=(const Relocaliser&) = delete;
  ~Relocaliser();

  struct Result {
    RelocState state = RelocState::kRelocalising;
    bool fixed_now = false;  // this sweep gave the fix
    bool lost_now = false;
    // This sweep's pose in the map was measured, not carried by odometry: the fix, or a verified tracking fit
    // (what ties a session extending the map to it, map/bundle_extend.hpp).
    bool anchored_now = false;
    std::optional<Eigen::Isometry3d> T_map_lidar;  // only when localised
  };
  // The robot is near this map pose at the next sweep processed (the operator's start pose; reloc.start sets
  // one at construction): relocalising searches only within `radius` (default reloc.start.radius) of it until
  // the fix. Replaces any other.
  void setPoseHint(const Eigen::Isometry3d& T_map_lidar, std::optional<double> radius = std::nullopt);

  // session: the run's own pose (mapper output) of the sweep; cloud: its deskewed points, lidar frame.
  Result process(const PoseEstimate& session, const std::vector<Eigen::Vector3f>& cloud, bool registration_failed);

  RelocState state() const { return state_; }
  const RelocStats& stats() const { return stats_; }
  const std::vector<RelocQueryRecord>& queryLog() const { return query_log_; }
  static constexpr std::size_t kMaxQueryLog = 2000;
  const MapBundle& bundle() const { return bundle_; }
  // Whether most places of the map repeat elsewhere in it (reloc.self_similar_samples keyframes spread over it,
  // each queried against the rest as a relocalising query would be). Judged once, from the bundle alone (waits
  // for the judgement started at construction); with reloc.refuse_self_similar such a map gives no fix.
  bool mapSelfSimilar();

 private:
  struct Fix {
    int match = -1;                 // bundle keyframe
    Eigen::Isometry3d T_match_query = Eigen::Isometry3d::Identity();
    Eigen::Isometry3d session = Eigen::Isometry3d::Identity();  // query's session pose
    double travelled = 0.0;         // session distance driven at the query
  };
  void relocalise(const PoseEstimate& session, Result& result);
  bool track(const PoseEstimate& session);  // true when a tracking fit refined the pose
  std::optional<Fix> query(const PoseEstimate& session, const std::vector<Eigen::Vector3f>& cloud);
  std::optional<Fix> bestFix(const PoseEstimate& session, const std::vector<Eigen::Vector3f>& cloud, RelocQueryRecord& record);
  // ICP from the seeds (the first that fits) with the search along a weak direction; counts into `stats` (the
  // background judgement has its own).
  LoopVerification verify(const PlaneTarget& target, const std::vector<Eigen::Vector3f>& source,
                          const std::vector<Eigen::Isometry3d>& seeds, const AxialSearchConfig& axial,
                          AxialSearchResult& search, RelocStats& stats) const;
  struct Candidate {
    int match = -1;
    std::vector<Eigen::Isometry3d> seeds;  // T_match_query
  };
  std::vector<Candidate> scanContextCandidates(const PoseEstimate& session, const std::vector<Eigen::Vector3f>& cloud) const;
  std::vector<Candidate> hintedCandidates(const Eigen::Isometry3d& guess) const;
  bool consistent(const Fix& a, const Fix& b) const;
  bool selfSimilar(const Eigen::Isometry3d& T_map_lidar);
  int nearestKeyframe(const Eigen::Vector3d& position) const;
  bool keyframeSelfSimilar(int keyframe);
  bool repeatsElsewhere(int keyframe, RelocStats& stats) const;  // reads only the bundle: safe on any thread
  struct MapJudgement {
    std::vector<int> samples;
    std::vector<bool> repeated;
    RelocStats counts;  // verifications and searches it made
  };
  MapJudgement judgeMap() const;
  CandidateNeighbourhood neighbourhood(int match) const;
  CompactCloud queryCloud(const Eigen::Isometry3d& session) const;
  void loseFix();

  MapBundle bundle_;
  LoopCloserConfig loop_;
  RelocaliserConfig config_;
  ScanContextDatabase database_;
  ScanContextDatabase alias_database_;  // the same contexts, more candidates per query (selfSimilar)
  std::vector<signed char> self_similar_;  // per bundle keyframe: -1 not checked yet, 0 no, 1 yes
  RelocState state_ = RelocState::kRelocalising;
  Eigen::Isometry3d T_map_session_ = Eigen::Isometry3d::Identity();
  std::vector<Fix> pending_;
  struct Hint {
    Eigen::Isometry3d T_map_session = Eigen::Isometry3d::Identity();
    double radius = 0.0;
    double until_travelled = 0.0;  // dropped once the session has driven this far
    int queries_left = 0;          // ... or after this many queries (a robot standing still)
  };
  std::optional<Hint> hint_;
  std::optional<std::pair<Eigen::Isometry3d, double>> next_hint_;  // T_map_lidar and radius, for the next sweep
  RelocStats stats_;
  std::vector<RelocQueryRecord> query_log_;
  // Session motion bookkeeping.
  bool have_last_ = false;
  Eigen::Isometry3d last_pose_ = Eigen::Isometry3d::Identity();
  std::int64_t last_utime_ = 0;
  double travelled_ = 0.0;
  double last_query_travelled_ = -1e9;
  int fruitless_queries_ = 0;  // queries in a row that gave no candidate fix (spacing backs off)
  std::int64_t last_query_utime_ = 0;
  int track_failures_ = 0;
  std::deque<std::pair<Eigen::Isometry3d, std::vector<Eigen::Vector3f>>> recent_;  // newest query_sweeps sweeps
  std::future<MapJudgement> map_judgement_;  // last member: joined before the rest is destroyed
};

}  // namespace adit
