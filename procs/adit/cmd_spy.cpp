// adit spy: lcm-spy with adit's message types. Debian's lcm-spy wrapper passes -Xincgc (gone in Java 17)
// and ignores CLASSPATH, so we start the Java class ourselves with the type jar built next to this binary.
#include "commands.hpp"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <vector>

namespace {

std::string findJar(const std::vector<std::string>& candidates) {
  for (const auto& c : candidates)
    if (std::filesystem::exists(c)) return c;
  return {};
}

}  // namespace

void registerSpyCommand(CLI::App& app) {
  auto url = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand("spy", "Open lcm-spy with adit's message types decoded");
  cmd->add_option("--lcm-url", *url, "LCM provider to watch (default: $LCM_DEFAULT_URL or udpm)");
  cmd->callback([url] {
    const std::string types = executableDir() + "/../share/adit_lcmtypes.jar";
    const std::string lcm = findJar({"/usr/share/java/lcm.jar", "/usr/local/share/java/lcm.jar"});
    const std::string chart = findJar({"/usr/share/java/jchart2d.jar", "/usr/local/share/java/jchart2d.jar"});
    if (!std::filesystem::exists(types)) throw std::runtime_error("no type jar at " + types + " (built when a JDK is installed)");
    if (lcm.empty() || chart.empty()) throw std::runtime_error("lcm.jar or jchart2d.jar missing: install liblcm-java libjchart2d-java");
    if (!url->empty()) ::setenv("LCM_DEFAULT_URL", url->c_str(), 1);
    const std::string classpath = lcm + ":" + chart + ":" + types;
    std::vector<std::string> argv{"java", "-Djava.net.preferIPv4Stack=true", "-cp", classpath, "lcm.spy.Spy"};
    if (!url->empty()) argv.push_back("--lcm-url=" + *url);
    std::vector<char*> cargv;
    for (auto& a : argv) cargv.push_back(a.data());
    cargv.push_back(nullptr);
    spdlog::info("starting lcm-spy ({})", url->empty() ? "default LCM URL" : *url);
    ::execvp("java", cargv.data());
    throw std::runtime_error("cannot start java: install openjdk-17-jre");
  });
}
