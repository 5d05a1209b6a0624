// adit view --allow-commands lets a page send save_map only: the verb is matched as a whole word.
#include "view/page_command.hpp"

#include <gtest/gtest.h>

namespace adit::view {
namespace {

using Words = std::vector<std::string>;

TEST(PageCommand, SaveMapIsMatchedAsAWholeWord) {
  EXPECT_EQ(saveMapArguments("save_map"), Words{});
  EXPECT_EQ(saveMapArguments("save_map drift_check"), Words{"drift_check"});
  EXPECT_EQ(saveMapArguments("  save_map \t a  b "), (Words{"a", "b"}));  // more than one name: saveMap refuses
  for (const char* other : {"save_mapX", "save_map_all drift", "save_ma", "Save_map", "xsave_map", "", "   ",
                            "play", "seek 3"})
    EXPECT_FALSE(saveMapArguments(other).has_value()) << "'" << other << "'";
}

}  // namespace
}  // namespace adit::view
