// Checks the bytes of an incoming LCM message against its type's wire layout before lcm-gen's decoder runs.
// The generated decoders resize every array from the count in the message before looking at how many bytes
// are left, so one 80-byte message with a count near INT_MAX makes the receiver allocate gigabytes (or
// throw from inside resize). checkWire() walks the message with the layout tables generated from the .lcm
// files and refuses it when any count (nested types, 2-D arrays and strings included) is negative, larger
// than the bytes that remain, or larger than a sane maximum. A message it accepts decodes with allocations
// bounded by a small multiple of its size.
#pragma once

#include <adit_wire_schema.hpp>

#include <cstddef>
#include <cstdint>
#include <string>

namespace adit::msg {

struct WireLimits {
  std::int64_t max_elements = std::int64_t{1} << 24;  // per array, all dimensions together
  std::int64_t max_string_bytes = std::int64_t{1} << 20;
};

enum class WireVerdict {
  Ok,
  Malformed,  // wrong type (fingerprint), truncated, negative count, string without room for its NUL
  Oversized,  // a count or string length larger than the bytes left or than WireLimits
};

struct WireCheck {
  WireVerdict verdict = WireVerdict::Ok;
  std::string reason;  // empty when Ok
  bool ok() const { return verdict == WireVerdict::Ok; }
};

// The full LCM fingerprint of the type at `index` in wire::kStructs (equal to Msg::getHash()).
std::uint64_t wireHash(int index);

WireCheck checkWire(int index, const std::uint8_t* data, std::size_t size, const WireLimits& limits);

template <class Msg>
WireCheck checkWire(const std::uint8_t* data, std::size_t size, const WireLimits& limits = {}) {
  return checkWire(wire::TypeIndex<Msg>::value, data, size, limits);
}

}  // namespace adit::msg
