// Which adit message type an encoded LCM message is (by its 8-byte fingerprint), for tools like `adit info`.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace adit::msg {

// "point_cloud_t", "imu_t", ... or "" if it is none of adit's types.
std::string messageTypeName(const std::uint8_t* data, std::size_t size);

}  // namespace adit::msg
