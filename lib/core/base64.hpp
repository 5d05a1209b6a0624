// Standard base64 with padding (RFC 4648): JSON byte fields (Foxglove), the WebSocket handshake.
#pragma once

#include <string>

namespace adit {

std::string base64(const std::string& bytes);

}  // namespace adit
