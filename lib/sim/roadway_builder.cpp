#include "sim/roadway_builder.hpp"

#include <algorithm>
#include <cmath>

namespace adit::sim {
namespace {

// Reflectivities (0..1): coal is dark, steel and painted pipes brighter, bolt plates and equipment brightest.
constexpr float kCoal = 0.12f, kFloor = 0.2f, kSteel = 0.35f, kPlate = 0.5f, kPipe = 0.45f, kCable = 0.08f,
                kEquipment = 0.6f;
constexpr double kCellLength = 0.75; // shell tessellation along a roadway (m)
constexpr int kFloorCells = 4;       // floor tessellation across a roadway
constexpr int kWallRows = 3;         // wall tessellation in height
constexpr int kArchSegments = 6;     // roof tessellation across
constexpr double kTaper = 1.0;       // relief fades to zero within this distance of roadway ends and openings (m)

double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}

// Cross-section polyline from the left wall foot, up the left wall, across the roof, down to the right wall foot;
// coordinates (v = left of the axis, z = up from the floor), with inward unit normals.
struct Section {
  std::vector<Eigen::Vector2d> points, normals;
  int left_wall_last = 0;    // points [0, left_wall_last] are on the left wall
  int right_wall_first = 0;  // points [right_wall_first, end) are on the right wall
  double height = 0.0;       // crown height
};

Section makeSection(double width, double wall_height, double rise) {
  Section s;
  const double half = width / 2;
  for (int k = 0; k <= kWallRows; ++k) {
    s.points.emplace_back(half, wall_height * k / kWallRows);
    s.normals.emplace_back(-1.0, 0.0);
  }
  s.left_wall_last = kWallRows;
  if (rise > 1e-6) {  // circular arch through both wall tops and the crown
    const double radius = (half * half + rise * rise) / (2 * rise);
    const double zc = wall_height + rise - radius;
    const double phi0 = std::atan2(wall_height - zc, half);
    for (int k = 1; k < kArchSegments; ++k) {
      const double phi = phi0 + (M_PI - 2 * phi0) * k / kArchSegments;
      const Eigen::Vector2d p(radius * std::cos(phi), zc + radius * std::sin(phi));
      s.points.push_back(p);
      s.normals.push_back((Eigen::Vector2d(0.0, zc) - p).normalized());
    }
  } else {
    for (int k = 1; k < kArchSegments; ++k) {
      s.points.emplace_back(half - width * k / kArchSegments, wall_height);
      s.normals.emplace_back(0.0, -1.0);
    }
  }
  s.right_wall_first = static_cast<int>(s.points.size());
  for (int k = kWallRows; k >= 0; --k) {
    s.points.emplace_back(-half, wall_height * k / kWallRows);
    s.normals.emplace_back(1.0, 0.0);
  }
  s.height = wall_height + std::max(0.0, rise);
  return s;
}

struct Opening {  // a side cut (niche) in one wall of a roadway
  int side;       // +1 left wall, -1 right wall
  double u0, u1, depth;
};

// One roadway between two junctions, in its own frame: u along the axis from node a, v to the left, z up.
class RoadwayBuilder {
 public:
  RoadwayBuilder(World& world, const Section& section, const Eigen::Vector2d& a, const Eigen::Vector2d& b)
      : w_(world), s_(section), a_(a) {
    const double length = (b - a).norm();
    dir_ = (b - a) / length;
    left_ = Eigen::Vector2d(-dir_.y(), dir_.x());
    u0_ = world.config.width / 2;  // junction chambers are width x width squares around the nodes
    u1_ = length - world.config.width / 2;
  }

  double u0() const { return u0_; }
  double u1() const { return u1_; }

  // World point at (u, v) with local height z above the grade (not above the floor relief).
  Eigen::Vector3d point(double u, double v, double z) const {
    const Eigen::Vector2d xy = a_ + u * dir_ + v * left_;
    return {xy.x(), xy.y(), w_.grade.value(xy.x(), xy.y()) + z};
  }
  Eigen::Vector3d floorPoint(double u, double v) const {
    const Eigen::Vector2d xy = a_ + u * dir_ + v * left_;
    return {xy.x(), xy.y(), w_.groundHeight(xy.x(), xy.y())};
  }
  Eigen::Vector3d direction3(double dv, double dz) const {
    return {dv * left_.x(), dv * left_.y(), dz};
  }
  Eigen::Vector3d axis3() const { return {dir_.x(), dir_.y(), 0.0}; }

  // Section point k at u, with wall relief displaced along the inward normal (zero at the wall feet, near
  // the roadway ends and near openings, so shells of neighbouring pieces meet without cracks).
  Eigen::Vector3d sectionPoint(double u, int k) const {
    const Eigen::Vector2d& p = s_.points[k];
    if (k == 0 || k == static_cast<int>(s_.points.size()) - 1) return floorPoint(u, p.x());
    Eigen::Vector3d q = point(u, p.x(), p.y());
    const double weight = taper(u);
    if (weight > 0.0) q += direction3(s_.normals[k].x(), s_.normals[k].y()) * (weight * w_.wall_relief.value(q.x(), q.y(), q.z()));
    return q;
  }

  double taper(double u) const {
    double d = std::min(u - u0_, u1_ - u);
    for (const Opening& o : openings_) d = std::min(d, std::max({0.0, o.u0 - u, u - o.u1}));
    return smoothstep(d / kTaper);
  }

  void planOpenings(Rng& rng) {
    if (!w_.config.side_cuts) return;
    for (double u = u0_ + rng.uniform(12.0, 40.0); u + 5.0 < u1_ - 10.0; u += rng.uniform(50.0, 90.0)) {
      const double length = rng.uniform(3.0, 5.0), depth = rng.uniform(2.0, 3.5);
      const int side = rng.uniform() < 0.5 ? 1 : -1;
      openings_.push_back({side, u, u + length, depth});
    }
  }

  bool inOpening(int side, double u) const {
    for (const Opening& o : openings_)
      if (o.side == side && u > o.u0 && u < o.u1) return true;
    return false;
  }

  void addShell() {
    std::vector<double> us;
    const int n = std::max(1, static_cast<int>(std::ceil((u1_ - u0_) / kCellLength)));
    for (int i = 0; i <= n; ++i) us.push_back(u0_ + (u1_ - u0_) * i / n);
    for (const Opening& o : openings_) {
      us.push_back(o.u0);
      us.push_back(o.u1);
    }
    std::sort(us.begin(), us.end());
    us.erase(std::unique(us.begin(), us.end(), [](double x, double y) { return std::fabs(x - y) < 1e-6; }), us.end());

    const double half = w_.config.width / 2;
    const int m = static_cast<int>(s_.points.size());
    for (std::size_t i = 0; i + 1 < us.size(); ++i) {
      const double ua = us[i], ub = us[i + 1], um = 0.5 * (ua + ub);
      for (int j = 0; j < kFloorCells; ++j) {
        const double va = -half + w_.config.width * j / kFloorCells, vb = -half + w_.config.width * (j + 1) / kFloorCells;
        quad(floorPoint(ua, va), floorPoint(ub, va), floorPoint(ub, vb), floorPoint(ua, vb), kFloor);
      }
      for (int k = 0; k + 1 < m; ++k) {
        if (k < s_.left_wall_last && inOpening(1, um)) continue;
        if (k >= s_.right_wall_first && inOpening(-1, um)) continue;
        quad(sectionPoint(ua, k), sectionPoint(ub, k), sectionPoint(ub, k + 1), sectionPoint(ua, k + 1), kCoal);
      }
    }
    // Header panels: close the gap between the arch and the flat roof of the junction chambers at both ends.
    if (w_.config.roof_rise > 1e-6) {
      for (const double u : {u0_, u1_}) {
        for (int k = s_.left_wall_last; k < s_.right_wall_first; ++k) {
          const double va = s_.points[k].x(), vb = s_.points[k + 1].x();
          quad(sectionPoint(u, k), sectionPoint(u, k + 1), point(u, vb, s_.height), point(u, va, s_.height), kCoal);
        }
      }
    }
    for (const Opening& o : openings_) addNiche(o);
  }

  void addNiche(const Opening& o) {
    const double half = w_.config.width / 2, hw = w_.config.wall_height;
    const double v_mouth = o.side * half, v_back = o.side * (half + o.depth);
    const int nu = std::max(1, static_cast<int>(std::ceil((o.u1 - o.u0) / kCellLength)));
    const int nv = std::max(1, static_cast<int>(std::ceil(o.depth / kCellLength)));
    for (int i = 0; i < nu; ++i) {
      const double ua = o.u0 + (o.u1 - o.u0) * i / nu, ub = o.u0 + (o.u1 - o.u0) * (i + 1) / nu;
      for (int j = 0; j < nv; ++j) {
        const double va = v_mouth + (v_back - v_mouth) * j / nv, vb = v_mouth + (v_back - v_mouth) * (j + 1) / nv;
        quad(floorPoint(ua, va), floorPoint(ub, va), floorPoint(ub, vb), floorPoint(ua, vb), kFloor);
        quad(point(ua, va, hw), point(ub, va, hw), point(ub, vb, hw), point(ua, vb, hw), kCoal);
      }
      quad(floorPoint(ua, v_back), floorPoint(ub, v_back), point(ub, v_back, hw), point(ua, v_back, hw), kCoal);
    }
    for (const double u : {o.u0, o.u1}) {
      for (int j = 0; j < nv; ++j) {
        const double va = v_mouth + (v_back - v_mouth) * j / nv, vb = v_mouth + (v_back - v_mouth) * (j + 1) / nv;
        quad(floorPoint(u, va), floorPoint(u, vb), point(u, vb, hw), point(u, va, hw), kCoal);
      }
    }
  }

  // Steel support arches: I-section sets following the section, 10 cm deep, every arch_spacing.
  void addSupportArches(Rng& rng) {
    const int m = static_cast<int>(s_.points.size());
    for (double u = u0_ + 0.6 + rng.uniform(0.0, 0.5); u < u1_ - 0.6; u += w_.config.arch_spacing + rng.uniform(-0.15, 0.15)) {
      for (int k = 0; k + 1 < m; ++k) {
        if (k < s_.left_wall_last && inOpening(1, u)) continue;
        if (k >= s_.right_wall_first && inOpening(-1, u)) continue;
        const Eigen::Vector3d p0 = point(u, s_.points[k].x(), s_.points[k].y());
        const Eigen::Vector3d p1 = point(u, s_.points[k + 1].x(), s_.points[k + 1].y());
        const Eigen::Vector2d n2 = (s_.normals[k] + s_.normals[k + 1]).normalized();
        const Eigen::Vector3d inward = direction3(n2.x(), n2.y());
        Eigen::Matrix3f axes;
        axes.col(0) = axis3().cast<float>();
        axes.col(1) = (p1 - p0).normalized().cast<float>();
        axes.col(2) = axes.col(0).cross(axes.col(1)).normalized();
        const Eigen::Vector3d centre = 0.5 * (p0 + p1) + inward * 0.04;  // 2 cm inside the rock, 10 cm proud
        box(centre, axes, {0.05, 0.5 * (p1 - p0).norm() + 0.02, 0.06}, kSteel);
      }
    }
  }

  // Roof bolts: 5 a row; a 15 cm square plate and a 6 cm tail, on the relief-displaced roof surface.
  void addRoofBolts(Rng& rng) {
    const double half = w_.config.width / 2, hw = w_.config.wall_height, rise = w_.config.roof_rise;
    for (double u = u0_ + 0.5 + rng.uniform(0.0, 0.5); u < u1_ - 0.5; u += w_.config.bolt_spacing + rng.uniform(-0.05, 0.05)) {
      for (int j = -2; j <= 2; ++j) {
        const double v = j * half * 0.36 + rng.uniform(-0.04, 0.04);
        Eigen::Vector2d p(v, hw), n(0.0, -1.0);
        if (rise > 1e-6) {
          const double radius = (half * half + rise * rise) / (2 * rise), zc = hw + rise - radius;
          p.y() = zc + std::sqrt(radius * radius - v * v);
          n = (Eigen::Vector2d(0.0, zc) - p).normalized();
        }
        const Eigen::Vector3d inward = direction3(n.x(), n.y());
        Eigen::Vector3d surface = point(u, p.x(), p.y());
        surface += inward * (taper(u) * w_.wall_relief.value(surface.x(), surface.y(), surface.z()));
        Eigen::Matrix3f axes;
        axes.col(2) = inward.cast<float>();
        axes.col(0) = axis3().cast<float>();
        axes.col(1) = axes.col(2).cross(axes.col(0)).normalized();
        box(surface + inward * 0.005, axes, {0.075, 0.075, 0.012}, kPlate);
        w_.scene.addCylinder((surface + inward * 0.017).cast<float>(), (surface + inward * 0.07).cast<float>(), 0.011f, kSteel);
      }
    }
  }

  // Pipes on brackets along the left wall, cables sagging between hooks along the right wall.
  void addServices(Rng& rng) {
    const double half = w_.config.width / 2, hw = w_.config.wall_height;
    const int pipes = 1 + rng.uniformInt(2);
    for (int i = 0; i < pipes; ++i) {
      const double radius = rng.uniform(0.06, 0.12), z = hw - 0.35 - 0.4 * i, v = half - 0.12 - radius;
      for (double u = u0_; u < u1_ - 1e-6; u += 6.0) {  // 6 m pieces follow the grade
        const double ub = std::min(u + 6.0, u1_);
        w_.scene.addCylinder(point(u, v, z).cast<float>(), point(ub, v, z).cast<float>(), static_cast<float>(radius), kPipe);
      }
      for (double u = u0_ + 1.5; u < u1_ - 0.5; u += 3.0) {
        const double vb = 0.5 * (half + v);
        box(point(u, vb, z - radius - 0.02), axesAlong(), {0.03, 0.5 * (half - v) + 0.02, 0.02}, kSteel);
      }
    }
    const double hook_pitch = 1.5, sag = 0.05;
    for (int c = 0; c < 3; ++c) {
      const double radius = rng.uniform(0.018, 0.03), z = hw * (0.5 + 0.08 * c), v = -(half - 0.06 - radius);
      for (double u = u0_ + 0.3; u + hook_pitch < u1_ - 0.3; u += hook_pitch) {
        const Eigen::Vector3f h0 = point(u, v, z).cast<float>(), h1 = point(u + hook_pitch, v, z).cast<float>();
        const Eigen::Vector3f mid = point(u + 0.5 * hook_pitch, v, z - sag).cast<float>();
        w_.scene.addCylinder(h0, mid, static_cast<float>(radius), kCable);
        w_.scene.addCylinder(mid, h1, static_cast<float>(radius), kCable);
      }
    }
  }

  // Equipment (switchgear, pumps, transformers) on the floor against a wall, clear of niches.
  void addEquipment(Rng& rng) {
    const double half = w_.config.width / 2;
    for (double u = u0_ + rng.uniform(5.0, 25.0); u < u1_ - 5.0; u += rng.uniform(25.0, 60.0)) {
      const double length = rng.uniform(1.2, 3.0), depth = rng.uniform(0.7, 1.1), height = rng.uniform(0.8, 1.5);
      const int side = rng.uniform() < 0.5 ? 1 : -1;
      if (u + length > u1_ - 3.0) break;
      bool clear = true;
      for (const Opening& o : openings_) clear = clear && (u + length < o.u0 - 1.0 || u > o.u1 + 1.0);
      if (!clear) continue;
      const double um = u + length / 2, v = side * (half - 0.15 - depth / 2);
      const Eigen::Vector3d foot = floorPoint(um, v);
      box(Eigen::Vector3d(foot.x(), foot.y(), foot.z() + height / 2 - 0.02), axesAlong(),
          {length / 2, depth / 2, height / 2}, kEquipment);
    }
  }

 private:
  Eigen::Matrix3f axesAlong() const {
    Eigen::Matrix3f axes;
    axes.col(0) = axis3().cast<float>();
    axes.col(1) = Eigen::Vector3f(static_cast<float>(left_.x()), static_cast<float>(left_.y()), 0.0f);
    axes.col(2) = Eigen::Vector3f::UnitZ();
    return axes;
  }
  void quad(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, const Eigen::Vector3d& d,
            float reflectivity) {
    w_.scene.addQuad(a.cast<float>(), b.cast<float>(), c.cast<float>(), d.cast<float>(), reflectivity);
  }
  void box(const Eigen::Vector3d& centre, const Eigen::Matrix3f& axes, const Eigen::Vector3d& half, float reflectivity) {
    w_.scene.addBox(centre.cast<float>(), axes, half.cast<float>(), reflectivity);
  }

  World& w_;
  const Section& s_;
  Eigen::Vector2d a_, dir_, left_;
  double u0_ = 0.0, u1_ = 0.0;
  std::vector<Opening> openings_;
};

// Junction chamber: a width x width square around the node with a flat roof at crown height; sides without a
// roadway are closed by a wall.
void addJunction(World& world, const Section& section, int node) {
  const Eigen::Vector2d c = world.network.nodes[node];
  const double half = world.config.width / 2, h = section.height;
  auto ground = [&](double x, double y) { return Eigen::Vector3f(float(x), float(y), float(world.groundHeight(x, y))); };
  auto roof = [&](double x, double y) { return Eigen::Vector3f(float(x), float(y), float(world.grade.value(x, y) + h)); };
  const int n = kFloorCells;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const double xa = c.x() - half + 2 * half * i / n, xb = c.x() - half + 2 * half * (i + 1) / n;
      const double ya = c.y() - half + 2 * half * j / n, yb = c.y() - half + 2 * half * (j + 1) / n;
      world.scene.addQuad(ground(xa, ya), ground(xb, ya), ground(xb, yb), ground(xa, yb), kFloor);
      world.scene.addQuad(roof(xa, ya), roof(xb, ya), roof(xb, yb), roof(xa, yb), kCoal);
    }
  }
  const Eigen::Vector2d sides[4] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
  for (const Eigen::Vector2d& side : sides) {
    bool open = false;
    for (const auto& e : world.network.edges) {
      const int other = e.first == node ? e.second : (e.second == node ? e.first : -1);
      if (other >= 0 && (world.network.nodes[other] - c).normalized().dot(side) > 0.99) open = true;
    }
    if (open) continue;
    const Eigen::Vector2d along(-side.y(), side.x());
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d pa = c + side * half + along * (-half + 2 * half * i / n);
      const Eigen::Vector2d pb = c + side * half + along * (-half + 2 * half * (i + 1) / n);
      world.scene.addQuad(ground(pa.x(), pa.y()), ground(pb.x(), pb.y()), roof(pb.x(), pb.y()), roof(pa.x(), pa.y()), kCoal);
    }
  }
}

}  // namespace

void addRoadwayGeometry(World& world, Rng& rng) {
  const WorldConfig& cfg = world.config;
  const Section section = makeSection(cfg.width, cfg.wall_height, cfg.roof_rise);
  for (int i = 0; i < static_cast<int>(world.network.nodes.size()); ++i) addJunction(world, section, i);
  for (const auto& [a, b] : world.network.edges) {
    RoadwayBuilder road(world, section, world.network.nodes[a], world.network.nodes[b]);
    if (road.u1() - road.u0() < 0.1) continue;
    road.planOpenings(rng);
    road.addShell();
    if (cfg.support_arches) road.addSupportArches(rng);
    if (cfg.roof_bolts) road.addRoofBolts(rng);
    if (cfg.services) road.addServices(rng);
    if (cfg.equipment) road.addEquipment(rng);
  }
}

}  // namespace adit::sim
