// The run's output folder: where a live process writes what commands ask for (maps, trajectories, graphs)
// and its checkpoints. Chosen by --run-dir, else $ADIT_RUN_DIR (set by `adit launch`), else the current
// directory. Nothing a message names can leave it: a command argument must be a plain file name.
#pragma once

#include <string>

namespace adit::runtime {

struct RunFolder {
  std::string dir = ".";
  std::string run_id;       // $ADIT_RUN_ID, else the folder's own name: what a checkpoint must belong to
  int restart_count = 0;    // $ADIT_RESTART_COUNT: how often `adit launch` restarted this process
  bool given = false;       // dir came from --run-dir or $ADIT_RUN_DIR (not the default)
  bool live = false;        // a process: checkpoints, and saves its products when it stops (replay: neither)

  // A checkpoint found in the folder is resumed from only when the folder was given for this run (the
  // launcher makes a new one per run) or the launcher says this is a restart.
  bool mayResume() const { return live && (restart_count > 0 || given); }
  std::string file(const std::string& name) const;
};

// The run folder of a process: flag_dir, else $ADIT_RUN_DIR, else ".". Creates the folder if it is missing.
RunFolder liveRunFolder(const std::string& flag_dir);

// Longest file name a command may give.
constexpr std::size_t kMaxCommandFileName = 64;

// "" if `name` may be written inside the run folder: 1..64 characters of [A-Za-z0-9._-], not starting with
// '.' or '-' (no hidden files, no option-like names, no "..", no separators). Else the reason it is refused.
std::string plainFileNameProblem(const std::string& name);

}  // namespace adit::runtime
