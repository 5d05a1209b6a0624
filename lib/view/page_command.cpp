#include "view/page_command.hpp"

#include <sstream>

namespace adit::view {

std::optional<std::vector<std::string>> saveMapArguments(const std::string& text) {
  std::istringstream in(text);
  std::string verb;
  if (!(in >> verb) || verb != "save_map") return std::nullopt;
  std::vector<std::string> arguments;
  for (std::string word; in >> word;) arguments.push_back(word);
  return arguments;
}

}  // namespace adit::view
