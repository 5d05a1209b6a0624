// LCM log files through the reader adit info / adit replay use: framing, resynchronisation after corrupt
// frames, truncated tails.
#include "fuzz_input.hpp"
#include "runtime/lcm_log.hpp"

#include <stdexcept>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  adit::fuzz::Input in(data, size);
  const std::string path = adit::fuzz::scratch().write("run.lcmlog", in.rest());
  try {
    adit::runtime::LogReader reader(path);
    adit::runtime::LogEvent event;
    std::size_t bytes = 0;
    while (reader.next(event)) {
      bytes += event.data.size() + event.channel.size();
      if (bytes > size) __builtin_trap();  // an event can only hold bytes the file has
    }
  } catch (const std::runtime_error&) {
  }
  return 0;
}
