// The wire check follows the .lcm files: every generated type has a table whose fingerprint equals the
// decoder's, valid messages pass, and counts the bytes cannot hold are refused before any allocation.
#include "msg/wire_check.hpp"

#include <adit/point_set_t.hpp>

#include <gtest/gtest.h>

#include <cstring>
#include <tuple>
#include <vector>

namespace {

using adit::msg::checkWire;
using adit::msg::WireVerdict;

template <class Msg>
std::vector<std::uint8_t> bytesOf(const Msg& m) {
  std::vector<std::uint8_t> b(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

void putInt32(std::vector<std::uint8_t>& b, std::size_t at, std::int32_t v) {
  const auto u = static_cast<std::uint32_t>(v);
  for (int i = 0; i < 4; ++i) b[at + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(u >> (24 - 8 * i));
}

// For every type of the .lcm files: the table's fingerprint is the decoder's; the default message passes;
// every truncation of it is refused (the decoder refuses them too).
template <class Msg>
void checkType() {
  SCOPED_TRACE(Msg::getTypeName());
  const int index = adit::msg::wire::TypeIndex<Msg>::value;
  EXPECT_EQ(adit::msg::wireHash(index), static_cast<std::uint64_t>(Msg::getHash()))
      << "the wire table of " << adit::msg::wire::kStructs[index].name << " does not match its .lcm file";
  const Msg m{};
  const auto b = bytesOf(m);
  EXPECT_TRUE(checkWire<Msg>(b.data(), b.size()).ok()) << checkWire<Msg>(b.data(), b.size()).reason;
  for (std::size_t n = 0; n < b.size(); ++n) {
    EXPECT_FALSE(checkWire<Msg>(b.data(), n).ok()) << "truncated to " << n << " bytes";
    Msg d;
    EXPECT_LT(d.decode(b.data(), 0, static_cast<int>(n)), 0);
  }
}

template <class... T>
void checkAll(std::tuple<T...>*) {
  (checkType<T>(), ...);
}

}  // namespace

TEST(WireCheck, EveryLcmTypeHasAMatchingTable) {
  static_assert(std::tuple_size_v<adit::msg::wire::AllTypes> == adit::msg::wire::kNumStructs);
  checkAll(static_cast<adit::msg::wire::AllTypes*>(nullptr));
}

TEST(WireCheck, PointCountNearIntMaxIsRefusedBeforeDecoding) {
  adit::point_cloud_t m{};
  m.sensor = "vlp16";
  auto b = bytesOf(m);  // num_points is the last int32 of an empty cloud
  putInt32(b, b.size() - 4, 0x7fffffff);
  const auto check = checkWire<adit::point_cloud_t>(b.data(), b.size());
  EXPECT_EQ(check.verdict, WireVerdict::Oversized) << check.reason;
  putInt32(b, b.size() - 4, -5);
  EXPECT_EQ(checkWire<adit::point_cloud_t>(b.data(), b.size()).verdict, WireVerdict::Malformed);
}

TEST(WireCheck, EmptyRowsOfATwoDimensionalArrayAreBoundedToo) {
  // descriptors[num_keypoints][descriptor_size] with descriptor_size 0 takes no bytes, yet the decoder
  // allocates num_keypoints rows: the row count is bounded by the message size.
  adit::features_t m{};
  m.num_keypoints = 2;
  m.descriptor_size = 0;
  m.keypoints.assign(2, std::vector<float>(3, 1.0f));
  m.descriptors.assign(2, {});
  auto b = bytesOf(m);
  ASSERT_TRUE(checkWire<adit::features_t>(b.data(), b.size()).ok());
  // Find num_keypoints (int32 2 followed by int16 0) and make the rows huge without room for the keypoints.
  for (std::size_t i = 0; i + 6 <= b.size(); ++i) {
    if (b[i] == 0 && b[i + 1] == 0 && b[i + 2] == 0 && b[i + 3] == 2 && b[i + 4] == 0 && b[i + 5] == 0) {
      putInt32(b, i, 1 << 30);
      break;
    }
  }
  EXPECT_EQ(checkWire<adit::features_t>(b.data(), b.size()).verdict, WireVerdict::Oversized);
}

TEST(WireCheck, StringLengthsAreChecked) {
  adit::command_t m{};
  m.command = "save_map";
  m.argument = "map.pcd";
  auto b = bytesOf(m);
  // The argument's length field: before the argument, the counter (8 bytes) and mac_size (4; no mac).
  const std::size_t at = b.size() - (4 + m.argument.size() + 1) - 8 - 4;
  putInt32(b, at, 0);  // no room for the NUL: lcm-gen would assign length -1
  EXPECT_EQ(checkWire<adit::command_t>(b.data(), b.size()).verdict, WireVerdict::Malformed);
  putInt32(b, at, 0x7fffffff);
  EXPECT_EQ(checkWire<adit::command_t>(b.data(), b.size()).verdict, WireVerdict::Oversized);
  adit::msg::WireLimits tight;
  tight.max_string_bytes = 4;
  const auto ok = bytesOf(m);
  EXPECT_EQ(checkWire<adit::command_t>(ok.data(), ok.size(), tight).verdict, WireVerdict::Oversized);
}

TEST(WireCheck, ElementLimitIsConfigurable) {
  adit::point_cloud_t m{};
  m.num_points = 100;
  for (auto* v : {&m.x, &m.y, &m.z, &m.intensity, &m.dt}) v->assign(100, 0.5f);
  m.ring.assign(100, 1);
  const auto b = bytesOf(m);
  EXPECT_TRUE(checkWire<adit::point_cloud_t>(b.data(), b.size()).ok());
  adit::msg::WireLimits tight;
  tight.max_elements = 99;
  EXPECT_EQ(checkWire<adit::point_cloud_t>(b.data(), b.size(), tight).verdict, WireVerdict::Oversized);
}

// A full message passes: every element width is its type's (an int16 array of n elements takes 2n bytes, not
// 4n; the first version demanded 4 bytes an element and refused every real sweep).
TEST(WireCheck, FullMessagesWithNarrowArraysPass) {
  adit::point_set_t m{};
  m.scale = 0.001f;
  m.num_points = 1000;
  for (auto* v : {&m.x, &m.y, &m.z}) v->assign(1000, 7);
  const auto b = bytesOf(m);
  const auto check = checkWire<adit::point_set_t>(b.data(), b.size());
  EXPECT_TRUE(check.ok()) << check.reason;
}
