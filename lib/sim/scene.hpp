// The world's surfaces as a set of primitives (triangles, oriented boxes, capped cylinders) behind a BVH, so a
// lidar ray costs O(log n) instead of O(n). Built once, then read-only: intersect() is const and thread-safe.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <limits>
#include <vector>

namespace adit::sim {

struct Ray {
  Eigen::Vector3f origin = Eigen::Vector3f::Zero();
  Eigen::Vector3f dir = Eigen::Vector3f::UnitX();  // unit length, so hit distances are ranges in metres
  float t_max = std::numeric_limits<float>::infinity();
};

struct Hit {
  float t = std::numeric_limits<float>::infinity();  // distance along the ray (m)
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();    // unit surface normal (either side)
  float reflectivity = 0.0f;                           // 0..1, drives lidar intensity and dropouts
  int primitive = -1;                                  // primitive index in the answering scene, -1 = no hit
  bool valid() const { return primitive >= 0; }
};

enum class Shape : std::uint8_t { Triangle, Box, Cylinder };

struct Triangle {
  Eigen::Vector3f a, e1, e2;  // vertex a and edges b-a, c-a
};

struct OrientedBox {
  Eigen::Vector3f center;
  Eigen::Matrix3f axes;  // columns: the box's local x, y, z in world coordinates (orthonormal)
  Eigen::Vector3f half;  // half extents along the local axes (m)
};

struct Cylinder {  // solid, capped
  Eigen::Vector3f base;
  Eigen::Vector3f axis;  // unit
  float length = 0.0f;
  float radius = 0.0f;
};

class Scene {
 public:
  void addTriangle(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c, float reflectivity);
  // Quad a-b-c-d (in order around the edge) as two triangles.
  void addQuad(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c, const Eigen::Vector3f& d,
               float reflectivity);
  void addBox(const Eigen::Vector3f& center, const Eigen::Matrix3f& axes, const Eigen::Vector3f& half,
              float reflectivity);
  // Cylinder between two points; degenerate ones (zero length or radius) are ignored.
  void addCylinder(const Eigen::Vector3f& p0, const Eigen::Vector3f& p1, float radius, float reflectivity);

  // Builds the BVH (binned SAH, collapsed to 4-wide nodes tested with SIMD). Must be called after the last add
  // and before intersect().
  void build();

  // Nearest hit with t in (t_min, ray.t_max]; invalid Hit if none.
  Hit intersect(const Ray& ray, float t_min = 1e-4f) const;
  // Same, by testing every primitive: the reference the BVH is tested against.
  Hit intersectBruteForce(const Ray& ray, float t_min = 1e-4f) const;

  // A new, built scene with every primitive whose bounds touch `region` (same primitives, same order).
  Scene crop(const Eigen::AlignedBox3f& region) const;

  std::size_t size() const { return refs_.size(); }
  std::size_t numNodes() const { return nodes4_.size(); }
  Eigen::AlignedBox3f bounds() const;

  // Read access for surface sampling (world point cloud) and tests.
  const std::vector<Triangle>& triangles() const { return triangles_; }
  const std::vector<OrientedBox>& boxes() const { return boxes_; }
  const std::vector<Cylinder>& cylinders() const { return cylinders_; }

 private:
  struct Ref {
    Shape shape;
    std::uint32_t index;  // into triangles_/boxes_/cylinders_
    float reflectivity;
  };
  struct Node {  // 32 bytes; leaf if count > 0, else children at this+1 and `right`
    float lo[3];
    std::int32_t first_or_right;
    float hi[3];
    std::int32_t count;
  };

  struct alignas(16) Node4 {  // 4-wide node, boxes as structure of arrays; child < 0: leaf ~child, count
    float lo[3][4];
    float hi[3][4];
    std::int32_t child[4];
    std::int32_t count[4];
  };

  // Triangle in the form the intersection test wants: plane first (cheap rejection by distance), then
  // barycentrics as two dot products.
  struct TriangleTest {
    Eigen::Vector3f a, normal, bu, bv;  // normal unit; u = (p - a).bu, v = (p - a).bv
  };

  friend class LocalRayCaster;
  // intersect() with the ray's component-wise inverse direction already computed.
  Hit intersect(const Ray& ray, float t_min, const Eigen::Vector3f& inv) const;
  Eigen::AlignedBox3f refBounds(const Ref& r) const;
  int collapse(int binary_node);
  bool intersectRef(const Ref& r, const Ray& ray, float t_min, Hit& hit) const;
  int buildNode(std::vector<Eigen::AlignedBox3f>& boxes, std::vector<Eigen::Vector3f>& centroids, int first, int count);

  std::vector<Triangle> triangles_;
  std::vector<TriangleTest> triangle_tests_;  // parallel to triangles_, filled by build()
  std::vector<OrientedBox> boxes_;
  std::vector<Cylinder> cylinders_;
  std::vector<Ref> refs_;
  std::vector<Node> nodes_;    // binary BVH (build only)
  std::vector<Node4> nodes4_;  // what intersect() traverses
  Eigen::AlignedBox3f bounds_;
};

// Exact nearest-hit queries for rays that start near one place (a lidar during a sweep): cropped copies of the
// scene around the query position answer most rays with a small BVH. Two nested crops (a near one for the many
// short rays, a far one for the rays along the roadway), then the whole scene for what leaves both. A crop
// depends only on the cell of the query position, never on the query history, so results are a pure function
// of the inputs.
class LocalRayCaster {
 public:
  explicit LocalRayCaster(const Scene& scene);
  // Selects the crops for rays starting near `position` (rebuilds a crop when its cell changed).
  void moveTo(const Eigen::Vector3f& position);
  // Same answer as Scene::intersect on the whole scene (up to exact ties between coincident surfaces).
  Hit intersect(const Ray& ray, float t_min = 1e-4f) const;

 private:
  struct Crop {
    float half_size, cell;  // m: the crop is the cube of this half size around the centre of the cell
    Eigen::Vector3i key = Eigen::Vector3i::Constant(std::numeric_limits<int>::min());
    Eigen::AlignedBox3f region;
    Scene scene;
  };
  const Scene* scene_;
  Crop crops_[2];
};

}  // namespace adit::sim
