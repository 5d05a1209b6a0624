// Checkpoint handling shared by the stage nodes: where a node's checkpoint lives in the run folder, resuming
// from it (refusing a bad one with a clear error and a fresh start), and saving it without ever taking the
// process down.
#pragma once

#include "runtime/background_writer.hpp"
#include "runtime/checkpoint.hpp"
#include "runtime/run_folder.hpp"

#include <spdlog/spdlog.h>

#include <filesystem>
#include <functional>
#include <memory>
#include <string>

namespace adit::nodes {

class RunState {
 public:
  explicit RunState(std::string kind) : kind_(std::move(kind)) {}

  // Also removes temp files a killed predecessor left half-written ("<kind>.ckpt.tmp.<pid>").
  void setFolder(const runtime::RunFolder& folder) {
    folder_ = folder;
    if (!folder_.live) return;
    writer_ = std::make_unique<runtime::BackgroundWriter>();
    std::error_code ec;
    const std::string stale = kind_ + ".ckpt.tmp.";
    for (const auto& entry : std::filesystem::directory_iterator(folder_.dir, ec))
      if (entry.path().filename().string().rfind(stale, 0) == 0) std::filesystem::remove(entry.path(), ec);
  }
  const runtime::RunFolder& folder() const { return folder_; }
  bool live() const { return folder_.live; }
  std::string checkpointPath() const { return folder_.file(kind_ + ".ckpt"); }

  // Resumes when the folder allows it and a checkpoint of this run is there: `restore` gets the payload and
  // returns "" or why it is unusable. Returns true if restored. `error` gets a refusal (already logged).
  bool resume(const std::function<std::string(const std::string&)>& restore, std::string& error) const {
    if (!folder_.mayResume()) return false;
    const runtime::LoadedCheckpoint loaded = runtime::loadCheckpoint(checkpointPath(), kind_, folder_.run_id);
    if (loaded.status == runtime::LoadedCheckpoint::Status::kMissing) {
      if (folder_.restart_count > 0)
        spdlog::warn("[{}] restarted but no checkpoint at {}: starting fresh", kind_, checkpointPath());
      return false;
    }
    error = loaded.error;
    if (loaded.status == runtime::LoadedCheckpoint::Status::kLoaded) {
      error = restore(loaded.payload);
      if (!error.empty()) error = checkpointPath() + ": " + error;
    }
    if (!error.empty()) error += ": checkpoint refused, starting fresh";
    return error.empty();
  }

  // Saves on the writer thread (never stalls the stage); a save not yet started is superseded by a newer
  // one. Errors and successes are collected with takeErrors() / saved().
  void saveLater(std::string payload) {
    submit([this, payload = std::move(payload)] { return save(payload); });
  }
  void submit(runtime::BackgroundWriter::Job job) {
    if (writer_) writer_->submit(std::move(job));
  }
  void flush() {
    if (writer_) writer_->flush();
  }
  std::vector<std::string> takeErrors() { return writer_ ? writer_->takeErrors() : std::vector<std::string>{}; }
  std::int64_t saved() const { return writer_ ? writer_->succeeded() : 0; }

  // Returns "" or the error (the previous checkpoint is then intact).
  std::string save(const std::string& payload) const {
    try {
      runtime::saveCheckpoint(checkpointPath(), kind_, folder_.run_id, payload);
      return "";
    } catch (const std::exception& e) {
      return std::string("checkpoint not written: ") + e.what();
    }
  }

 private:
  std::string kind_;
  runtime::RunFolder folder_;
  std::unique_ptr<runtime::BackgroundWriter> writer_;  // live only: replay never starts a thread
};

}  // namespace adit::nodes
