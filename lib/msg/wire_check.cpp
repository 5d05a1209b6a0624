#include "msg/wire_check.hpp"

#include <algorithm>
#include <array>
#include <vector>

namespace adit::msg {
namespace {

using wire::Kind;
using wire::kDims;
using wire::kMembers;
using wire::kNumStructs;
using wire::kStructs;
using wire::widthOf;
using wire::MemberSchema;
using wire::StructSchema;

constexpr int kMaxDepth = 32;  // nesting of structs; LCM types are shallow, a cycle is not

std::uint64_t computeHash(int index, std::vector<int>& parents) {
  if (std::find(parents.begin(), parents.end(), index) != parents.end()) return 0;  // as lcm-gen: no recursion
  parents.push_back(index);
  const StructSchema& s = kStructs[index];
  std::uint64_t hash = s.base_hash;
  for (int m = s.first_member; m < s.first_member + s.num_members; ++m)
    if (kMembers[m].kind == Kind::Struct) hash += computeHash(kMembers[m].nested, parents);
  parents.pop_back();
  return (hash << 1) + ((hash >> 63) & 1);
}

class Walker {
 public:
  Walker(const std::uint8_t* data, std::size_t size, const WireLimits& limits)
      : data_(data), size_(size), limits_(limits) {}

  WireCheck run(int index) {
    if (size_ < 8) return fail(WireVerdict::Malformed, "shorter than a fingerprint");
    const auto hash = static_cast<std::uint64_t>(read(8));
    if (hash != wireHash(index))
      return fail(WireVerdict::Malformed, std::string("not a ") + kStructs[index].name + " (fingerprint differs)");
    walkStruct(index, 0);
    return result_;
  }

 private:
  std::size_t left() const { return size_ - pos_; }

  // Big-endian signed integer of `width` bytes at the cursor (the caller checked there is room).
  std::int64_t read(std::size_t width) {
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < width; ++i) v = (v << 8) | data_[pos_ + i];
    pos_ += width;
    const unsigned shift = static_cast<unsigned>(64 - 8 * width);
    return static_cast<std::int64_t>(v << shift) >> shift;
  }

  WireCheck fail(WireVerdict verdict, std::string reason) {
    if (result_.ok()) result_ = WireCheck{verdict, std::move(reason)};
    return result_;
  }
  bool failed() const { return !result_.ok(); }

  void walkStruct(int index, int depth) {
    if (depth > kMaxDepth) {
      fail(WireVerdict::Malformed, "structs nested too deeply");
      return;
    }
    const StructSchema& s = kStructs[index];
    // Values of the integer scalars read so far: the sizes of later arrays.
    std::vector<std::int64_t> values(static_cast<std::size_t>(s.num_members), 0);
    for (int i = 0; i < s.num_members && !failed(); ++i) {
      const MemberSchema& m = kMembers[s.first_member + i];
      std::int64_t elements = 1;
      if (!countElements(m, values, elements)) return;
      if (m.num_dims == 0 && widthOf(m.kind) > 0 && m.kind != Kind::Float && m.kind != Kind::Double) {
        if (left() < widthOf(m.kind)) {
          fail(WireVerdict::Malformed, std::string("truncated at ") + m.name);
          return;
        }
        values[static_cast<std::size_t>(i)] = read(widthOf(m.kind));
        continue;
      }
      walkElements(m, elements, depth);
    }
  }

  // Product of the member's dimensions, refused when negative or too large; rows of a multi-dimensional
  // array are allocated even when empty, so every partial product is bounded by the message size too.
  bool countElements(const MemberSchema& m, const std::vector<std::int64_t>& values, std::int64_t& elements) {
    for (int d = 0; d < m.num_dims; ++d) {
      const wire::DimSchema& dim = kDims[m.first_dim + d];
      const std::int64_t n = dim.member >= 0 ? values[static_cast<std::size_t>(dim.member)] : dim.fixed;
      if (n < 0) {
        fail(WireVerdict::Malformed, std::string("negative count ") + std::to_string(n) + " for " + m.name);
        return false;
      }
      const bool inner = d + 1 < m.num_dims;
      const bool too_many = n > 0 && elements > limits_.max_elements / n;  // the product, without overflow
      if (!too_many) elements *= n;
      if (too_many || (inner && elements > static_cast<std::int64_t>(size_))) {
        fail(WireVerdict::Oversized, std::string("count ") + std::to_string(n) + " for " + m.name +
                                         " exceeds the limit of " + std::to_string(limits_.max_elements) +
                                         " elements or the message size");
        return false;
      }
    }
    return true;
  }

  void walkElements(const MemberSchema& m, std::int64_t elements, int depth) {
    const std::size_t width = widthOf(m.kind);
    const auto n = static_cast<std::size_t>(elements);
    if (width > 0 || m.kind == Kind::String) {
      // Strings take at least their 4-byte length each.
      const std::size_t need = n * (m.kind == Kind::String ? std::size_t{4} : width);
      if (need > left()) {
        fail(WireVerdict::Oversized, std::string("count ") + std::to_string(elements) + " for " + m.name + " needs " +
                                         std::to_string(need) + " bytes, " + std::to_string(left()) + " left");
        return;
      }
      if (width > 0) {
        pos_ += n * width;
        return;
      }
      for (std::size_t e = 0; e < n && !failed(); ++e) walkString(m);
      return;
    }
    for (std::size_t e = 0; e < n && !failed(); ++e) walkStruct(m.nested, depth + 1);
  }

  void walkString(const MemberSchema& m) {
    if (left() < 4) {
      fail(WireVerdict::Malformed, std::string("truncated at ") + m.name);
      return;
    }
    const std::int64_t length = read(4);  // includes the terminating NUL
    if (length < 1) {
      fail(WireVerdict::Malformed, std::string("string length ") + std::to_string(length) + " for " + m.name);
      return;
    }
    if (length > static_cast<std::int64_t>(left()) || length > limits_.max_string_bytes) {
      fail(WireVerdict::Oversized, std::string("string length ") + std::to_string(length) + " for " + m.name +
                                       ", " + std::to_string(left()) + " bytes left");
      return;
    }
    pos_ += static_cast<std::size_t>(length);
  }

  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
  const WireLimits& limits_;
  WireCheck result_;
};

}  // namespace

std::uint64_t wireHash(int index) {
  static const std::array<std::uint64_t, kNumStructs> hashes = [] {
    std::array<std::uint64_t, kNumStructs> h{};
    std::vector<int> parents;
    for (int i = 0; i < kNumStructs; ++i) h[static_cast<std::size_t>(i)] = computeHash(i, parents);
    return h;
  }();
  return hashes.at(static_cast<std::size_t>(index));
}

WireCheck checkWire(int index, const std::uint8_t* data, std::size_t size, const WireLimits& limits) {
  if (index < 0 || index >= kNumStructs) return {WireVerdict::Malformed, "unknown message type"};
  return Walker(data, size, limits).run(index);
}

}  // namespace adit::msg
