#include "io/pcd_format.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "io/io_error.hpp"
#include "io/lzf.hpp"

namespace adit::io {
namespace {

constexpr std::uint32_t kMaxCount = 1u << 20;  // elements of one field: far above any real layout

template <class T>
double load(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return static_cast<double>(v);
}

template <class T>
void put(std::uint8_t* p, T v) {
  std::memcpy(p, &v, sizeof(T));
}

// The bytes of a file, cut into lines on demand (for the header and ascii bodies).
class LineCursor {
 public:
  LineCursor(const std::uint8_t* bytes, std::size_t size) : bytes_(bytes), size_(size) {}
  bool next(std::string& line) {
    if (pos_ >= size_) return false;
    const auto* start = bytes_ + pos_;
    const auto* nl = static_cast<const std::uint8_t*>(std::memchr(start, '\n', size_ - pos_));
    const std::size_t len = nl ? static_cast<std::size_t>(nl - start) : size_ - pos_;
    line.assign(reinterpret_cast<const char*>(start), len);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    pos_ += len + (nl ? 1 : 0);
    ++line_;
    return true;
  }
  std::size_t position() const { return pos_; }
  int line() const { return line_; }

 private:
  const std::uint8_t* bytes_;
  std::size_t size_;
  std::size_t pos_ = 0;
  int line_ = 0;
};

std::vector<std::string> tokens(const std::string& line) {
  std::vector<std::string> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

bool parseUnsigned(const std::string& text, std::uint64_t& value) {
  if (text.empty() || text[0] < '0' || text[0] > '9') return false;
  errno = 0;
  char* end = nullptr;
  value = std::strtoull(text.c_str(), &end, 10);
  return errno == 0 && *end == '\0';
}

struct Header {
  std::vector<PcdField> fields;
  std::vector<std::string> names;
  std::vector<std::uint64_t> sizes, counts;
  std::vector<std::string> types;
  std::uint64_t width = 0, height = 1, points = 0;
  bool has_width = false, has_points = false;
  std::string data;  // ascii, binary, binary_compressed
};

class Parser {
 public:
  Parser(const std::uint8_t* bytes, std::size_t size, std::string name)
      : bytes_(bytes), size_(size), name_(std::move(name)), lines_(bytes, size) {}

  PcdCloud parse() {
    readHeader();
    PcdCloud cloud = layout();
    if (header_.data == "ascii") readAscii(cloud);
    else if (header_.data == "binary") readBinary(cloud);
    else readCompressed(cloud);
    return cloud;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { throw ReadError("PCD: '" + name_ + "' " + what); }
  [[noreturn]] void failAt(int line, const std::string& what) const {
    fail("line " + std::to_string(line) + ": " + what);
  }

  std::vector<std::uint64_t> unsignedList(const std::vector<std::string>& t) const {
    std::vector<std::uint64_t> out;
    for (std::size_t i = 1; i < t.size(); ++i) {
      std::uint64_t v = 0;
      if (!parseUnsigned(t[i], v)) failAt(lines_.line(), t[0] + " value '" + t[i] + "' is not a non-negative integer");
      out.push_back(v);
    }
    return out;
  }

  std::uint64_t single(const std::vector<std::string>& t) const {
    if (t.size() != 2) failAt(lines_.line(), t[0] + " takes one value");
    return unsignedList(t)[0];
  }

  void readHeader() {
    std::string line;
    while (lines_.next(line)) {
      const std::vector<std::string> t = tokens(line);
      if (t.empty() || t[0][0] == '#') continue;
      const std::string& key = t[0];
      if (key == "VERSION" || key == "VIEWPOINT") continue;
      if (key == "FIELDS" || key == "COLUMNS") header_.names.assign(t.begin() + 1, t.end());
      else if (key == "SIZE") header_.sizes = unsignedList(t);
      else if (key == "TYPE") header_.types.assign(t.begin() + 1, t.end());
      else if (key == "COUNT") header_.counts = unsignedList(t);
      else if (key == "WIDTH") header_.width = single(t), header_.has_width = true;
      else if (key == "HEIGHT") header_.height = single(t);
      else if (key == "POINTS") header_.points = single(t), header_.has_points = true;
      else if (key == "DATA") {
        if (t.size() != 2 || (t[1] != "ascii" && t[1] != "binary" && t[1] != "binary_compressed"))
          failAt(lines_.line(), "DATA must be ascii, binary or binary_compressed");
        header_.data = t[1];
        return;
      } else {
        failAt(lines_.line(), "'" + key.substr(0, 40) + "' is not a PCD header entry (not a PCD file?)");
      }
    }
    fail("has no DATA line: not a PCD file, or its header is cut short");
  }

  // Validates the header and lays the fields out, packed in header order.
  PcdCloud layout() {
    const std::size_t n = header_.names.size();
    if (n == 0) fail("header lists no FIELDS");
    if (header_.counts.empty()) header_.counts.assign(n, 1);
    if (header_.sizes.size() != n || header_.types.size() != n || header_.counts.size() != n)
      fail("header: FIELDS, SIZE, TYPE and COUNT list different numbers of entries");
    if (!header_.has_width) fail("header has no WIDTH");
    PcdCloud cloud;
    for (std::size_t i = 0; i < n; ++i) {
      PcdField f;
      f.name = header_.names[i];
      const std::string& type = header_.types[i];
      const std::uint64_t size = header_.sizes[i], count = header_.counts[i];
      const bool int_ok = (type == "I" || type == "U") && (size == 1 || size == 2 || size == 4 || size == 8);
      const bool float_ok = type == "F" && (size == 4 || size == 8);
      if (!int_ok && !float_ok) fail("header: field '" + f.name + "' has TYPE " + type + " with SIZE " + std::to_string(size));
      if (count < 1 || count > kMaxCount) fail("header: field '" + f.name + "' has COUNT " + std::to_string(count));
      f.type = type[0];
      f.size = static_cast<std::uint32_t>(size);
      f.count = static_cast<std::uint32_t>(count);
      f.offset = cloud.point_step;
      cloud.point_step += f.size * f.count;
      cloud.fields.push_back(f);
    }
    const std::uint64_t wh = header_.width * header_.height;
    if (header_.height != 0 && wh / header_.height != header_.width) fail("header: WIDTH x HEIGHT overflows");
    if (header_.has_points && header_.points != wh)
      fail("header: POINTS " + std::to_string(header_.points) + " is not WIDTH x HEIGHT = " + std::to_string(wh));
    cloud.points = wh;
    return cloud;
  }

  std::size_t bodySize() const { return size_ - lines_.position(); }
  const std::uint8_t* body() const { return bytes_ + lines_.position(); }

  void readBinary(PcdCloud& cloud) {
    if (cloud.points > bodySize() / cloud.point_step)
      fail("is truncated: " + std::to_string(bodySize()) + " bytes of point data, the header announces " +
           std::to_string(cloud.points) + " points of " + std::to_string(cloud.point_step) + " bytes");
    cloud.data.assign(body(), body() + cloud.points * cloud.point_step);
  }

  void readCompressed(PcdCloud& cloud) {
    if (cloud.points == 0) return;
    if (bodySize() < 8) fail("is truncated before its compressed body");
    std::uint32_t sizes[2];  // compressed, uncompressed (little-endian, as PCL writes them on x86)
    std::memcpy(sizes, body(), sizeof(sizes));
    const std::size_t compressed = sizes[0], raw = sizes[1];
    if (compressed > bodySize() - 8)
      fail("is truncated: compressed body of " + std::to_string(compressed) + " bytes, " + std::to_string(bodySize() - 8) +
           " present");
    if (cloud.points > raw / cloud.point_step || raw != cloud.points * cloud.point_step)
      fail("compressed body holds " + std::to_string(raw) + " bytes, the header announces " +
           std::to_string(cloud.points) + " points of " + std::to_string(cloud.point_step) + " bytes");
    if (raw > lzfMaxExpansion(compressed)) fail("compressed body cannot expand to the announced size: corrupt");
    std::vector<std::uint8_t> columns(raw);
    if (!lzfDecompress(body() + 8, compressed, columns.data(), raw)) fail("compressed body is corrupt (LZF)");
    // binary_compressed stores each field for all points in turn; points are interleaved here.
    cloud.data.resize(raw);
    std::size_t at = 0;
    for (const PcdField& f : cloud.fields) {
      const std::size_t bytes = static_cast<std::size_t>(f.size) * f.count;
      for (std::size_t i = 0; i < cloud.points; ++i, at += bytes)
        std::memcpy(cloud.data.data() + i * cloud.point_step + f.offset, columns.data() + at, bytes);
    }
  }

  void readAscii(PcdCloud& cloud) {
    std::size_t values = 0;
    for (const PcdField& f : cloud.fields) values += f.count;
    // Every value takes at least one character: bounds the allocation by the file's size.
    if (cloud.points > bodySize() / values)
      fail("is truncated: " + std::to_string(bodySize()) + " bytes of ascii data cannot hold the announced " +
           std::to_string(cloud.points) + " points");
    cloud.data.assign(cloud.points * cloud.point_step, 0);
    std::size_t point = 0;
    std::string line;
    while (lines_.next(line)) {
      const std::vector<std::string> t = tokens(line);
      if (t.empty()) continue;
      if (point == cloud.points) failAt(lines_.line(), "more points than the header's " + std::to_string(cloud.points));
      if (t.size() != values)
        failAt(lines_.line(), std::to_string(t.size()) + " values, the header announces " + std::to_string(values));
      std::size_t k = 0;
      for (const PcdField& f : cloud.fields)
        for (std::uint32_t c = 0; c < f.count; ++c, ++k)
          store(f, t[k], cloud.data.data() + point * cloud.point_step + f.offset + c * f.size);
      ++point;
    }
    if (point != cloud.points)
      fail("is truncated: " + std::to_string(point) + " of the announced " + std::to_string(cloud.points) + " points");
  }

  void store(const PcdField& f, const std::string& text, std::uint8_t* out) const {
    char* end = nullptr;
    errno = 0;
    bool ok = false;
    if (f.type == 'F') {
      const double v = std::strtod(text.c_str(), &end);
      ok = end != text.c_str() && *end == '\0';
      if (f.size == 4) put(out, static_cast<float>(v)); else put(out, v);
    } else if (f.type == 'I') {
      const long long v = std::strtoll(text.c_str(), &end, 10);
      const long long lim = f.size == 8 ? std::numeric_limits<long long>::max() : (1LL << (8 * f.size - 1)) - 1;
      ok = end != text.c_str() && *end == '\0' && errno == 0 && v <= lim && v >= -lim - 1;
      if (f.size == 1) put(out, static_cast<std::int8_t>(v));
      else if (f.size == 2) put(out, static_cast<std::int16_t>(v));
      else if (f.size == 4) put(out, static_cast<std::int32_t>(v));
      else put(out, static_cast<std::int64_t>(v));
    } else {
      std::uint64_t v = 0;
      ok = parseUnsigned(text, v) && (f.size == 8 || v < (1ULL << (8 * f.size)));
      if (f.size == 1) put(out, static_cast<std::uint8_t>(v));
      else if (f.size == 2) put(out, static_cast<std::uint16_t>(v));
      else if (f.size == 4) put(out, static_cast<std::uint32_t>(v));
      else put(out, v);
    }
    if (!ok)
      failAt(lines_.line(), "'" + text.substr(0, 40) + "' is not a valid " + std::string(1, f.type) +
                                std::to_string(8 * f.size) + " value for field '" + f.name + "'");
  }

  const std::uint8_t* bytes_;
  std::size_t size_;
  std::string name_;
  LineCursor lines_;
  Header header_;
};

}  // namespace

double PcdField::read(const std::uint8_t* point) const {
  const std::uint8_t* p = point + offset;
  if (type == 'F') return size == 4 ? load<float>(p) : load<double>(p);
  if (type == 'I') {
    switch (size) {
      case 1: return load<std::int8_t>(p);
      case 2: return load<std::int16_t>(p);
      case 4: return load<std::int32_t>(p);
      default: return load<std::int64_t>(p);
    }
  }
  switch (size) {
    case 1: return load<std::uint8_t>(p);
    case 2: return load<std::uint16_t>(p);
    case 4: return load<std::uint32_t>(p);
    default: return load<std::uint64_t>(p);
  }
}

const PcdField* PcdCloud::field(const std::string& name) const {
  for (const PcdField& f : fields)
    if (f.name == name) return &f;
  return nullptr;
}

PcdCloud parsePcd(const std::uint8_t* bytes, std::size_t size, const std::string& name) {
  if (size == 0) throw ReadError("PCD: '" + name + "' is empty");
  return Parser(bytes, size, name).parse();
}

PcdCloud readPcdFile(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw ReadError("PCD: file '" + path + "' does not exist or is not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ReadError("PCD: cannot open '" + path + "': " + std::strerror(errno));
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw ReadError("PCD: cannot read '" + path + "'");
  return parsePcd(bytes.data(), bytes.size(), path);
}

std::string pcdBinaryHeader(const std::vector<PcdField>& fields, std::size_t points) {
  std::string names, sizes, types, counts;
  for (const PcdField& f : fields) {
    names += " " + f.name;
    sizes += " " + std::to_string(f.size);
    types += std::string(" ") + f.type;
    counts += " " + std::to_string(f.count);
  }
  const std::string n = std::to_string(points);
  return "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS" + names + "\nSIZE" + sizes + "\nTYPE" + types +
         "\nCOUNT" + counts + "\nWIDTH " + n + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + n + "\nDATA binary\n";
}

}  // namespace adit::io
