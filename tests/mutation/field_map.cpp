#include "field_map.hpp"

namespace adit::mutation {
namespace {

using msg::wire::Kind;
using msg::wire::kDims;
using msg::wire::kMembers;
using msg::wire::kStructs;
using msg::wire::widthOf;

class Mapper {
 public:
  Mapper(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  bool walk(int index, int depth) {
    if (depth > 8) return false;
    const auto& s = kStructs[index];
    std::vector<std::int64_t> values(static_cast<std::size_t>(s.num_members), 0);
    std::vector<bool> sizes_later(static_cast<std::size_t>(s.num_members), false);
    for (int i = 0; i < s.num_members; ++i) {
      const auto& m = kMembers[s.first_member + i];
      for (int d = 0; d < m.num_dims; ++d)
        if (kDims[m.first_dim + d].member >= 0) sizes_later[static_cast<std::size_t>(kDims[m.first_dim + d].member)] = true;
    }
    for (int i = 0; i < s.num_members; ++i) {
      const auto& m = kMembers[s.first_member + i];
      std::int64_t n = 1;
      for (int d = 0; d < m.num_dims; ++d) {
        const auto& dim = kDims[m.first_dim + d];
        n *= dim.member >= 0 ? values[static_cast<std::size_t>(dim.member)] : dim.fixed;
        if (n < 0 || n > static_cast<std::int64_t>(size_)) return false;
      }
      const std::size_t width = widthOf(m.kind);
      if (width > 0) {
        const std::size_t bytes = static_cast<std::size_t>(n) * width;
        if (bytes > size_ - pos_) return false;
        Field f{pos_, m.kind, width, static_cast<std::size_t>(n), sizes_later[static_cast<std::size_t>(i)], m.name, depth};
        if (m.num_dims == 0 && m.kind != Kind::Float && m.kind != Kind::Double) values[static_cast<std::size_t>(i)] = read(width);
        if (n > 0) fields.push_back(f);
        pos_ += bytes;
        continue;
      }
      for (std::int64_t e = 0; e < n; ++e) {
        if (m.kind == Kind::Struct) {
          if (!walk(m.nested, depth + 1)) return false;
          continue;
        }
        if (size_ - pos_ < 4) return false;  // a string: its length prefix, then the bytes with their NUL
        fields.push_back(Field{pos_, Kind::String, 4, 1, true, m.name, depth});
        const std::int64_t length = read(4);
        if (length < 0 || static_cast<std::size_t>(length) > size_ - pos_ - 4) return false;
        pos_ += 4 + static_cast<std::size_t>(length);
      }
    }
    return true;
  }

  std::size_t pos_ = 8;  // after the fingerprint
  std::vector<Field> fields;

 private:
  std::int64_t read(std::size_t width) const {
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < width; ++i) v = (v << 8) | data_[pos_ + i];
    const unsigned shift = static_cast<unsigned>(64 - 8 * width);
    return static_cast<std::int64_t>(v << shift) >> shift;
  }
  const std::uint8_t* data_;
  std::size_t size_;
};

}  // namespace

std::vector<Field> mapFields(int index, const std::uint8_t* data, std::size_t size) {
  if (size < 8) return {};
  Mapper m(data, size);
  if (!m.walk(index, 0)) return {};
  return m.fields;
}

}  // namespace adit::mutation
