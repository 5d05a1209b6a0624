#include "sources/source_options.hpp"

#include "sources/file_sources.hpp"

namespace adit::sources {

void addLidarSourceOptions(CLI::App& app, LidarSourceArgs& a, bool kind_positional) {
  const auto kinds = CLI::IsMember({"kitti", "pcd"});
  if (kind_positional)
    app.add_option("kind", a.kind, "Data set kind: kitti | pcd")->required()->check(kinds);
  else
    app.add_option("--source", a.kind, "Data set kind: kitti | pcd")->required()->check(kinds);
  app.add_option(kind_positional ? "path" : "--path", a.path,
                 "KITTI sequence folder (sequences/NN) or folder of PCD files")->required()->check(CLI::ExistingDirectory);
  app.add_option("--channel", a.channel, "Channel of the sweeps");
  app.add_option("--sensor", a.sensor, "PCD: sensor profile for rings by elevation (vlp16, rs16, hdl64)");
  app.add_option("--beams", a.beams, "PCD: beam count for a uniform fan when the profile is unknown");
  app.add_option("--period", a.period_s, "PCD: sweep period (s) when file names are not timestamps");
}

std::unique_ptr<runtime::MessageSource> makeLidarSource(const LidarSourceArgs& a) {
  if (a.kind == "kitti") return makeKittiSource(a.path, a.channel);
  if (a.kind == "pcd") {
    io::PcdFolderConfig config;
    config.sensor = a.sensor;
    config.num_beams = a.beams;
    config.sweep_duration = a.period_s;
    return makePcdSource(a.path, config, a.channel);
  }
  throw std::runtime_error("unknown source kind '" + a.kind + "' (kitti or pcd)");
}

}  // namespace adit::sources
