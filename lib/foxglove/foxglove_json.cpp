#include "foxglove/foxglove_json.hpp"

#include "core/base64.hpp"
#include "core/json_writer.hpp"

#include <algorithm>
#include <cstring>

namespace adit::foxglove {
namespace {

void time(JsonWriter& j, std::int64_t utime) {
  const std::int64_t t = std::max<std::int64_t>(utime, 0);
  j.beginObject().field("sec", t / 1000000).field("nsec", (t % 1000000) * 1000).endObject();
}

void xyz(JsonWriter& j, const Eigen::Vector3d& v) {
  j.beginObject().field("x", v.x()).field("y", v.y()).field("z", v.z()).endObject();
}

void quaternion(JsonWriter& j, const Eigen::Quaterniond& q) {
  j.beginObject().field("x", q.x()).field("y", q.y()).field("z", q.z()).field("w", q.w()).endObject();
}

void pose(JsonWriter& j, const Eigen::Isometry3d& T) {
  j.beginObject().key("position");
  xyz(j, T.translation());
  j.key("orientation");
  quaternion(j, Eigen::Quaterniond(T.rotation()).normalized());
  j.endObject();
}

void color(JsonWriter& j, double r, double g, double b, double a) {
  j.beginObject().field("r", r).field("g", g).field("b", b).field("a", a).endObject();
}

void appendFloat(std::string& out, float v) {
  char bytes[4];
  std::memcpy(bytes, &v, 4);  // little-endian machines (x86-64, aarch64), as Foxglove reads
  out.append(bytes, 4);
}

}  // namespace

std::string pointCloudJson(std::int64_t utime, const std::string& frame_id, const std::vector<Eigen::Vector3f>& points,
                           const std::vector<float>* intensity) {
  const bool with_intensity = intensity && intensity->size() == points.size();
  std::string data;
  data.reserve(points.size() * (with_intensity ? 16 : 12));
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (int k = 0; k < 3; ++k) appendFloat(data, points[i][k]);
    if (with_intensity) appendFloat(data, (*intensity)[i]);
  }
  JsonWriter j;
  j.beginObject().key("timestamp");
  time(j, utime);
  j.field("frame_id", frame_id).key("pose");
  pose(j, Eigen::Isometry3d::Identity());
  j.field("point_stride", with_intensity ? 16 : 12).key("fields").beginArray();
  const char* names[] = {"x", "y", "z", "intensity"};
  for (int k = 0; k < (with_intensity ? 4 : 3); ++k)
    j.beginObject().field("name", names[k]).field("offset", 4 * k).field("type", 7).endObject();  // 7: FLOAT32
  j.endArray().field("data", base64(data)).endObject();
  return j.str();
}

std::string frameTransformJson(std::int64_t utime, const std::string& parent, const std::string& child,
                               const Eigen::Isometry3d& T) {
  JsonWriter j;
  j.beginObject().key("timestamp");
  time(j, utime);
  j.field("parent_frame_id", parent).field("child_frame_id", child).key("translation");
  xyz(j, T.translation());
  j.key("rotation");
  quaternion(j, Eigen::Quaterniond(T.rotation()).normalized());
  j.endObject();
  return j.str();
}

std::string posesInFrameJson(std::int64_t utime, const std::string& frame_id, const std::vector<view::TimedPose>& poses) {
  JsonWriter j;
  j.beginObject().key("timestamp");
  time(j, utime);
  j.field("frame_id", frame_id).key("poses").beginArray();
  for (const auto& p : poses) pose(j, p.pose);
  j.endArray().endObject();
  return j.str();
}

std::string lineListSceneJson(std::int64_t utime, const std::string& frame_id, const std::string& id,
                              const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& segments) {
  JsonWriter j;
  j.beginObject().key("deletions").beginArray().endArray().key("entities").beginArray().beginObject().key("timestamp");
  time(j, utime);
  j.field("frame_id", frame_id).field("id", id).key("lifetime");
  j.beginObject().field("sec", 0).field("nsec", 0).endObject();
  j.field("frame_locked", false).key("metadata").beginArray().endArray();
  for (const char* list : {"arrows", "cubes", "spheres", "cylinders", "triangles", "texts", "models"})
    j.key(list).beginArray().endArray();
  j.key("lines").beginArray().beginObject().field("type", 2).key("pose");  // 2: LINE_LIST
  pose(j, Eigen::Isometry3d::Identity());
  j.field("thickness", 3.0).field("scale_invariant", true).key("points").beginArray();
  for (const auto& [a, b] : segments) {
    xyz(j, a);
    xyz(j, b);
  }
  j.endArray().key("color");
  color(j, 1.0, 0.2, 0.8, 1.0);
  j.key("colors").beginArray().endArray().key("indices").beginArray().endArray().endObject().endArray();
  j.endObject().endArray().endObject();
  return j.str();
}

std::string statusJson(const view::StatusRow& r) {
  JsonWriter j;
  j.beginObject().field("process", r.process).field("state", r.state).key("wall_time");
  time(j, r.wall_utime);
  j.field("uptime_s", r.uptime_s).field("inputs", r.inputs).field("outputs", r.outputs).field("drops", r.drops);
  j.field("errors", r.errors).field("proc_ms_p50", r.proc_ms_p50).field("proc_ms_p95", r.proc_ms_p95);
  j.field("proc_ms_max", r.proc_ms_max).field("busy_fraction", r.busy_fraction).field("input_rate_hz", r.input_rate_hz);
  j.key("counters").beginArray();
  for (const auto& [name, value] : r.counters) j.beginObject().field("name", name).field("value", value).endObject();
  j.endArray().field("last_error", r.last_error).endObject();
  return j.str();
}

}  // namespace adit::foxglove
