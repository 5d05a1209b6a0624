// JSON Schemas (encoding "jsonschema") of the Foxglove message types adit exports, so that Foxglove and
// Lichtblick recognise the channels by schema name and render them with no plug-in: foxglove.PointCloud,
// foxglove.FrameTransform, foxglove.PosesInFrame, foxglove.SceneUpdate (line primitives only), and
// adit.Status for STATUS. Each describes the fields adit writes, with Foxglove's names and types.
#pragma once

#include <string>

namespace adit::foxglove {

struct SchemaText {
  std::string name;  // "foxglove.PointCloud", ...
  std::string json;  // the JSON Schema
};

SchemaText pointCloudSchema();
SchemaText frameTransformSchema();
SchemaText posesInFrameSchema();
SchemaText sceneUpdateSchema();
SchemaText statusSchema();

}  // namespace adit::foxglove
