#include "sim/scene.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

namespace adit::sim {
namespace {

constexpr int kMaxLeafSize = 2;  // measured: 2 beats 1, 3 and 4 for lidar rays in roadways
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

template <class TriangleTest>
bool hitTriangle(const TriangleTest& tri, const Ray& ray, float t_min, float& t, Eigen::Vector3f& normal) {
  const float denom = tri.normal.dot(ray.dir);
  if (std::fabs(denom) < 1e-12f) return false;
  const float th = tri.normal.dot(tri.a - ray.origin) / denom;
  if (!(th > t_min && th < t)) return false;
  const Eigen::Vector3f q = ray.origin + th * ray.dir - tri.a;
  const float u = q.dot(tri.bu), v = q.dot(tri.bv);
  if (u < 0.0f || v < 0.0f || u + v > 1.0f) return false;
  t = th;
  normal = tri.normal;
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
    case Shape::Triangle: found = hitTriangle(triangle_tests_[r.index], ray, t_min, hit.t, hit.normal); break;
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
  bounds_ = Eigen::AlignedBox3f(Eigen::Vector3f(nodes_[0].lo[0], nodes_[0].lo[1], nodes_[0].lo[2]),
                                Eigen::Vector3f(nodes_[0].hi[0], nodes_[0].hi[1], nodes_[0].hi[2]));
  // Store primitives in leaf order so a leaf's data is contiguous in memory.
  std::vector<Triangle> triangles;
  std::vector<OrientedBox> boxes_sorted;
  std::vector<Cylinder> cylinders;
  triangles.reserve(triangles_.size());
  boxes_sorted.reserve(boxes_.size());
  cylinders.reserve(cylinders_.size());
  for (Ref& r : refs_) {
    switch (r.shape) {
      case Shape::Triangle: triangles.push_back(triangles_[r.index]); r.index = static_cast<std::uint32_t>(triangles.size() - 1); break;
      case Shape::Box: boxes_sorted.push_back(boxes_[r.index]); r.index = static_cast<std::uint32_t>(boxes_sorted.size() - 1); break;
      case Shape::Cylinder: cylinders.push_back(cylinders_[r.index]); r.index = static_cast<std::uint32_t>(cylinders.size() - 1); break;
    }
  }
  triangles_.swap(triangles);
  triangle_tests_.clear();
  triangle_tests_.reserve(triangles_.size());
  for (const Triangle& t : triangles_) {
    const Eigen::Vector3f n = t.e1.cross(t.e2);
    const float n2 = n.squaredNorm();
    triangle_tests_.push_back({t.a, n / std::sqrt(n2), t.e2.cross(n) / n2, n.cross(t.e1) / n2});
  }
  boxes_.swap(boxes_sorted);
  cylinders_.swap(cylinders);
  nodes4_.clear();
  nodes4_.reserve(nodes_.size() / 2 + 1);
  collapse(0);
  nodes_.clear();
  nodes_.shrink_to_fit();
}

// Collapses the binary subtree at `binary_node` into 4-wide nodes: a node's children are replaced by their own
// children, largest box first, until it has 4. Unused slots get an empty box far away that no ray can enter.
int Scene::collapse(int binary_node) {
  const int index = static_cast<int>(nodes4_.size());
  nodes4_.push_back(Node4{});
  std::vector<int> kids;
  if (nodes_[binary_node].count > 0) {
    kids = {binary_node};
  } else {
    kids = {binary_node + 1, nodes_[binary_node].first_or_right};
    while (kids.size() < 4) {
      int best = -1;
      float best_area = -1.0f;
      for (int k = 0; k < static_cast<int>(kids.size()); ++k) {
        const Node& n = nodes_[kids[k]];
        if (n.count > 0) continue;
        const Eigen::AlignedBox3f b(Eigen::Vector3f(n.lo[0], n.lo[1], n.lo[2]), Eigen::Vector3f(n.hi[0], n.hi[1], n.hi[2]));
        if (area(b) > best_area) {
          best_area = area(b);
          best = k;
        }
      }
      if (best < 0) break;
      const int split = kids[best];
      kids.erase(kids.begin() + best);
      kids.push_back(split + 1);
      kids.push_back(nodes_[split].first_or_right);
    }
  }
  for (int k = 0; k < 4; ++k) {
    const bool used = k < static_cast<int>(kids.size());
    int child = -1, count = 0;
    if (used) {
      const Node& n = nodes_[kids[k]];
      if (n.count > 0) {
        child = ~n.first_or_right;
        count = n.count;
      } else {
        child = collapse(kids[k]);  // may reallocate nodes4_: write through the index below
      }
    }
    Node4& out = nodes4_[index];
    for (int a = 0; a < 3; ++a) {
      out.lo[a][k] = used ? nodes_[kids[k]].lo[a] : 1e30f;
      out.hi[a][k] = used ? nodes_[kids[k]].hi[a] : 1e30f;
    }
    out.child[k] = child;
    out.count[k] = count;
  }
  return index;
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

Hit Scene::intersect(const Ray& ray, float t_min) const { return intersect(ray, t_min, safeInverse(ray.dir)); }

Hit Scene::intersect(const Ray& ray, float t_min, const Eigen::Vector3f& inv) const {
  Hit hit;
  hit.t = ray.t_max;
  if (nodes4_.empty()) return Hit{};
  // Slab test as t = bound * inv - origin * inv, four child boxes at once.
  const float oi[3] = {ray.origin.x() * inv.x(), ray.origin.y() * inv.y(), ray.origin.z() * inv.z()};
  struct Pending {
    std::int32_t child, count;
    float t;
  };
  Pending stack[128];
  int sp = 0;
  Pending cur{0, 0, t_min};
  alignas(16) float t_enter[4];
  for (;;) {
    if (cur.child < 0) {  // leaf
      const int first = ~cur.child;
      for (int i = first; i < first + cur.count; ++i)
        if (intersectRef(refs_[i], ray, t_min, hit)) hit.primitive = i;
    } else {
      const Node4& n = nodes4_[cur.child];
      int mask = 0;
#if defined(__SSE2__)
      __m128 near = _mm_set1_ps(t_min), far = _mm_set1_ps(hit.t);
      for (int a = 0; a < 3; ++a) {
        const __m128 i4 = _mm_set1_ps(inv[a]), o4 = _mm_set1_ps(oi[a]);
        const __m128 t0 = _mm_sub_ps(_mm_mul_ps(_mm_load_ps(n.lo[a]), i4), o4);
        const __m128 t1 = _mm_sub_ps(_mm_mul_ps(_mm_load_ps(n.hi[a]), i4), o4);
        near = _mm_max_ps(near, _mm_min_ps(t0, t1));
        far = _mm_min_ps(far, _mm_max_ps(t0, t1));
      }
      mask = _mm_movemask_ps(_mm_cmple_ps(near, far));
      _mm_store_ps(t_enter, near);
#else
      for (int k = 0; k < 4; ++k) {
        float near = t_min, far = hit.t;
        for (int a = 0; a < 3; ++a) {
          const float t0 = n.lo[a][k] * inv[a] - oi[a], t1 = n.hi[a][k] * inv[a] - oi[a];
          near = std::max(near, std::min(t0, t1));
          far = std::min(far, std::max(t0, t1));
        }
        t_enter[k] = near;
        if (near <= far) mask |= 1 << k;
      }
#endif
      if (mask != 0) {
        // Continue with the nearest child; push the others, farthest first.
        int order[4], m = 0;
        for (int k = 0; k < 4; ++k) {
          if (!(mask & (1 << k))) continue;
          int j = m++;
          while (j > 0 && t_enter[order[j - 1]] < t_enter[k]) {
            order[j] = order[j - 1];
            --j;
          }
          order[j] = k;
        }
        for (int j = 0; j + 1 < m && sp < 128; ++j) stack[sp++] = {n.child[order[j]], n.count[order[j]], t_enter[order[j]]};
        const int k = order[m - 1];
        cur = {n.child[k], n.count[k], t_enter[k]};
        continue;
      }
    }
    // Next pending node that can still hold a nearer hit.
    do {
      if (sp == 0) return hit.primitive < 0 ? Hit{} : hit;
      cur = stack[--sp];
    } while (cur.t > hit.t);
  }
}

Hit Scene::intersectBruteForce(const Ray& ray, float t_min) const {
  Hit hit;
  hit.t = ray.t_max;
  for (std::size_t i = 0; i < refs_.size(); ++i)
    if (intersectRef(refs_[i], ray, t_min, hit)) hit.primitive = static_cast<int>(i);
  if (hit.primitive < 0) return Hit{};
  return hit;
}

Eigen::AlignedBox3f Scene::bounds() const { return bounds_; }

Scene Scene::crop(const Eigen::AlignedBox3f& region) const {
  Scene out;
  for (const Ref& r : refs_) {
    if (!refBounds(r).intersects(region)) continue;
    Ref copy = r;
    switch (r.shape) {
      case Shape::Triangle: copy.index = static_cast<std::uint32_t>(out.triangles_.size()); out.triangles_.push_back(triangles_[r.index]); break;
      case Shape::Box: copy.index = static_cast<std::uint32_t>(out.boxes_.size()); out.boxes_.push_back(boxes_[r.index]); break;
      case Shape::Cylinder: copy.index = static_cast<std::uint32_t>(out.cylinders_.size()); out.cylinders_.push_back(cylinders_[r.index]); break;
    }
    out.refs_.push_back(copy);
  }
  out.build();
  return out;
}

LocalRayCaster::LocalRayCaster(const Scene& scene) : scene_(&scene) {
  crops_[0].half_size = 8.0f;  // most lidar rays in a roadway end within a few metres
  crops_[0].cell = 2.0f;
  crops_[1].half_size = 40.0f;  // rays along the roadway
  crops_[1].cell = 10.0f;
}

void LocalRayCaster::moveTo(const Eigen::Vector3f& position) {
  for (Crop& crop : crops_) {
    const Eigen::Vector3i key = (position / crop.cell).array().floor().cast<int>();
    if (key == crop.key) continue;
    crop.key = key;
    const Eigen::Vector3f centre = (key.cast<float>().array() + 0.5f) * crop.cell;
    const Eigen::Vector3f half = Eigen::Vector3f::Constant(crop.half_size);
    crop.region = Eigen::AlignedBox3f(centre - half, centre + half);
    crop.scene = scene_->crop(crop.region);
  }
}

Hit LocalRayCaster::intersect(const Ray& ray, float t_min) const {
  const Eigen::Vector3f inv = safeInverse(ray.dir);
  for (const Crop& crop : crops_) {
    if (!crop.region.contains(ray.origin)) continue;
    // Distance at which the ray leaves the crop region.
    float t_exit = std::numeric_limits<float>::infinity();
    for (int a = 0; a < 3; ++a) {
      const float bound = ray.dir[a] > 0.0f ? crop.region.max()[a] : crop.region.min()[a];
      t_exit = std::min(t_exit, (bound - ray.origin[a]) * inv[a]);
    }
    Ray local_ray = ray;
    local_ray.t_max = std::min(ray.t_max, t_exit);
    const Hit hit = crop.scene.intersect(local_ray, t_min, inv);
    // A hit inside the region is the nearest: anything nearer lies in the region, hence in the crop.
    if (hit.valid() || t_exit >= ray.t_max) return hit;
    // Nothing before the exit: only hits beyond it remain (a small overlap guards against rounding).
    t_min = std::max(t_min, t_exit - 1e-3f);
  }
  return scene_->intersect(ray, t_min, inv);
}

}  // namespace adit::sim
