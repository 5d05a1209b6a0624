#include "mutator.hpp"

#include <cmath>
#include <cstring>
#include <limits>

namespace adit::mutation {
namespace {

using msg::wire::Kind;

void writeInt(Bytes& b, std::size_t at, std::size_t width, std::int64_t v) {
  for (std::size_t i = 0; i < width; ++i) b[at + width - 1 - i] = static_cast<std::uint8_t>(static_cast<std::uint64_t>(v) >> (8 * i));
}
std::int64_t readInt(const Bytes& b, std::size_t at, std::size_t width) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < width; ++i) v = (v << 8) | b[at + i];
  const unsigned shift = static_cast<unsigned>(64 - 8 * width);
  return static_cast<std::int64_t>(v << shift) >> shift;
}
void writeFloat(Bytes& b, std::size_t at, Kind kind, double v) {
  if (kind == Kind::Double) {
    std::uint64_t u;
    std::memcpy(&u, &v, 8);
    writeInt(b, at, 8, static_cast<std::int64_t>(u));
  } else {
    const float f = static_cast<float>(v);
    std::uint32_t u;
    std::memcpy(&u, &f, 4);
    writeInt(b, at, 4, static_cast<std::int64_t>(u));
  }
}
bool isInteger(Kind k) { return k == Kind::Int8 || k == Kind::Int16 || k == Kind::Int32 || k == Kind::Int64; }

}  // namespace


const char* kindName(Op op) {
  switch (op) {
    case Op::BitFlip: return "bit flips";
    case Op::BoundaryByte: return "boundary bytes";
    case Op::Truncate: return "truncation";
    case Op::Extend: return "extension";
    case Op::Count: return "counts";
    case Op::Float: return "NaN/Inf/1e30";
    case Op::Stamp: return "stamps";
    case Op::Seq: return "seq jumps";
    case Op::Fingerprint: return "fingerprints";
    case Op::Integer: return "integers";
  }
  return "?";
}

const Field* Mutator::pickField(const std::vector<Field>& fields, bool (*want)(const Field&)) {
  std::vector<const Field*> candidates;
  for (const Field& f : fields)
    if (want(f)) candidates.push_back(&f);
  return candidates.empty() ? nullptr : candidates[pick(candidates.size())];
}

bool Mutator::applyCount(Bytes& b, const std::vector<Field>& fields) {
  const Field* f = pickField(fields, [](const Field& x) { return x.is_count && x.elements == 1; });
  if (!f) return false;
  const std::int64_t n = readInt(b, f->offset, f->width);
  const std::int64_t max = f->width >= 4 ? std::numeric_limits<std::int32_t>::max() : (std::int64_t{1} << (8 * f->width - 1)) - 1;
  const std::int64_t values[] = {0, -1, max, max / 2 + 1, 1 << 20, n + 1, n - 1, n * 2, std::numeric_limits<std::int32_t>::min()};
  writeInt(b, f->offset, f->width, values[pick(std::size(values))]);
  return true;
}

bool Mutator::applyFloat(Bytes& b, const std::vector<Field>& fields) {
  const Field* f = pickField(fields, [](const Field& x) { return x.kind == Kind::Float || x.kind == Kind::Double; });
  if (!f) return false;
  const double inf = std::numeric_limits<double>::infinity();
  const double values[] = {std::numeric_limits<double>::quiet_NaN(), inf, -inf, 1e30, -1e30, 1e-310, 0.0, 1e6, -3.0};
  writeFloat(b, f->offset + pick(f->elements) * f->width, f->kind, values[pick(std::size(values))]);
  return true;
}

bool Mutator::applyStamp(Bytes& b, const std::vector<Field>& fields, const char* name) {
  const Field* f = nullptr;
  for (const Field& x : fields)
    if (x.depth == 1 && x.name == name && x.kind == Kind::Int64) { f = &x; break; }  // the message's own header
  if (!f) return false;
  const std::int64_t v = readInt(b, f->offset, 8);
  const std::int64_t s = 1'000'000;
  const std::int64_t stamps[] = {v + s / 2, v + 19 * s / 10, v + 3 * s, v + 3600 * s, v + 1'000'000 * s, v - s / 2,
                                 v - 3600 * s, 0, -1, std::numeric_limits<std::int64_t>::max(),
                                 std::numeric_limits<std::int64_t>::min()};
  const std::int64_t seqs[] = {v + 1, v + 2, v + 10'001, v - 1, v - 10'001, 0, -1, std::numeric_limits<std::int64_t>::max(),
                               std::numeric_limits<std::int64_t>::min()};
  if (std::string(name) == "utime")
    writeInt(b, f->offset, 8, stamps[pick(std::size(stamps))]);
  else
    writeInt(b, f->offset, 8, seqs[pick(std::size(seqs))]);
  return true;
}

bool Mutator::applyInteger(Bytes& b, const std::vector<Field>& fields) {
  const Field* f = pickField(fields, [](const Field& x) { return isInteger(x.kind) && !x.is_count; });
  if (!f) return false;
  const std::int64_t values[] = {0, -1, 1, std::numeric_limits<std::int64_t>::max(), std::numeric_limits<std::int64_t>::min(), 0x7F, 0x80, 0xFF};
  writeInt(b, f->offset + pick(f->elements) * f->width, f->width, values[pick(std::size(values))]);
  return true;
}

Mutation Mutator::mutate(const Bytes& original, int type_index) {
  const std::vector<Field> fields = mapFields(type_index, original.data(), original.size());
  for (;;) {
    Mutation m{static_cast<Op>(pick(kNumKinds)), original};
    if (!(ops_ >> static_cast<unsigned>(m.op) & 1u)) continue;
    Bytes& b = m.bytes;
    switch (m.op) {
      case Op::BitFlip:
        for (std::size_t i = 0, n = 1 + pick(4); i < n; ++i) b[pick(b.size())] ^= static_cast<std::uint8_t>(1u << pick(8));
        return m;
      case Op::BoundaryByte: {
        const std::uint8_t values[] = {0x00, 0xFF, 0x7F, 0x80, 0x01};
        for (std::size_t i = 0, n = 1 + pick(4); i < n; ++i) b[pick(b.size())] = values[pick(std::size(values))];
        return m;
      }
      case Op::Truncate:
        b.resize(pick(b.size()));
        return m;
      case Op::Extend:
        for (std::size_t i = 0, n = 1 + pick(64); i < n; ++i) b.push_back(static_cast<std::uint8_t>(pick(256)));
        return m;
      case Op::Count:
        if (applyCount(b, fields)) return m;
        break;
      case Op::Float:
        if (applyFloat(b, fields)) return m;
        break;
      case Op::Stamp:
        if (applyStamp(b, fields, "utime")) return m;
        break;
      case Op::Seq:
        if (applyStamp(b, fields, "seq")) return m;
        break;
      case Op::Fingerprint:
        if (hashes_.empty()) break;
        writeInt(b, 0, 8, static_cast<std::int64_t>(hashes_[pick(hashes_.size())]));
        return m;
      case Op::Integer:
        if (applyInteger(b, fields)) return m;
        break;
    }
  }
}

}  // namespace adit::mutation
