// Keeping a query's match across the correspondence rounds of one registration.
//
// Each round re-searches every query at the pose the last round solved for. After the first round that pose
// moves by millimetres to a few centimetres, and a query that moved less than that against neighbours spaced
// 0.2-0.4 m apart finds the same neighbours and fits the same line or plane: the search (KD-tree or voxel
// map, then a 3x3 eigen-solve) is repeated for nothing. MatchReuse remembers, per query, where it was last
// searched and what it found (or that it found nothing), and hands that back while the query stays within
// `tolerance` of that position. A query that moved farther is searched again.
//
// Deterministic: what is reused depends only on the positions, never on the thread that searched. Slots are
// per query index, and parallel_matching.hpp gives every index to exactly one thread per round, so no locks.
// tolerance <= 0 reuses nothing (every round searches, as without this class).
#pragma once

#include "registration/correspondences.hpp"

#include <Eigen/Core>

#include <cstddef>
#include <limits>
#include <optional>
#include <vector>

namespace adit {

class MatchReuse {
 public:
  MatchReuse(std::size_t num_lines, std::size_t num_planes, double tolerance_m)
      : tolerance_sq_(tolerance_m > 0.0 ? tolerance_m * tolerance_m : -1.0), lines_(num_lines), planes_(num_planes) {}

  // search(q) -> std::optional<LineMatch> (or PlaneMatch): the match of query i at its position q in the
  // reference frame. The result, fresh or kept, is appended to `out` if there is one.
  template <class Search>
  void add(std::size_t i, const Eigen::Vector3d& q, std::vector<LineMatch>& out, const Search& search) {
    lookup(lines_[i], q, out, search);
  }
  template <class Search>
  void add(std::size_t i, const Eigen::Vector3d& q, std::vector<PlaneMatch>& out, const Search& search) {
    lookup(planes_[i], q, out, search);
  }

  // Queries answered from a slot, and searched, since construction (for the benchmarks and tests).
  std::size_t reused() const { return count(true); }
  std::size_t searched() const { return count(false); }

 private:
  template <class Match>
  struct Slot {
    Eigen::Vector3d searched_at = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
    std::optional<Match> match;
    int reused = 0, searched = 0;
  };

  template <class Match, class Search>
  void lookup(Slot<Match>& slot, const Eigen::Vector3d& q, std::vector<Match>& out, const Search& search) {
    // NaN (never searched) fails the comparison: searched.
    if ((q - slot.searched_at).squaredNorm() < tolerance_sq_) {
      ++slot.reused;
    } else {
      slot.searched_at = q;
      slot.match = search(q);
      ++slot.searched;
    }
    if (slot.match) out.push_back(*slot.match);
  }

  std::size_t count(bool reused) const {
    std::size_t n = 0;
    for (const auto& s : lines_) n += static_cast<std::size_t>(reused ? s.reused : s.searched);
    for (const auto& s : planes_) n += static_cast<std::size_t>(reused ? s.reused : s.searched);
    return n;
  }

  double tolerance_sq_;
  std::vector<Slot<LineMatch>> lines_;
  std::vector<Slot<PlaneMatch>> planes_;
};

// Query i's match appended to `out`: kept across rounds by `reuse`, or searched afresh when reuse is nullptr.
template <class Match, class Search>
void addMatch(MatchReuse* reuse, std::size_t i, const Eigen::Vector3d& q, std::vector<Match>& out, const Search& search) {
  if (reuse) reuse->add(i, q, out, search);
  else if (const std::optional<Match> m = search(q)) out.push_back(*m);
}

}  // namespace adit
