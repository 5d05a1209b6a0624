#include "sim/scene.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

namespace adit::sim {
namespace {

constexpr int kMaxLeafSize = 4;
constexpr int kBins = 16;

float area(const Eigen::AlignedBox3f& b) {
  if (b.isEmpty()) return 0.0f;
  const Eigen::Vector3f e = b.sizes();
  return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
}

// Direction inverse that never produces NaN in the slab test (0 * inf).
Eigen::Vector3f safeInverse(const Eigen::Vector3f& d) {
  Eigen::Vector3f inv;
  for (int i = 0; i < 3; ++i) inv[i] = 1.0f / (std::fabs(d[i]) > 1e-20f ? d[i] : std::copysign(1e-20f, d[i]));
  return inv;
}

bool hitTriangle(const Triangle& tri, const Ray& ray, float t_min, float& t, Eigen::Vector3f& normal) {
  const Eigen::Vector3f p = ray.dir.cross(tri.e2);
  const float det = tri.e1.dot(p);
  if (std::fabs(det) < 1e-12f) return false;
  const float inv = 1.0f / det;
  const Eigen::Vector3f s = ray.origin - tri.a;
  const float u = s.dot(p) * inv;
  if (u < 0.0f || u > 1.0f) return false;
  const Eigen::Vector3f q = s.cross(tri.e1);
  const float v = ray.dir.dot(q) * inv;
  if (v < 0.0f || u + v > 1.0f) return false;
  const float th = tri.e2.dot(q) * inv;
  if (th <= t_min || th >= t) return false;
  t = th;
  normal = tri.e1.cross(tri.e2).normalized();
  return true;
}

bool hitBox(const OrientedBox& box, const Ray& ray, float t_min, float& t, Eigen::Vector3f& normal) {
  const Eigen::Vector3f o = box.axes.transpose() * (ray.origin - box.center);
  const Eigen::Vector3f d = box.axes.transpose() * ray.dir;
  const Eigen::Vector3f inv = safeInverse(d);
  float t_enter = -std::numeric_limits<float>::infinity(), t_exit = std::numeric_limits<float>::infinity();
  int axis = 0;
  for (int i = 0; i < 3; ++i) {
    float a = (-box.half[i] - o[i]) * inv[i], b = (box.half[i] - o[i]) * inv[i];
    if (a > b) std::swap(a, b);
    if (a > t_enter) {
      t_enter = a;
      axis = i;
    }
    t_exit = std::min(t_exit, b);
  }
  if (t_enter > t_exit || t_enter <= t_min || t_enter >= t) return false;  // origin inside a box: no hit
  t = t_enter;
  normal = box.axes.col(axis) * (d[axis] > 0.0f ? -1.0f : 1.0f);
  return true;
}

bool hitCylinder(const Cylinder& c, const Ray& ray, float t_min, float& t, Eigen::Vector3f& normal) {
  bool found = false;
  const Eigen::Vector3f w = ray.origin - c.base;
  const float dw = ray.dir.dot(c.axis), ww = w.dot(c.axis);
  const Eigen::Vector3f dp = ray.dir - dw * c.axis, wp = w - ww * c.axis;
  const float a = dp.squaredNorm(), b = 2.0f * dp.dot(wp), cc = wp.squaredNorm() - c.radius * c.radius;
  if (a > 1e-12f) {
    const float disc = b * b - 4.0f * a * cc;
    if (disc >= 0.0f) {
      const float th = (-b - std::sqrt(disc)) / (2.0f * a);  // entry side only: origin is never inside
      const float s = ww + th * dw;
      if (th > t_min && th < t && s >= 0.0f && s <= c.length) {
        t = th;
        normal = (wp + th * dp).normalized();
        found = true;
      }
    }
  }
  if (std::fabs(dw) > 1e-12f) {  // caps
    for (const float s_cap : {0.0f, c.length}) {
      const float th = (s_cap - ww) / dw;
      if (th <= t_min || th >= t) continue;
      if ((wp + th * dp).squaredNorm() > c.radius * c.radius) continue;
      t = th;
      normal = c.axis;
      found = true;
    }
  }
  return found;
}

}  // namespace

void Scene::addTriangle(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c,
                        float reflectivity) {
  const Eigen::Vector3f e1 = b - a, e2 = c - a;
  if (e1.cross(e2).squaredNorm() < 1e-14f) return;  // degenerate
  refs_.push_back({Shape::Triangle, static_cast<std::uint32_t>(triangles_.size()), reflectivity});
  triangles_.push_back({a, e1, e2});
}

void Scene::addQuad(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c,
                    const Eigen::Vector3f& d, float reflectivity) {
  addTriangle(a, b, c, reflectivity);
  addTriangle(a, c, d, reflectivity);
}

void Scene::addBox(const Eigen::Vector3f& center, const Eigen::Matrix3f& axes, const Eigen::Vector3f& half,
                   float reflectivity) {
  if ((half.array() <= 0.0f).any()) return;
  refs_.push_back({Shape::Box, static_cast<std::uint32_t>(boxes_.size()), reflectivity});
  boxes_.push_back({center, axes, half});
}

void Scene::addCylinder(const Eigen::Vector3f& p0, const Eigen::Vector3f& p1, float radius, float reflectivity) {
  const float length = (p1 - p0).norm();
  if (length < 1e-6f || radius <= 0.0f) return;
  refs_.push_back({Shape::Cylinder, static_cast<std::uint32_t>(cylinders_.size()), reflectivity});
  cylinders_.push_back({p0, (p1 - p0) / length, length, radius});
}

Eigen::AlignedBox3f Scene::refBounds(const Ref& r) const {
  Eigen::AlignedBox3f b;
  switch (r.shape) {
    case Shape::Triangle: {
      const Triangle& t = triangles_[r.index];
      b.extend(t.a);
      b.extend(Eigen::Vector3f(t.a + t.e1));
      b.extend(Eigen::Vector3f(t.a + t.e2));
      break;
    }
    case Shape::Box: {
      const OrientedBox& x = boxes_[r.index];
      const Eigen::Vector3f extent = x.axes.cwiseAbs() * x.half;
      b.extend(Eigen::Vector3f(x.center - extent));
      b.extend(Eigen::Vector3f(x.center + extent));
      break;
    }
    case Shape::Cylinder: {
      const Cylinder& c = cylinders_[r.index];
      // Exact AABB of a capped cylinder: radius * sqrt(1 - axis_i^2) around both cap centres.
      const Eigen::Vector3f pad = c.radius * (Eigen::Vector3f::Ones() - c.axis.cwiseAbs2()).cwiseMax(0.0f).cwiseSqrt();
      const Eigen::Vector3f end = c.base + c.length * c.axis;
      b.extend(Eigen::Vector3f(c.base - pad));
      b.extend(Eigen::Vector3f(c.base + pad));
      b.extend(Eigen::Vector3f(end - pad));
      b.extend(Eigen::Vector3f(end + pad));
      break;
    }
  }
  return b;
}

bool Scene::intersectRef(const Ref& r, const Ray& ray, float t_min, Hit& hit) const {
  bool found = false;
  switch (r.shape) {
    case Shape::Triangle: found = hitTriangle(triangles_[r.index], ray, t_min, hit.t, hit.normal); break;
    case Shape::Box: found = hitBox(boxes_[r.index], ray, t_min, hit.t, hit.normal); break;
    case Shape::Cylinder: found = hitCylinder(cylinders_[r.index], ray, t_min, hit.t, hit.normal); break;
  }
  if (found) hit.reflectivity = r.reflectivity;
  return found;
}

void Scene::build() {
  nodes_.clear();
  if (refs_.empty()) return;
  std::vector<Eigen::AlignedBox3f> boxes(refs_.size());
  std::vector<Eigen::Vector3f> centroids(refs_.size());
  for (std::size_t i = 0; i < refs_.size(); ++i) {
    boxes[i] = refBounds(refs_[i]);
    centroids[i] = boxes[i].center();
  }
  nodes_.reserve(2 * refs_.size() / kMaxLeafSize + 1);
  buildNode(boxes, centroids, 0, static_cast<int>(refs_.size()));
}

// Recursive binned-SAH build over refs_[first, first+count); boxes/centroids are permuted along with refs_.
int Scene::buildNode(std::vector<Eigen::AlignedBox3f>& boxes, std::vector<Eigen::Vector3f>& centroids, int first,
                     int count) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.push_back(Node{});
  Eigen::AlignedBox3f bounds, centre_bounds;
  for (int i = first; i < first + count; ++i) {
    bounds.extend(boxes[i]);
    centre_bounds.extend(centroids[i]);
  }
  for (int k = 0; k < 3; ++k) {
    nodes_[index].lo[k] = bounds.min()[k];
    nodes_[index].hi[k] = bounds.max()[k];
  }
  auto makeLeaf = [&] {
    nodes_[index].first_or_right = first;
    nodes_[index].count = count;
    return index;
  };
  if (count <= kMaxLeafSize) return makeLeaf();

  // Best SAH split over 3 axes x (kBins - 1) planes.
  float best_cost = std::numeric_limits<float>::infinity();
  int best_axis = -1, best_plane = 0;
  const Eigen::Vector3f extent = centre_bounds.sizes();
  for (int axis = 0; axis < 3; ++axis) {
    if (extent[axis] <= 1e-9f) continue;
    std::array<Eigen::AlignedBox3f, kBins> bin_box;
    std::array<int, kBins> bin_count{};
    const float scale = kBins / extent[axis];
    for (int i = first; i < first + count; ++i) {
      const int b = std::min(kBins - 1, static_cast<int>((centroids[i][axis] - centre_bounds.min()[axis]) * scale));
      bin_box[b].extend(boxes[i]);
      ++bin_count[b];
    }
    std::array<float, kBins> right_cost{};
    Eigen::AlignedBox3f acc;
    int n = 0;
    for (int b = kBins - 1; b > 0; --b) {
      acc.extend(bin_box[b]);
      n += bin_count[b];
      right_cost[b] = n * area(acc);
    }
    acc.setEmpty();
    n = 0;
    for (int b = 0; b < kBins - 1; ++b) {
      acc.extend(bin_box[b]);
      n += bin_count[b];
      const float cost = n * area(acc) + right_cost[b + 1];
      if (n > 0 && n < count && cost < best_cost) {
        best_cost = cost;
        best_axis = axis;
        best_plane = b;
      }
    }
  }

  int mid = first + count / 2;
  if (best_axis >= 0) {
    const float scale = kBins / extent[best_axis];
    const float lo = centre_bounds.min()[best_axis];
    int i = first, j = first + count - 1;
    while (i <= j) {  // partition, keeping the three arrays in step
      const int b = std::min(kBins - 1, static_cast<int>((centroids[i][best_axis] - lo) * scale));
      if (b <= best_plane) {
        ++i;
      } else {
        std::swap(refs_[i], refs_[j]);
        std::swap(boxes[i], boxes[j]);
        std::swap(centroids[i], centroids[j]);
        --j;
      }
    }
    mid = i;
    if (mid == first || mid == first + count) mid = first + count / 2;
  }
  buildNode(boxes, centroids, first, mid - first);  // left child is index + 1
  const int right = buildNode(boxes, centroids, mid, first + count - mid);
  nodes_[index].first_or_right = right;
  nodes_[index].count = 0;
  return index;
}

Hit Scene::intersect(const Ray& ray, float t_min) const {
  Hit hit;
  hit.t = ray.t_max;
  if (nodes_.empty()) return Hit{};
  const Eigen::Vector3f inv = safeInverse(ray.dir);
  const Eigen::Vector3f o = ray.origin;
  // Entry distance into a node's box, or +inf if the ray misses it before the current best hit.
  auto entry = [&](const Node& n) {
    float t0 = t_min, t1 = hit.t;
    for (int k = 0; k < 3; ++k) {
      float a = (n.lo[k] - o[k]) * inv[k], b = (n.hi[k] - o[k]) * inv[k];
      if (a > b) std::swap(a, b);
      t0 = a > t0 ? a : t0;
      t1 = b < t1 ? b : t1;
    }
    return t0 <= t1 ? t0 : std::numeric_limits<float>::infinity();
  };
  struct Pending {
    int node;
    float t;
  };
  Pending stack[64];
  int sp = 0;
  int node = entry(nodes_[0]) < std::numeric_limits<float>::infinity() ? 0 : -1;
  while (node >= 0) {
    const Node& n = nodes_[node];
    if (n.count > 0) {
      for (int i = n.first_or_right; i < n.first_or_right + n.count; ++i)
        if (intersectRef(refs_[i], ray, t_min, hit)) hit.primitive = i;
      node = -1;
    } else {
      int near = node + 1, far = n.first_or_right;
      float t_near = entry(nodes_[near]), t_far = entry(nodes_[far]);
      if (t_far < t_near) {
        std::swap(near, far);
        std::swap(t_near, t_far);
      }
      if (t_far < std::numeric_limits<float>::infinity() && sp < 64) stack[sp++] = {far, t_far};
      node = t_near < std::numeric_limits<float>::infinity() ? near : -1;
    }
    while (node < 0 && sp > 0) {
      const Pending p = stack[--sp];
      if (p.t <= hit.t) node = p.node;
    }
  }
  if (hit.primitive < 0) return Hit{};
  return hit;
}

Hit Scene::intersectBruteForce(const Ray& ray, float t_min) const {
  Hit hit;
  hit.t = ray.t_max;
  for (std::size_t i = 0; i < refs_.size(); ++i)
    if (intersectRef(refs_[i], ray, t_min, hit)) hit.primitive = static_cast<int>(i);
  if (hit.primitive < 0) return Hit{};
  return hit;
}

Eigen::AlignedBox3f Scene::bounds() const {
  Eigen::AlignedBox3f b;
  if (!nodes_.empty()) {
    b.extend(Eigen::Vector3f(nodes_[0].lo[0], nodes_[0].lo[1], nodes_[0].lo[2]));
    b.extend(Eigen::Vector3f(nodes_[0].hi[0], nodes_[0].hi[1], nodes_[0].hi[2]));
  }
  return b;
}

}  // namespace adit::sim
