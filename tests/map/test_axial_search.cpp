// The search along a fit's weak translation (map/axial_search.hpp) on a synthetic roadway: 4 m wide, 3 m high,
// a steel rib every 2 m. A query seen from one place fits the cross-section wherever it is put along the
// roadway. With one niche in view the search must find the true place; with ribs alone (every place 2 m on
// looks the same) it must refuse rather than guess.
#include "loop/loop_verifier.hpp"
#include "map/axial_search.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace adit {
namespace {

using Cloud = std::vector<Eigen::Vector3f>;

void addRect(Cloud& c, const Eigen::Vector3f& origin, const Eigen::Vector3f& u, const Eigen::Vector3f& v, float step) {
  const int nu = static_cast<int>(u.norm() / step), nv = static_cast<int>(v.norm() / step);
  for (int i = 0; i <= nu; ++i)
    for (int j = 0; j <= nv; ++j) c.push_back(origin + u * (static_cast<float>(i) / nu) + v * (static_cast<float>(j) / nv));
}

// Walls y = +-2, floor z = 0, roof z = 3 over x in [x0, x1]; ribs (0.3 m deep, 0.3 m wide) every 2 m on walls
// and roof; a niche (4 m long, 2 m deep) in the left wall at x = 6 when `niche`.
Cloud roadway(float x0, float x1, bool niche) {
  Cloud c;
  const float s = 0.1f, L = x1 - x0;
  addRect(c, {x0, -2, 0}, {L, 0, 0}, {0, 4, 0}, s);
  addRect(c, {x0, -2, 3}, {L, 0, 0}, {0, 4, 0}, s);
  addRect(c, {x0, -2, 0}, {L, 0, 0}, {0, 0, 3}, s);
  if (!niche) {
    addRect(c, {x0, 2, 0}, {L, 0, 0}, {0, 0, 3}, s);
  } else {
    addRect(c, {x0, 2, 0}, {6.0f - x0, 0, 0}, {0, 0, 3}, s);
    addRect(c, {10.0f, 2, 0}, {x1 - 10.0f, 0, 0}, {0, 0, 3}, s);
    addRect(c, {6.0f, 4.0f, 0}, {4.0f, 0, 0}, {0, 0, 2.5f}, s);  // back
    addRect(c, {6.0f, 2, 0}, {0, 2.0f, 0}, {0, 0, 2.5f}, s);     // sides
    addRect(c, {10.0f, 2, 0}, {0, 2.0f, 0}, {0, 0, 2.5f}, s);
    addRect(c, {6.0f, 2, 2.5f}, {4.0f, 0, 0}, {0, 2.0f, 0}, s);  // top
  }
  for (float x = std::ceil(x0 / 2) * 2; x <= x1; x += 2.0f) {
    for (float side : {-1.0f, 1.0f}) {
      const float wall = 2.0f * side, inner = 1.7f * side;
      addRect(c, {x - 0.15f, inner, 0}, {0.3f, 0, 0}, {0, 0, 2.7f}, s);          // face
      addRect(c, {x - 0.15f, inner, 0}, {0, wall - inner, 0}, {0, 0, 2.7f}, s);  // flanks
      addRect(c, {x + 0.15f, inner, 0}, {0, wall - inner, 0}, {0, 0, 2.7f}, s);
    }
    addRect(c, {x - 0.15f, -1.7f, 2.7f}, {0.3f, 0, 0}, {0, 3.4f, 0}, s);        // roof rib
    addRect(c, {x - 0.15f, -1.7f, 2.7f}, {0, 3.4f, 0}, {0, 0, 0.3f}, s);
    addRect(c, {x + 0.15f, -1.7f, 2.7f}, {0, 3.4f, 0}, {0, 0, 0.3f}, s);
  }
  return c;
}

struct Outcome {
  AxialSearchResult search;
  double error_m = 0;
};

// The query is the roadway seen within 8 m of the lidar at x = 7.9 (1.2 m above the floor); the fit to search
// starts 3.3 m off along the roadway (ribs and niche misaligned: nothing there pins the position along it).
Outcome searchFrom(bool niche) {
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
  truth.translation() = Eigen::Vector3d(7.9, 0.1, 1.2);
  Cloud query;
  for (const Eigen::Vector3f& p : roadway(-4.0f, 13.0f, niche))
    if ((p.cast<double>() - truth.translation()).norm() < 8.0) query.push_back((truth.inverse() * p.cast<double>()).cast<float>());
  const LoopVerifierConfig verifier;
  const PlaneTarget target(roadway(-20.0f, 30.0f, niche), verifier.icp);
  const std::vector<Eigen::Vector3f> source = querySource(query, verifier);
  Eigen::Isometry3d seed = truth;
  seed.translation().x() += 3.3;
  const LoopVerification fit = verifyLoopAgainst(target, source, {seed}, verifier);
  EXPECT_TRUE(fitsTightly(fit.icp, verifier)) << "rms " << fit.icp.rms << " inliers " << fit.icp.inlier_ratio;
  Outcome out;
  out.search = searchWeakDirection(target, source, fit.icp, verifier, AxialSearchConfig{});
  out.error_m = (out.search.T_target_source.translation() - truth.translation()).norm();
  return out;
}

TEST(AxialSearch, ANicheInViewPinsThePlaceAlongTheRoadway) {
  const Outcome o = searchFrom(true);
  EXPECT_TRUE(o.search.resolved) << o.search.refusal << ": best " << o.search.icp.inlier_ratio << ", runner-up "
                                 << o.search.runner_up;
  EXPECT_LT(o.error_m, 0.1);
}

TEST(AxialSearch, RibsAloneAreRefusedNotGuessed) {
  const Outcome o = searchFrom(false);
  EXPECT_FALSE(o.search.resolved) << "accepted a place " << o.error_m << " m from the truth";
  EXPECT_STREQ(o.search.refusal, "ambiguous") << "axis " << o.search.axis.transpose() << " best " << o.search.icp.inlier_ratio;
  EXPECT_GT(o.search.runner_up, 0.0);
}

}  // namespace
}  // namespace adit
