// Write files so that readers never see a half-written one: bytes go to "<path>.tmp.<pid>" next to the
// target, are flushed and fsync'ed, then renamed over the target (rename is atomic on POSIX within one
// file system), and the directory is fsync'ed so the rename survives a power cut. On any failure the
// temp file is removed, the old target (if any) is left untouched, and WriteError names the file.
#pragma once

#include <functional>
#include <ostream>
#include <string>

namespace adit::io {

// Replace `path` with exactly `bytes`.
void writeFileAtomically(const std::string& path, const std::string& bytes);

// Streaming variant for large outputs: `write` fills a binary std::ostream backed by the temp file.
// If `write` throws, the temp file is removed and the exception propagates unchanged.
void writeFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

// The temp file name used for `path` by this process ("<path>.tmp.<pid>").
std::string atomicTempPath(const std::string& path);

}  // namespace adit::io
