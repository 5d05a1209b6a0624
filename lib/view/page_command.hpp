// The one command a page may send to the run (adit view --allow-commands): "save_map" or "save_map NAME".
// Recognised by its whole first word, so "save_mapX" or "save_map_all" is not it (and is refused as an
// unknown command), whatever a page or another client on the LAN sends.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace adit::view {

// nullopt: the first word of `text` (words split by blanks) is not exactly save_map; else the words after it.
std::optional<std::vector<std::string>> saveMapArguments(const std::string& text);

}  // namespace adit::view
