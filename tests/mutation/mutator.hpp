// Deterministic mutations of encoded bus messages (a seed gives the same mutations on every machine): bit
// flips, boundary bytes, truncation, extension, array counts and string lengths set to 0 / -1 / INT_MAX /
// huge, NaN / Inf / 1e30 in float fields, stamps far in the future or past, sequence jumps, and the
// fingerprint of another type. Structured mutations aim at fields found by field_map.hpp.
#pragma once

#include "field_map.hpp"

#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace adit::mutation {

using Bytes = std::vector<std::uint8_t>;

enum class Op { BitFlip, BoundaryByte, Truncate, Extend, Count, Float, Stamp, Seq, Fingerprint, Integer };
constexpr int kNumKinds = 10;
const char* kindName(Op op);

struct Mutation {
  Op op = Op::BitFlip;
  Bytes bytes;
};

class Mutator {
 public:
  // `type_index`: the message's wire type (msg::wire::kStructs); `hashes`: fingerprints to swap in.
  // `ops`: bit i set = Op i used (all by default).
  Mutator(std::uint64_t seed, std::vector<std::uint64_t> hashes, unsigned ops = ~0u)
      : rng_(seed), hashes_(std::move(hashes)), ops_(ops) {}

  Mutation mutate(const Bytes& original, int type_index);

 private:
  std::size_t pick(std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng_); }
  const Field* pickField(const std::vector<Field>& fields, bool (*want)(const Field&));
  bool applyCount(Bytes& b, const std::vector<Field>& fields);
  bool applyFloat(Bytes& b, const std::vector<Field>& fields);
  bool applyStamp(Bytes& b, const std::vector<Field>& fields, const char* name);
  bool applyInteger(Bytes& b, const std::vector<Field>& fields);

  std::mt19937_64 rng_;
  std::vector<std::uint64_t> hashes_;
  unsigned ops_;
};

}  // namespace adit::mutation
