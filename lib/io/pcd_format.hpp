// The PCD file format (Point Cloud Library, v0.5-v0.7) parsed by hand: ascii, binary and binary_compressed
// (LZF) bodies. Every size in the header is checked against the bytes that are actually there before
// anything is allocated, so a short, crafted or garbage file is a ReadError naming the file (and the line,
// for the header and ascii bodies), never a crash or a huge allocation. PCL's own reader trusts the header.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace adit::io {

struct PcdField {
  std::string name;
  char type = 'F';           // 'I' signed, 'U' unsigned, 'F' floating point
  std::uint32_t size = 4;    // bytes per element: 1, 2, 4 or 8 (F: 4 or 8)
  std::uint32_t count = 1;   // elements per point
  std::size_t offset = 0;    // bytes from the start of a point
  bool isInteger() const { return type != 'F'; }
  // The field's first element of the point at `point`, as a double.
  double read(const std::uint8_t* point) const;
};

struct PcdCloud {
  std::vector<PcdField> fields;
  std::size_t point_step = 0;       // bytes per point, fields packed in header order
  std::size_t points = 0;           // WIDTH * HEIGHT
  std::vector<std::uint8_t> data;   // points * point_step bytes
  // The first field called `name`, or nullptr.
  const PcdField* field(const std::string& name) const;
};

// Parses a whole PCD file held in memory; `name` (the file) is quoted in errors. Throws ReadError.
PcdCloud parsePcd(const std::uint8_t* bytes, std::size_t size, const std::string& name);
// Reads and parses `path`. Throws ReadError naming the file.
PcdCloud readPcdFile(const std::string& path);

// Header of a binary PCD with these fields and points (offsets ignored: packed in order), up to and
// including the "DATA binary" line; byte for byte what PCL's writer produces.
std::string pcdBinaryHeader(const std::vector<PcdField>& fields, std::size_t points);

}  // namespace adit::io
