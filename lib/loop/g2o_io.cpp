// g2o text reading and writing for PoseGraph (the file wrappers are the only file I/O of the loop library).
#include "loop/pose_graph.hpp"

#include "io/atomic_file.hpp"
#include "io/io_error.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <locale>
#include <sstream>
#include <string>
#include <utility>

namespace adit {
namespace {

// g2o measures the rotation error as the quaternion's vector part (half the angle); ours is the rotation
// vector. information_g2o = J^T information J with J = diag(1, 1, 1, 2, 2, 2).
Matrix6d toG2oInformation(const Matrix6d& info) {
  Matrix6d J = Matrix6d::Identity();
  J.bottomRightCorner<3, 3>() *= 2.0;
  return J.transpose() * info * J;
}
Matrix6d fromG2oInformation(const Matrix6d& info) {
  Matrix6d J = Matrix6d::Identity();
  J.bottomRightCorner<3, 3>() *= 0.5;
  return J.transpose() * info * J;
}

void writePose(std::ostream& out, const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q = Eigen::Quaterniond(T.linear()).normalized();
  const Eigen::Vector3d& t = T.translation();
  out << t.x() << ' ' << t.y() << ' ' << t.z() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z() << ' ' << q.w();
}

bool readPose(std::istream& in, Eigen::Isometry3d& T) {
  double x, y, z, qx, qy, qz, qw;
  if (!(in >> x >> y >> z >> qx >> qy >> qz >> qw)) return false;
  Eigen::Quaterniond q(qw, qx, qy, qz);
  if (!std::isfinite(q.norm()) || q.norm() < 1e-9) return false;
  T = Eigen::Isometry3d::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T.matrix().allFinite();
}

}  // namespace

void writeG2o(const PoseGraph& graph, std::ostream& out) {
  std::ostringstream text;
  text.imbue(std::locale::classic());
  text.precision(17);
  for (int i = 0; i < graph.size(); ++i) {
    text << "VERTEX_SE3:QUAT " << i << ' ';
    writePose(text, graph.pose(i));
    text << '\n';
  }
  if (graph.size() > 0) text << "FIX 0\n";
  for (const PoseGraphEdge& e : graph.edges()) {
    text << "EDGE_SE3:QUAT " << e.from << ' ' << e.to << ' ';
    writePose(text, e.T_from_to);
    const Matrix6d info = toG2oInformation(e.information);
    for (int r = 0; r < 6; ++r)
      for (int c = r; c < 6; ++c) text << ' ' << info(r, c);
    text << '\n';
  }
  out << text.str();
}

bool readG2o(std::istream& in, PoseGraph& graph) {
  PoseGraph loaded;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    fields.imbue(std::locale::classic());
    std::string tag;
    if (!(fields >> tag) || tag[0] == '#' || tag == "FIX") continue;
    if (tag == "VERTEX_SE3:QUAT") {
      int id;
      Eigen::Isometry3d T;
      if (!(fields >> id) || id != loaded.size() || !readPose(fields, T)) return false;
      loaded.addNode(T);
    } else if (tag == "EDGE_SE3:QUAT") {
      PoseGraphEdge e;
      Matrix6d info = Matrix6d::Zero();
      if (!(fields >> e.from >> e.to) || !readPose(fields, e.T_from_to)) return false;
      for (int r = 0; r < 6; ++r)
        for (int c = r; c < 6; ++c) {
          if (!(fields >> info(r, c))) return false;
          info(c, r) = info(r, c);
        }
      e.information = fromG2oInformation(info);
      e.robust = std::abs(e.to - e.from) != 1;
      if (!loaded.addEdge(e)) return false;
    } else {
      return false;  // a type this graph cannot represent
    }
  }
  graph = std::move(loaded);
  return true;
}

bool saveG2o(const PoseGraph& graph, const std::string& path) {
  try {
    io::writeFileAtomically(path, [&graph](std::ostream& out) { writeG2o(graph, out); });
    return true;
  } catch (const io::WriteError&) {
    return false;
  }
}

bool loadG2o(const std::string& path, PoseGraph& graph) {
  std::ifstream in(path);
  if (!in) return false;
  return readG2o(in, graph);
}

}  // namespace adit
