// ctest learns the test names from doctest and splits them at ';' (a CMake list), so a
// name with a semicolon becomes filters that match nothing and "pass" without running.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include "helpers.hpp"

TEST_CASE("Test suite: no test name holds a semicolon, which ctest would split into empty tests") {
  const std::regex test_case(R"re(TEST_CASE\("([^"]*)")re");
  std::size_t names = 0;
  for (const auto& entry : std::filesystem::directory_iterator(mlmap::test::sourceDir() / "tests")) {
    if (entry.path().extension() != ".cpp") continue;
    std::ifstream in(entry.path());
    std::string line;
    while (std::getline(in, line)) {
      std::smatch match;
      if (!std::regex_search(line, match, test_case)) continue;
      ++names;
      INFO(entry.path().filename().string() << ": " << match[1].str());
      CHECK(match[1].str().find(';') == std::string::npos);
    }
  }
  CHECK(names > 100);
}
