// The one exception family of the data-source readers and writers.
//
// Readers throw ReadError for unrecoverable file problems (missing, truncated, corrupt, unreadable):
// its what() is one line naming the file and the problem, fit to print as-is. Recoverable per-point or
// per-line issues (NaN points, a bad CSV line) never throw: they are kept or counted and reported.
// Writers throw WriteError. Callers that do not care which catch IoError (or std::runtime_error).
#pragma once

#include <stdexcept>
#include <string>

namespace adit::io {

class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ReadError : public IoError {
 public:
  using IoError::IoError;
};

class WriteError : public IoError {
 public:
  using IoError::IoError;
};

}  // namespace adit::io
