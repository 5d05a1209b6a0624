// Surface sampling of a scene: the world as a point cloud for visual comparison with a built map.
#include "sim/rng.hpp"
#include "sim/simulator.hpp"

#include <cmath>

namespace adit::sim {
namespace {

// Number of samples for an area: expected value area / spacing^2, randomly rounded (unbiased for small faces).
int sampleCount(double area, double spacing, Rng& rng) {
  const double expected = area / (spacing * spacing);
  const double whole = std::floor(expected);
  return static_cast<int>(whole) + (rng.uniform() < expected - whole ? 1 : 0);
}

void sampleParallelogram(const Eigen::Vector3f& origin, const Eigen::Vector3f& a, const Eigen::Vector3f& b,
                         double spacing, Rng& rng, std::vector<Eigen::Vector3f>& out) {
  const int n = sampleCount(a.cross(b).norm(), spacing, rng);
  for (int i = 0; i < n; ++i) {
    const float s = static_cast<float>(rng.uniform()), t = static_cast<float>(rng.uniform());
    out.push_back(origin + s * a + t * b);
  }
}

}  // namespace

std::vector<Eigen::Vector3f> sampleSurfaces(const Scene& scene, double spacing, std::uint64_t seed) {
  std::vector<Eigen::Vector3f> out;
  if (!(spacing > 0.0)) return out;
  Rng rng = Rng::forStream(seed, Stream::WorldCloud);
  for (const Triangle& t : scene.triangles()) {
    const int n = sampleCount(0.5 * t.e1.cross(t.e2).norm(), spacing, rng);
    for (int i = 0; i < n; ++i) {
      float u = static_cast<float>(rng.uniform()), v = static_cast<float>(rng.uniform());
      if (u + v > 1.0f) {  // fold back into the triangle
        u = 1.0f - u;
        v = 1.0f - v;
      }
      out.push_back(t.a + u * t.e1 + v * t.e2);
    }
  }
  for (const OrientedBox& b : scene.boxes()) {
    for (int axis = 0; axis < 3; ++axis) {
      const int i = (axis + 1) % 3, j = (axis + 2) % 3;
      const Eigen::Vector3f a = 2 * b.half[i] * b.axes.col(i), c = 2 * b.half[j] * b.axes.col(j);
      for (const float side : {-1.0f, 1.0f}) {
        const Eigen::Vector3f corner = b.center + side * b.half[axis] * b.axes.col(axis) - 0.5f * a - 0.5f * c;
        sampleParallelogram(corner, a, c, spacing, rng, out);
      }
    }
  }
  for (const Cylinder& c : scene.cylinders()) {
    const Eigen::Vector3f u = c.axis.unitOrthogonal(), w = c.axis.cross(u);
    const int n = sampleCount(2 * M_PI * c.radius * c.length, spacing, rng);
    for (int i = 0; i < n; ++i) {
      const float phi = static_cast<float>(2 * M_PI * rng.uniform()), s = static_cast<float>(rng.uniform()) * c.length;
      out.push_back(c.base + s * c.axis + c.radius * (std::cos(phi) * u + std::sin(phi) * w));
    }
  }
  return out;
}

}  // namespace adit::sim
