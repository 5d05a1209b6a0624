// YAML configuration files through the reader every process and adit config use, and typed reads of the
// keys it produced.
#include "core/config.hpp"
#include "fuzz_input.hpp"

#include <cstdint>
#include <stdexcept>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  adit::fuzz::Input in(data, size);
  try {
    const adit::Config config = adit::Config::fromYamlString(in.rest());
    for (const auto& [key, value] : config.values()) {
      try {
        config.get<double>(key, 0.0);
        config.get<int>(key, 0);
        config.get<std::int64_t>(key, 0);
        config.get<bool>(key, false);
        config.getList<double>(key, {});
      } catch (const std::runtime_error&) {
      }
    }
  } catch (const std::exception&) {
  }
  return 0;
}
