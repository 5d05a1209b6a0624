// A map bundle folder as `adit info <bundle>` and `adit replay --prior-map` read it: the manifest
// (readBundleSummary: YAML, sizes and CRC-32 of every file), keyframes.bin (loop/keyframe_codec: compact clouds,
// Scan Context descriptors), pose_graph.g2o and config.yaml (loadMapBundle), then a relocaliser built on the
// loaded bundle and given two sweeps, as the relocaliser process does.
// Input: four files as [uint16 size][bytes]: manifest.yaml, keyframes.bin, pose_graph.g2o, config.yaml; then one
// byte: bit 0 set appends the files' true sizes and checksums to the manifest (so that the fuzzer gets past the
// checksums to the decoders), bit 1 set leaves map.pcd out.
#include "core/crc32.hpp"
#include "fuzz_input.hpp"
#include "map/map_bundle.hpp"
#include "map/relocaliser.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <filesystem>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool quiet = (spdlog::set_level(spdlog::level::off), true);
  (void)quiet;
  adit::fuzz::Input in(data, size);
  const auto& scratch = adit::fuzz::scratch();
  const std::string dir = scratch.path() + "/bundle";
  std::filesystem::remove_all(dir);
  std::string manifest = in.bytes(in.u16());
  const std::pair<std::string, std::string> files[] = {{"keyframes.bin", in.bytes(in.u16())},
                                                       {"pose_graph.g2o", in.bytes(in.u16())},
                                                       {"config.yaml", in.bytes(in.u16())},
                                                       {"map.pcd", "not read when loading, only checksummed\n"}};
  const std::uint8_t flags = in.byte();
  if (flags & 1) manifest += "\nfiles:\n";
  for (const auto& [name, bytes] : files) {
    if (name == "map.pcd" && (flags & 2)) continue;
    scratch.write("bundle/" + name, bytes);
    if (flags & 1)
      manifest += fmt::format("  \"{}\": {{bytes: {}, crc32: {}}}\n", name, bytes.size(), adit::crc32(bytes.data(), bytes.size()));
  }
  scratch.write("bundle/manifest.yaml", manifest);
  try {
    adit::MapBundle bundle = adit::loadMapBundle(dir);
    // The relocaliser process first compares the manifest's sensor keys with its own configuration; a manifest
    // may leave them out, so the relocaliser must cope with any descriptor grid: that check is not made here.
    (void)adit::bundleSensorMismatch(bundle.summary, bundle.config);
    const std::vector<Eigen::Vector3f> cloud =
        bundle.keyframes.empty() ? std::vector<Eigen::Vector3f>{} : bundle.keyframes.front().cloud.decode();
    if (cloud.size() > 1000) return 0;  // enough for the decoders; the rest would be ICP time
    // One candidate verified against its own keyframe and one neighbour: every step of a query, at a
    // fraction of the ICP work of the defaults (which took over 10 s per input at nice 19 on a loaded machine).
    adit::RelocaliserConfig reloc;
    reloc.max_verifications = 1;
    reloc.submap_neighbors = 1;
    reloc.query_sweeps = 1;
    reloc.self_similar_samples = 1;  // the map's self-similarity from one keyframe (its judgement runs on a thread)
    adit::Relocaliser relocaliser(std::move(bundle), adit::LoopCloserConfig{}, reloc);
    adit::PoseEstimate session;
    for (int k = 0; k < 2; ++k) {
      session.utime = 1700000000000000 + k * 100000;
      session.pose.translation().x() = 0.6 * k;
      relocaliser.process(session, cloud, false);
    }
  } catch (const adit::BundleError&) {
  }
  return 0;
}
