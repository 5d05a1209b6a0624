// Bounds the readers put on values from files before converting them, so that a hostile value is an
// error (or is ignored) instead of an overflow.
#pragma once

namespace adit::io {

// Largest time (s) a reader accepts: 1e10 s after 1970 is the year 2286. Above it, seconds * 1e6 no
// longer fits comfortably in the int64 microseconds of utime.
constexpr double kMaxStampSeconds = 1e10;

}  // namespace adit::io
