// The wire layout of an LCM message type as constant tables. The tables themselves are generated at build
// time from the .lcm files (lcmtypes/wire_schema_gen.cpp -> <adit_wire_schema.hpp>); this header only says
// what they hold. lib/msg/wire_check.hpp walks them.
#pragma once

#include <cstddef>
#include <cstdint>

namespace adit::msg::wire {

// How a member is encoded: big-endian integers and IEEE floats of the given width, a string
// (int32 length including the terminating NUL, then the bytes), or a nested struct (without its hash).
enum class Kind : std::uint8_t { Int8, Int16, Int32, Int64, Float, Double, String, Struct };

// Bytes of one value of a fixed-width kind; 0 for strings and structs (variable size).
constexpr std::size_t widthOf(Kind kind) {
  switch (kind) {
    case Kind::Int8: return 1;
    case Kind::Int16: return 2;
    case Kind::Int32: case Kind::Float: return 4;
    case Kind::Int64: case Kind::Double: return 8;
    default: return 0;
  }
}

struct DimSchema {
  std::int32_t fixed;   // the size when fixed, -1 when it is read from a member
  std::int32_t member;  // index (within the struct) of the integer member holding the size, -1 when fixed
};

struct MemberSchema {
  const char* name;
  Kind kind;
  std::int32_t nested;     // index into kStructs for Kind::Struct, else -1
  std::int32_t first_dim;  // index into kDims
  std::int32_t num_dims;   // 0 for a scalar
};

struct StructSchema {
  const char* name;        // "package.name"
  std::uint64_t base_hash;  // lcm-gen's fingerprint of the struct before nested types are mixed in
  std::int32_t first_member;  // index into kMembers
  std::int32_t num_members;
};

// TypeIndex<Msg>::value is the index of Msg's table in kStructs; the generated header specialises it for
// every type of the .lcm files. A type without a table does not compile.
template <class Msg>
struct TypeIndex {
  static_assert(sizeof(Msg) == 0, "no wire schema for this type: is its .lcm file under lcmtypes/adit?");
};

}  // namespace adit::msg::wire
