// adit view's web server as a browser on the LAN reaches it: an HTTP request head, the answer chosen for it,
// then (after an upgrade) WebSocket frames, all through lib/view/web_protocol.hpp as the server's connection
// loop drives it, with the bytes arriving in pieces as recv() would return them; each message a client sends
// is read as a Foxglove client's request (foxglove/foxglove_client.hpp), as adit view --foxglove does.
// Input: one byte (piece size - 1), then the bytes the client sends.
#include "fuzz_input.hpp"
#include "foxglove/foxglove_client.hpp"
#include "view/web_protocol.hpp"

#include <cstdlib>

namespace {

constexpr std::size_t kMaxMessage = 4096;

void require(bool ok) {
  if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace adit::view;
  adit::fuzz::Input input(data, size);
  const std::size_t piece = input.byte() + 1u;
  const std::string bytes = input.rest();
  const std::vector<std::string> subprotocols{"foxglove.websocket.v1"};
  std::string in;
  bool websocket = false;
  ClientFrameReader frames(kMaxMessage);
  for (std::size_t at = 0; at < bytes.size(); at += piece) {
    in += bytes.substr(at, piece);
    Parse parsed = Parse::kDone;
    while (parsed == Parse::kDone && !websocket) {
      HttpRequest request;
      parsed = takeHttpRequest(in, request);
      require(parsed != Parse::kIncomplete || in.size() <= kMaxRequestBytes);
      if (parsed != Parse::kDone) break;
      const HttpAnswer answer = answerRequest(request, subprotocols);
      // What may be served: a plain name in the web root, never a path out of it.
      if (answer.status == 200)
        require(!answer.file.empty() && answer.file[0] != '.' && answer.file.find('/') == std::string::npos);
      if (answer.status == 101) {
        require(answer.handshake.size() > 4 && answer.handshake.compare(answer.handshake.size() - 4, 4, "\r\n\r\n") == 0);
        websocket = true;
      }
    }
    if (parsed == Parse::kBad) return 0;  // the server answers 400 and closes
    ClientEvent event;
    while (websocket && (parsed = frames.next(in, event)) == Parse::kDone) {
      require(event.payload.size() <= kMaxMessage);
      if (event.kind == ClientEvent::kClose) return 0;
      if (event.kind == ClientEvent::kPing) require(!webSocketFrame(event.payload, 0xA).empty());
      if (event.kind == ClientEvent::kMessage) {
        const adit::foxglove::ClientRequest request = adit::foxglove::parseClientRequest(event.payload);
        for (const auto& [subscription, channel] : request.subscribe) require(channel >= 0);
      }
    }
    if (parsed == Parse::kBad) return 0;  // closed
    require(in.size() <= kMaxRequestBytes + kMaxMessage + 14 + piece);
  }
  return 0;
}
