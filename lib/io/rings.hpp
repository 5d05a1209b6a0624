// Ring (beam index) assignment for clouds that carry no ring field. Ring 0 = lowest elevation beam.
//
// Two methods:
//  - by elevation: each point gets the beam whose nominal vertical angle is nearest to the point's
//    elevation atan2(z, hypot(x, y)). Right for sensors whose beams all start at the optical centre
//    (VLP-16, RS-16: beams 2 deg apart, far wider than the per-beam scatter).
//  - by scan order: for clouds stored beam by beam (KITTI), a new beam starts where the azimuth crosses
//    the row-start direction again. Needed for the HDL-64E: its lasers sit at different heights on the
//    head, so a beam's apparent elevation scatters by 0.2-0.7 deg, more than the 0.33-0.5 deg between
//    beams, and no elevation table separates them (checked on kitti_mini).
#pragma once

#include <string>
#include <vector>

#include "core/types.hpp"

namespace adit::io {

// Nominal vertical angles (radians), ascending: element k is ring k.
std::vector<double> vlp16Elevations();  // -15..+15 deg by 2 deg (Velodyne VLP-16 manual)
std::vector<double> rs16Elevations();   // -15..+15 deg by 2 deg (RoboSense RS-LiDAR-16 manual, default table)
// HDL-64E: lower block -24.33..-8.83 deg by 1/2 deg, upper block -8.33..+2 deg by 1/3 deg. Nominal only:
// each unit differs (see the header comment); use it as a fallback, not for KITTI.
std::vector<double> hdl64Elevations();
// A uniform fan of `num_beams` beams from min_rad to max_rad (num_beams >= 1; one beam sits at min_rad).
std::vector<double> uniformElevations(int num_beams, double min_rad, double max_rad);
// "vlp16", "rs16" or "hdl64"; an empty vector for any other name.
std::vector<double> beamTable(const std::string& sensor);

struct RingAssignmentStats {
  int num_beams = 0;
  int invalid_points = 0;     // NaN/inf or at the origin: ring 0, left for preprocessing to remove
  int far_from_beam = 0;      // valid points farther than the tolerance from every beam (still assigned)
  std::vector<int> per_ring;  // valid points per ring
};

// Assigns every point the nearest beam of `elevations` (ascending, radians, non-empty).
// `tolerance_rad`: a point farther than this from its beam is counted in far_from_beam.
RingAssignmentStats assignRingsByElevation(std::vector<LidarPoint>& points, const std::vector<double>& elevations,
                                           double tolerance_rad);

// Scan-order assignment for clouds stored beam by beam, top beam first, each beam's row starting at
// the front (azimuth 0) and sweeping counter-clockwise (azimuth increasing) once around: KITTI's layout.
// A row ends where the azimuth crosses 0 from below; a crossing within `min_row_points` points of the
// previous one is jitter, not a new row. If exactly `num_beams` rows are found, sets ring = num_beams-1-row
// and returns true; otherwise leaves the points unchanged and returns false (caller falls back).
bool assignRingsByScanOrder(std::vector<LidarPoint>& points, int num_beams, int min_row_points = 10);
// Rows of a cloud stored beam by beam (as assignRingsByScanOrder counts them); 0 for an empty cloud.
int countScanOrderRows(const std::vector<LidarPoint>& points, int min_row_points = 10);

// The beams a cloud shows in its elevation histogram (0.05 deg bins over +-45 deg, lightly smoothed): each run
// of bins holding more than a fifth of the average non-empty bin is one beam, at the run's weighted mean
// elevation (radians, ascending). Clear for fans whose beams are >= 0.3 deg apart (16- and 32-beam heads);
// for denser fans (HDL-64E, 128-beam heads) neighbouring beams merge and the scan order is the reliable count.
std::vector<double> elevationPeaks(const std::vector<LidarPoint>& points);

// Beam count of a sweep written by an unknown sensor: its scan-order rows if they are a usual fan size
// (16, 32, 40, 64, 128), else the elevation peaks if they are 4..128 of them, else 0 (unknown).
int detectBeamCount(const std::vector<LidarPoint>& points);

// Ring fields number beams either from the bottom (Velodyne, adit's convention) or from the top (Ouster:
// channel 0 is the highest beam). If each ring's mean elevation lies below the previous ring's (at least
// 4 rings), renumbers ring -> max_ring - ring and returns true; any other order is left alone. Points at
// the origin or non-finite are ignored.
bool orientRingsBottomUp(std::vector<LidarPoint>& points);

}  // namespace adit::io
