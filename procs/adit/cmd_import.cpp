// adit import kitti <sequence_dir> -o <log>   |   adit import pcd <dir> -o <log>
// adit import pcap <file> --sensor S -o <log>   |   adit import rosbag <file.bag> --lidar-topic T [--imu-topic T] -o <log>
#include "commands.hpp"

#include "runtime/source.hpp"
#include "sources/source_options.hpp"

#include <spdlog/spdlog.h>

void registerImportCommand(CLI::App& app) {
  auto source = std::make_shared<adit::sources::LidarSourceArgs>();
  auto output = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand("import", "Convert a data set (KITTI odometry layout, PCD folder, pcap/pcapng capture of a lidar, ROS 1 bag) into an LCM log");
  addLidarSourceOptions(*cmd, *source, true);
  cmd->add_option("-o,--output", *output, "LCM log to write")->required();
  auto keep_going = std::make_shared<bool>(false);
  cmd->add_flag("--keep-going", *keep_going,
                "Skip (and count) unreadable sweeps; by default the first one stops the import with no log written");
  cmd->callback([source, output, keep_going] {
    adit::runtime::SourceRunOptions run;
    run.process = "import";
    run.output_log = *output;
    // A capture always holds some foreign or damaged packets: they are counted and listed, never fatal.
    run.keep_going = *keep_going || source->kind == "pcap";
    run.input = source->path;
    auto src = adit::sources::makeLidarSource(*source);
    if (const int code = adit::runtime::runSource(*src, run); code != 0) throw CLI::RuntimeError(code);
    // A bag with lost chunks or cut short: the log holds everything else, and the status says it is not the whole bag.
    const auto& counters = src->health().counters;
    const auto count = [&](const char* name) { return counters.count(name) ? counters.at(name) : 0; };
    if (count("bag_chunk_lost") > 0 || count("bag_truncated") > 0) {
      spdlog::error("bag '{}' is damaged: {} chunk(s) lost{}; the log holds the rest", source->path,
                    count("bag_chunk_lost"), count("bag_truncated") ? ", truncated" : "");
      throw CLI::RuntimeError(kExitDamagedInput);
    }
  });
}
