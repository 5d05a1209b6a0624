// Launch files (YAML with ${VAR} substitution) through the reader adit launch uses.
#include "fuzz_input.hpp"
#include "launch/launch_file.hpp"

#include <stdexcept>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  adit::fuzz::Input in(data, size);
  const std::string path = adit::fuzz::scratch().write("run.launch.yaml", in.rest());
  try {
    adit::launch::loadLaunchFile(path, {{"WORLD", "roadway-loop"}, {"LOG", "run.lcmlog"}});
  } catch (const std::exception&) {  // runtime_error naming the file; yaml-cpp's own exceptions derive from it
  }
  return 0;
}
