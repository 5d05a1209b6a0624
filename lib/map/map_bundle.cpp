#include "map/map_bundle.hpp"

#include "core/byte_codec.hpp"
#include "core/config.hpp"
#include "io/atomic_file.hpp"
#include "io/pcd.hpp"
#include "io/pcd_format.hpp"
#include "loop/keyframe_codec.hpp"
#include "loop/loop_closer.hpp"
#include "runtime/checkpoint.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace adit {
namespace fs = std::filesystem;
namespace {

constexpr const char* kFormat = "adit-map-bundle";
constexpr const char* kKeyframesMagic = "ADITKFS1";
const std::vector<std::string> kFiles{"map.pcd", "keyframes.bin", "pose_graph.g2o", "config.yaml"};

std::string isoDate(std::int64_t utime) {
  const std::time_t t = static_cast<std::time_t>(utime / 1000000);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

std::string readWhole(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw BundleError("missing file " + path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string keyframesBytes(const std::vector<BundleKeyframe>& keyframes) {
  ByteWriter w;
  for (const char* c = kKeyframesMagic; *c; ++c) w.put<char>(*c);
  w.put<std::uint32_t>(kMapBundleVersion);
  w.put<std::uint64_t>(keyframes.size());
  for (const BundleKeyframe& k : keyframes) {
    w.put<std::int64_t>(k.utime);
    w.putPose(k.pose);
    putCompactCloud(w, k.cloud);
    putScanContext(w, k.context);
  }
  return w.bytes();
}

std::vector<BundleKeyframe> keyframesFrom(const std::string& bytes, const std::string& path) {
  ByteReader r(bytes);
  std::string magic;
  for (const char* c = kKeyframesMagic; *c; ++c) magic += r.get<char>();
  if (!r.ok() || magic != kKeyframesMagic) throw BundleError(path + " is not a keyframe file");
  if (const auto v = r.get<std::uint32_t>(); v != kMapBundleVersion)
    throw BundleError(fmt::format("{} is version {}, this build reads version {}", path, v, kMapBundleVersion));
  std::vector<BundleKeyframe> keyframes(r.getCount(8 + 96 + 4 + 8 + 12));
  for (std::size_t i = 0; i < keyframes.size(); ++i) {
    BundleKeyframe& k = keyframes[i];
    k.utime = r.get<std::int64_t>();
    k.pose = r.getPose();
    std::optional<CompactCloud> cloud = getCompactCloud(r);
    std::optional<ScanContext> context = cloud ? getScanContext(r) : std::nullopt;
    if (!context) throw BundleError(fmt::format("{}: keyframe {} is malformed or cut short", path, i));
    k.cloud = std::move(*cloud);
    k.context = std::move(*context);
  }
  if (!r.ok() || !r.atEnd()) throw BundleError(path + " is malformed (count or trailing bytes)");
  return keyframes;
}

std::string configYaml(const std::map<std::string, std::string>& config) {
  std::string out = "# every pipeline key of the run that made this bundle (flat keys)\n";
  for (const auto& [key, value] : config) out += fmt::format("\"{}\": \"{}\"\n", key, value);
  return out;
}

std::string manifestYaml(const BundleSummary& s) {
  std::string out = fmt::format("format: {}\nversion: {}\ncreated: \"{}\"\nkeyframes: {}\n", kFormat, s.version,
                                s.created, s.keyframes);
  out += fmt::format("extent_min: [{:.3f}, {:.3f}, {:.3f}]\nextent_max: [{:.3f}, {:.3f}, {:.3f}]\n", s.extent_min.x(),
                     s.extent_min.y(), s.extent_min.z(), s.extent_max.x(), s.extent_max.y(), s.extent_max.z());
  out += fmt::format("roadway_length_m: {:.1f}\nmap_voxel: {}\nsensor:\n", s.roadway_length_m, s.map_voxel);
  for (const auto& [key, value] : s.sensor) out += fmt::format("  \"{}\": \"{}\"\n", key, value);
  out += "files:\n";
  for (const auto& [name, f] : s.files) out += fmt::format("  \"{}\": {{bytes: {}, crc32: {}}}\n", name, f.bytes, f.crc32);
  return out;
}

// The manifest's value for key, or a BundleError naming it.
template <class T>
T manifestValue(const Config& m, const std::string& key, const std::string& path) {
  if (!m.has(key)) throw BundleError(path + " has no '" + key + "'");
  try {
    return m.get<T>(key, T{});
  } catch (const std::exception&) {
    throw BundleError(path + ": '" + key + "' is not a valid value");
  }
}

void writeFiles(const MapBundle& b, const std::string& dir) {
  std::vector<LidarPoint> points;
  points.reserve(b.map.size());
  for (const Eigen::Vector3f& p : b.map) points.push_back({p, 0.0f, 0, 0.0f});
  io::writePcd((fs::path(dir) / "map.pcd").string(), points);
  io::writeFileAtomically((fs::path(dir) / "keyframes.bin").string(), keyframesBytes(b.keyframes));
  std::ostringstream g2o;
  writeG2o(b.graph, g2o);
  io::writeFileAtomically((fs::path(dir) / "pose_graph.g2o").string(), g2o.str());
  io::writeFileAtomically((fs::path(dir) / "config.yaml").string(), configYaml(b.config));
  BundleSummary s = b.summary;
  s.version = kMapBundleVersion;
  for (const std::string& name : kFiles) {
    const std::string bytes = readWhole((fs::path(dir) / name).string());
    s.files[name] = {bytes.size(), runtime::crc32(bytes.data(), bytes.size())};
  }
  io::writeFileAtomically((fs::path(dir) / "manifest.yaml").string(), manifestYaml(s));
}

}  // namespace

std::map<std::string, std::string> bundleSensorKeys(const std::map<std::string, std::string>& config) {
  std::map<std::string, std::string> out;
  for (const auto& [key, value] : config) {
    const bool sensor = key == "features.preprocess.num_rings" || key == "features.preprocess.min_elevation_deg" ||
                        key == "features.preprocess.max_elevation_deg" || key == "loop.keyframe_voxel" ||
                        key == "loop.level_scan_context" || key.rfind("loop.scan_context.", 0) == 0;
    if (sensor) out[key] = value;
  }
  return out;
}

std::string bundleSensorMismatch(const BundleSummary& bundle, const std::map<std::string, std::string>& run_config) {
  const auto run = bundleSensorKeys(run_config);
  for (const auto& [key, value] : bundle.sensor) {
    const auto it = run.find(key);
    if (it == run.end()) continue;  // a key this build does not have
    if (it->second != value)
      return fmt::format("the bundle was made with {} = {}, this run has {}", key, value, it->second);
  }
  return "";
}

double roadwayLength(const std::vector<Eigen::Vector3d>& positions, double revisit_radius, int recent,
                     const std::vector<Eigen::Vector3d>& mapped) {
  const auto near = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& q) { return (p - q).norm() < revisit_radius; };
  double length = 0.0;
  for (std::size_t k = 1; k < positions.size(); ++k) {
    bool revisit = std::any_of(mapped.begin(), mapped.end(), [&](const Eigen::Vector3d& m) { return near(m, positions[k]); });
    for (std::size_t j = 0; j + static_cast<std::size_t>(recent) < k && !revisit; ++j) revisit = near(positions[j], positions[k]);
    if (!revisit) length += (positions[k] - positions[k - 1]).norm();
  }
  return length;
}

BundleSummary bundleSummaryOf(const std::vector<BundleKeyframe>& keyframes, double map_voxel,
                              const std::map<std::string, std::string>& config, double roadway_length_m) {
  BundleSummary s;
  s.version = kMapBundleVersion;
  std::int64_t newest = 0;
  for (const BundleKeyframe& k : keyframes) newest = std::max(newest, k.utime);
  s.created = isoDate(newest);
  s.keyframes = static_cast<int>(keyframes.size());
  if (!keyframes.empty()) s.extent_min = s.extent_max = keyframes.front().pose.translation();
  for (const BundleKeyframe& k : keyframes) {
    s.extent_min = s.extent_min.cwiseMin(k.pose.translation());
    s.extent_max = s.extent_max.cwiseMax(k.pose.translation());
  }
  s.roadway_length_m = roadway_length_m;
  s.map_voxel = map_voxel;
  s.sensor = bundleSensorKeys(config);
  return s;
}

MapBundle bundleFrom(const LoopCloser& closer, double map_voxel, const std::map<std::string, std::string>& config) {
  MapBundle b;
  std::vector<Eigen::Vector3d> positions;
  for (std::size_t k = 0; k < closer.keyframes().size(); ++k) {
    const int id = static_cast<int>(k);
    b.keyframes.push_back({closer.keyframes()[k].utime, closer.graph().pose(id), closer.keyframeCloud(static_cast<int>(k)),
                           closer.keyframeContext(id)});
    positions.push_back(closer.graph().pose(id).translation());
  }
  b.graph = closer.graph();
  b.map = closer.correctedMap(map_voxel);
  b.config = config;
  b.summary = bundleSummaryOf(b.keyframes, map_voxel, config, roadwayLength(positions));
  return b;
}

void writeMapBundle(const MapBundle& bundle, const std::string& dir) {
  const fs::path target = fs::absolute(fs::path(dir).lexically_normal());
  const std::string name = target.has_filename() ? target.filename().string() : target.parent_path().filename().string();
  const fs::path final_dir = target.has_filename() ? target : target.parent_path();
  const fs::path tmp = final_dir.parent_path() / fmt::format(".{}.tmp.{}", name, ::getpid());
  const fs::path old = final_dir.parent_path() / fmt::format(".{}.old.{}", name, ::getpid());
  try {
    fs::create_directories(final_dir.parent_path());
    fs::remove_all(tmp);
    fs::create_directories(tmp);
    writeFiles(bundle, tmp.string());
    if (fs::exists(final_dir)) {
      fs::remove_all(old);
      fs::rename(final_dir, old);
    }
    fs::rename(tmp, final_dir);
    fs::remove_all(old);
  } catch (const std::exception& e) {
    std::error_code ignored;
    fs::remove_all(tmp, ignored);
    if (!fs::exists(final_dir, ignored) && fs::exists(old, ignored)) fs::rename(old, final_dir, ignored);
    throw std::runtime_error("map bundle " + dir + " not written: " + e.what());
  }
}

BundleSummary readBundleSummary(const std::string& dir) {
  if (!fs::is_directory(dir)) throw BundleError(dir + " is not a map bundle folder");
  const std::string path = (fs::path(dir) / "manifest.yaml").string();
  if (!fs::exists(path)) throw BundleError(dir + " has no manifest.yaml (not a map bundle, or not finished)");
  Config m;
  try {
    m = Config::fromYamlFile(path);
  } catch (const std::exception& e) {
    throw BundleError(path + " is not valid YAML: " + e.what());
  }
  if (manifestValue<std::string>(m, "format", path) != kFormat) throw BundleError(path + " is not an adit map bundle");
  BundleSummary s;
  s.version = manifestValue<int>(m, "version", path);
  if (s.version != kMapBundleVersion)
    throw BundleError(fmt::format("{} is a version {} bundle, this build reads version {}", dir, s.version, kMapBundleVersion));
  s.created = manifestValue<std::string>(m, "created", path);
  s.keyframes = manifestValue<int>(m, "keyframes", path);
  for (int i = 0; i < 3; ++i) {
    s.extent_min[i] = manifestValue<double>(m, "extent_min." + std::to_string(i), path);
    s.extent_max[i] = manifestValue<double>(m, "extent_max." + std::to_string(i), path);
  }
  s.roadway_length_m = manifestValue<double>(m, "roadway_length_m", path);
  s.map_voxel = manifestValue<double>(m, "map_voxel", path);
  for (const auto& [key, value] : m.values())
    if (key.rfind("sensor.", 0) == 0) s.sensor[key.substr(7)] = value;
  for (const std::string& name : kFiles) {
    BundleSummary::File f;
    f.bytes = manifestValue<std::uint64_t>(m, "files." + name + ".bytes", path);
    f.crc32 = manifestValue<std::uint32_t>(m, "files." + name + ".crc32", path);
    const std::string file = (fs::path(dir) / name).string();
    if (!fs::exists(file)) throw BundleError(dir + " is missing " + name);
    const std::string bytes = readWhole(file);
    if (bytes.size() != f.bytes)
      throw BundleError(fmt::format("{} holds {} bytes, the manifest says {} (truncated or replaced)", file, bytes.size(), f.bytes));
    if (runtime::crc32(bytes.data(), bytes.size()) != f.crc32)
      throw BundleError(file + " does not match its checksum in the manifest (corrupt or replaced)");
    s.files[name] = f;
  }
  return s;
}

MapBundle loadMapBundle(const std::string& dir) {
  MapBundle b;
  b.summary = readBundleSummary(dir);
  const std::string kf_path = (fs::path(dir) / "keyframes.bin").string();
  b.keyframes = keyframesFrom(readWhole(kf_path), kf_path);
  if (static_cast<int>(b.keyframes.size()) != b.summary.keyframes)
    throw BundleError(fmt::format("{} holds {} keyframes, the manifest says {}", kf_path, b.keyframes.size(), b.summary.keyframes));
  std::istringstream g2o(readWhole((fs::path(dir) / "pose_graph.g2o").string()));
  if (!readG2o(g2o, b.graph)) throw BundleError(dir + "/pose_graph.g2o is malformed");
  try {
    const Config config = Config::fromYamlFile((fs::path(dir) / "config.yaml").string());
    b.config = config.values();
  } catch (const std::exception& e) {
    throw BundleError(dir + "/config.yaml is not valid YAML: " + std::string(e.what()));
  }
  return b;
}

std::vector<Eigen::Vector3f> loadBundleMap(const std::string& dir) {
  const std::string path = (fs::path(dir) / "map.pcd").string();
  try {
    const io::PcdCloud cloud = io::readPcdFile(path);
    const io::PcdField* x = cloud.field("x");
    const io::PcdField* y = cloud.field("y");
    const io::PcdField* z = cloud.field("z");
    if (!x || !y || !z) throw BundleError(path + " has no x, y and z fields");
    std::vector<Eigen::Vector3f> points;
    points.reserve(cloud.points);
    for (std::size_t i = 0; i < cloud.points; ++i) {
      const std::uint8_t* point = cloud.data.data() + i * cloud.point_step;
      const Eigen::Vector3f p(static_cast<float>(x->read(point)), static_cast<float>(y->read(point)),
                              static_cast<float>(z->read(point)));
      if (p.allFinite()) points.push_back(p);
    }
    return points;
  } catch (const io::ReadError& e) {
    throw BundleError(e.what());
  }
}

}  // namespace adit
