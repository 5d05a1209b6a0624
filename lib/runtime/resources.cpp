#include "runtime/resources.hpp"

#include <dirent.h>

#include <fstream>
#include <string>

namespace adit::runtime {

ProcessResources readProcessResources() {
  ProcessResources r;
  std::ifstream status("/proc/self/status");
  std::string key;
  std::int64_t value = 0;
  while (status >> key) {
    if (key == "Threads:" && status >> value) r.threads = static_cast<int>(value);
    else if (key == "RssAnon:" && status >> value) r.anonymous_kb = value;  // in kB
    status.ignore(256, '\n');
  }
  if (DIR* dir = ::opendir("/proc/self/fd")) {
    while (const dirent* entry = ::readdir(dir)) r.open_files += entry->d_name[0] != '.' ? 1 : 0;
    ::closedir(dir);
    --r.open_files;  // the directory's own descriptor, open while it is read
  }
  return r;
}

}  // namespace adit::runtime
