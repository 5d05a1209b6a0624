// Moving the points of a raw (not deskewed) sweep to its end instant with a constant-velocity motion,
// used only to make the two sides of a registration consistent when exactly one of them was deskewed
// upstream (start-up, before the feature stage has a motion prior, or a deskew outage). Registering a raw
// sweep against a deskewed one at 10-15 m/s (KITTI) errs by half a metre; both raw or both deskewed is fine.
#pragma once

#include "core/types.hpp"

#include <vector>

namespace adit {

// p <- T_end_at(dt) * p, with the lidar pose at time dt (<= 0, relative to the sweep end) interpolated between
// identity (dt = 0) and T_prev_curr^-1 (dt = -gap_s): the sweep moved as it moved between the two sweeps.
void compensateMotion(std::vector<LidarPoint>& points, const Eigen::Isometry3d& T_prev_curr, double gap_s);

}  // namespace adit
