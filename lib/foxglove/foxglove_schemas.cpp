#include "foxglove/foxglove_schemas.hpp"

namespace adit::foxglove {
namespace {

std::string object(const std::string& title, const std::string& properties, const std::string& required) {
  return R"({"title":")" + title + R"(","type":"object","properties":{)" + properties + R"(},"required":[)" +
         required + "]}";
}

const std::string kNumber = R"({"type":"number"})";
const std::string kInteger = R"({"type":"integer"})";
const std::string kString = R"({"type":"string"})";
const std::string kBoolean = R"({"type":"boolean"})";

std::string timeSchema() {
  return R"({"type":"object","title":"time","properties":{"sec":{"type":"integer","minimum":0},)"
         R"("nsec":{"type":"integer","minimum":0,"maximum":999999999}},"required":["sec","nsec"]})";
}
std::string durationSchema() {
  return R"({"type":"object","title":"duration","properties":{"sec":{"type":"integer"},)"
         R"("nsec":{"type":"integer","minimum":0,"maximum":999999999}},"required":["sec","nsec"]})";
}
std::string xyz(const std::string& title) {
  return object(title, R"("x":)" + kNumber + R"(,"y":)" + kNumber + R"(,"z":)" + kNumber, R"("x","y","z")");
}
std::string quaternionSchema() {
  return object("foxglove.Quaternion",
                R"("x":)" + kNumber + R"(,"y":)" + kNumber + R"(,"z":)" + kNumber + R"(,"w":)" + kNumber,
                R"("x","y","z","w")");
}
std::string poseSchema() {
  return object("foxglove.Pose", R"("position":)" + xyz("foxglove.Vector3") + R"(,"orientation":)" + quaternionSchema(),
                R"("position","orientation")");
}
std::string colorSchema() {
  return object("foxglove.Color",
                R"("r":)" + kNumber + R"(,"g":)" + kNumber + R"(,"b":)" + kNumber + R"(,"a":)" + kNumber,
                R"("r","g","b","a")");
}
std::string arrayOf(const std::string& item) { return R"({"type":"array","items":)" + item + "}"; }
// Enumerations as Foxglove writes them: oneOf of titled constants.
std::string enumeration(const std::string& title, const std::string& constants) {
  return R"({"title":")" + title + R"(","oneOf":[)" + constants + "]}";
}
std::string constant(const std::string& title, int value) {
  return R"({"title":")" + title + R"(","const":)" + std::to_string(value) + "}";
}

}  // namespace

SchemaText pointCloudSchema() {
  const std::string numeric_type = enumeration(
      "foxglove.NumericType", constant("UNKNOWN", 0) + "," + constant("UINT8", 1) + "," + constant("INT8", 2) + "," +
                                  constant("UINT16", 3) + "," + constant("INT16", 4) + "," + constant("UINT32", 5) +
                                  "," + constant("INT32", 6) + "," + constant("FLOAT32", 7) + "," +
                                  constant("FLOAT64", 8));
  const std::string field = object("foxglove.PackedElementField",
                                   R"("name":)" + kString + R"(,"offset":{"type":"integer","minimum":0},"type":)" +
                                       numeric_type,
                                   R"("name","offset","type")");
  return {"foxglove.PointCloud",
          object("foxglove.PointCloud",
                 R"("timestamp":)" + timeSchema() + R"(,"frame_id":)" + kString + R"(,"pose":)" + poseSchema() +
                     R"(,"point_stride":{"type":"integer","minimum":0},"fields":)" + arrayOf(field) +
                     R"(,"data":{"type":"string","contentEncoding":"base64"})",
                 R"("timestamp","frame_id","pose","point_stride","fields","data")")};
}

SchemaText frameTransformSchema() {
  return {"foxglove.FrameTransform",
          object("foxglove.FrameTransform",
                 R"("timestamp":)" + timeSchema() + R"(,"parent_frame_id":)" + kString + R"(,"child_frame_id":)" +
                     kString + R"(,"translation":)" + xyz("foxglove.Vector3") + R"(,"rotation":)" + quaternionSchema(),
                 R"("timestamp","parent_frame_id","child_frame_id","translation","rotation")")};
}

SchemaText posesInFrameSchema() {
  return {"foxglove.PosesInFrame",
          object("foxglove.PosesInFrame",
                 R"("timestamp":)" + timeSchema() + R"(,"frame_id":)" + kString + R"(,"poses":)" + arrayOf(poseSchema()),
                 R"("timestamp","frame_id","poses")")};
}

SchemaText sceneUpdateSchema() {
  const std::string line_type =
      enumeration("foxglove.LineType", constant("LINE_STRIP", 0) + "," + constant("LINE_LOOP", 1) + "," +
                                           constant("LINE_LIST", 2));
  const std::string line = object(
      "foxglove.LinePrimitive",
      R"("type":)" + line_type + R"(,"pose":)" + poseSchema() + R"(,"thickness":)" + kNumber +
          R"(,"scale_invariant":)" + kBoolean + R"(,"points":)" + arrayOf(xyz("foxglove.Point3")) + R"(,"color":)" +
          colorSchema() + R"(,"colors":)" + arrayOf(colorSchema()) +
          R"(,"indices":{"type":"array","items":{"type":"integer","minimum":0}})",
      R"("type","pose","thickness","scale_invariant","points","color","colors","indices")");
  // Entities carry every primitive list (adit fills only `lines`; the others stay empty arrays).
  const std::string any_list = R"({"type":"array","items":{"type":"object"}})";
  std::string entity_properties = R"("timestamp":)" + timeSchema() + R"(,"frame_id":)" + kString + R"(,"id":)" +
                                  kString + R"(,"lifetime":)" + durationSchema() + R"(,"frame_locked":)" + kBoolean +
                                  R"(,"metadata":)" + any_list + R"(,"lines":)" + arrayOf(line);
  for (const char* list : {"arrows", "cubes", "spheres", "cylinders", "triangles", "texts", "models"})
    entity_properties += std::string(",\"") + list + "\":" + any_list;
  const std::string entity =
      object("foxglove.SceneEntity", entity_properties,
             R"("timestamp","frame_id","id","lifetime","frame_locked","metadata","arrows","cubes","spheres",)"
             R"("cylinders","lines","triangles","texts","models")");
  const std::string deletion = object("foxglove.SceneEntityDeletion",
                                      R"("timestamp":)" + timeSchema() + R"(,"type":)" +
                                          enumeration("foxglove.SceneEntityDeletionType",
                                                      constant("MATCHING_ID", 0) + "," + constant("ALL", 1)) +
                                          R"(,"id":)" + kString,
                                      R"("timestamp","type","id")");
  return {"foxglove.SceneUpdate",
          object("foxglove.SceneUpdate", R"("deletions":)" + arrayOf(deletion) + R"(,"entities":)" + arrayOf(entity),
                 R"("deletions","entities")")};
}

SchemaText statusSchema() {
  const std::string counter = object("adit.Counter", R"("name":)" + kString + R"(,"value":)" + kInteger,
                                     R"("name","value")");
  return {"adit.Status",
          object("adit.Status",
                 R"("process":)" + kString + R"(,"state":)" + kString + R"(,"wall_time":)" + timeSchema() +
                     R"(,"uptime_s":)" + kNumber + R"(,"inputs":)" + kInteger + R"(,"outputs":)" + kInteger +
                     R"(,"drops":)" + kInteger + R"(,"errors":)" + kInteger + R"(,"proc_ms_p50":)" + kNumber +
                     R"(,"proc_ms_p95":)" + kNumber + R"(,"proc_ms_max":)" + kNumber + R"(,"busy_fraction":)" +
                     kNumber + R"(,"input_rate_hz":)" + kNumber + R"(,"counters":)" + arrayOf(counter) +
                     R"(,"last_error":)" + kString,
                 R"("process","state","inputs","outputs","drops","errors","counters")")};
}

}  // namespace adit::foxglove
