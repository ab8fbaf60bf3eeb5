// ctest learns the test names from doctest and splits them at ';' (a CMake list), so a
// name with a semicolon becomes filters that match nothing and "pass" without running.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "helpers.hpp"

TEST_CASE("Test suite: no test name holds a semicolon, which ctest would split into empty tests") {
  // A plain search, not std::regex: GCC 12 warns inside <regex> under the sanitizers.
  const std::string opening = "TEST_CASE(\"";
  std::size_t names = 0;
  for (const auto& entry : std::filesystem::directory_iterator(mlmap::test::sourceDir() / "tests")) {
    if (entry.path().extension() != ".cpp") continue;
    std::ifstream in(entry.path());
    std::string line;
    while (std::getline(in, line)) {
      const std::size_t start = line.find(opening);
      if (start == std::string::npos) continue;
      const std::size_t begin = start + opening.size();
      const std::size_t end = line.find('"', begin);
      if (end == std::string::npos) continue;
      const std::string name = line.substr(begin, end - begin);
      ++names;
      INFO(entry.path().filename().string() << ": " << name);
      CHECK(name.find(';') == std::string::npos);
    }
  }
  CHECK(names > 100);
}
