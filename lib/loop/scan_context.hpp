// Scan Context (Kim & Kim, IROS 2018): a rotation-searchable polar image of one sweep, used to recognise a
// place seen before. Rings are concentric annuli on the horizontal plane, sectors are azimuth wedges; each bin
// holds the maximum height of the points falling in it. Its row means (ring key) are rotation invariant and
// index the database; its column means (sector key) give a coarse yaw; the column-shift search gives the
// distance and the yaw between two places.
#pragma once

#include <Eigen/Core>

#include <utility>
#include <vector>

namespace adit {

struct ScanContextConfig {
  // Radial extent (m) of the polar grid. A 16-beam lidar in a 4.5-5 m wide roadway sees the walls at ~2.5 m and
  // the roadway along its axis to 40-80 m, but beyond ~40 m only a few grazing rings of floor/ceiling remain,
  // which change little between places. 40 m keeps the far field that distinguishes junctions and cross-cuts.
  double max_range = 40.0;
  // Points closer than this (m) are ignored: the robot body and the sensor mount, not the place.
  double min_range = 0.5;
  // Number of rings (annuli) over [0, max_range): 20 gives 2 m rings, so a side wall at ~2.5 m lands in ring 1
  // for sideways sectors and the roadway along its axis spreads over all rings; finer rings mostly split the
  // same wall into neighbouring bins and make the descriptor sensitive to a lateral offset in the roadway.
  int rings = 20;
  // Number of azimuth sectors: 60 gives 6 degree wedges, fine enough that a cross-cut or side roadway (an
  // opening of ~40-90 degrees seen from its mouth) spans several sectors, coarse enough for a VLP-16's 0.2 deg
  // azimuth step to fill every bin it sees. It is also the yaw resolution of the place match.
  int sectors = 60;
  // Added (m) to each point's height above the sensor before taking the bin maximum, so that an occupied bin is
  // always > 0 and an empty bin (0) stays distinguishable: a sensor ~1.5-2 m above the floor sees the floor at
  // about -offset. Values below +0.01 are clamped to 0.01 (still occupied).
  double height_offset = 2.0;
  // Half-width (sectors) of the fine column-shift search around each coarse yaw from the sector key.
  int shift_search_radius = 3;
};

class ScanContext {
 public:
  ScanContext() = default;
  // Points are in a sensor-centred frame whose z axis is (close to) vertical. Non-finite points are ignored.
  static ScanContext build(const std::vector<Eigen::Vector3f>& points, const ScanContextConfig& config);
  // The context whose descriptor() is `descriptor` (restoring a checkpoint): identical to the one built.
  static ScanContext fromDescriptor(const Eigen::MatrixXf& descriptor, int shift_search_radius);

  // Distance in [0, 1] (1 - mean cosine similarity of the columns occupied in both) and the best column shift s:
  // this context looks like `other` rotated by +s sectors about z (this = Rz(yaw) * other, see yawOfShift).
  // Distance 1 when either is empty or their shapes differ.
  std::pair<double, int> distance(const ScanContext& other) const;
  // Distance at one given shift (same convention), for tests and diagnostics.
  double distanceAtShift(const ScanContext& other, int shift) const;

  const Eigen::MatrixXf& descriptor() const { return descriptor_; }  // rings x sectors
  const Eigen::VectorXf& ringKey() const { return ring_key_; }       // mean of each ring, rotation invariant
  const Eigen::VectorXf& sectorKey() const { return sector_key_; }   // mean of each sector
  int rings() const { return static_cast<int>(descriptor_.rows()); }
  int sectors() const { return static_cast<int>(descriptor_.cols()); }
  int shiftSearchRadius() const { return shift_search_radius_; }
  bool empty() const { return occupied_bins_ == 0; }
  int occupiedBins() const { return occupied_bins_; }

 private:
  std::vector<int> coarseShifts(const ScanContext& other) const;

  Eigen::MatrixXf descriptor_;
  Eigen::VectorXf ring_key_;
  Eigen::VectorXf sector_key_;
  Eigen::VectorXf column_norm_;
  int occupied_bins_ = 0;
  int shift_search_radius_ = 3;
};

// Yaw (rad, in (-pi, pi]) of a column shift: the rotation about z taking the other scan's frame to this one's.
double yawOfShift(int shift, int sectors);

}  // namespace adit
