// Write files so that readers never see a half-written one: bytes go to "<path>.tmp.<pid>" next to the
// target, are flushed and fsync'ed, then renamed over the target (rename is atomic on POSIX within one
// file system), and the directory is fsync'ed so the rename survives a power cut. On any failure the
// temp file is removed, the old target (if any) is left untouched, and WriteError names the file.
// A target that exists and is neither a regular file nor a directory (/dev/null, /dev/stdout, a named pipe)
// is written in place instead: renaming a temp file over it would replace the device or pipe with a
// regular file (as root, `-o /dev/null` would turn the system's /dev/null into a file).
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

// True if `path` exists and is neither a regular file nor a directory (following links): written in place.
bool writesInPlace(const std::string& path);

}  // namespace adit::io
