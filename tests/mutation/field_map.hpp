// Where the fields of an encoded LCM message lie, from the wire layout generated from the .lcm files
// (msg/wire_schema.hpp): the mutator aims its structured mutations (counts, floats, stamps) with it.
#pragma once

#include <adit_wire_schema.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace adit::mutation {

struct Field {
  std::size_t offset = 0;        // first byte of the first element
  msg::wire::Kind kind = msg::wire::Kind::Int8;
  std::size_t width = 0;         // bytes per element (4 for a string: its length prefix)
  std::size_t elements = 1;      // contiguous elements (an array of scalars)
  bool is_count = false;         // an integer that sizes a later array
  std::string name;              // member name ("utime", "seq", "num_points", ...)
  int depth = 0;                 // 0 = a member of the message itself (its header is depth 1)
};

// Fields of the message of type `index` (kStructs) in `data`, in wire order. Empty when the bytes do not
// walk (the mutator then only uses its byte-level mutations).
std::vector<Field> mapFields(int index, const std::uint8_t* data, std::size_t size);

}  // namespace adit::mutation
