// The CLI's OpenMP threads sleep while they wait unless the user chose a policy: the
// CLI starts itself again with OMP_WAIT_POLICY=passive (apps/passive_wait.cpp).
#include <doctest/doctest.h>

#include <cstdio>
#include <string>

namespace {

// What the OpenMP runtime says about its settings when `mlmap --version` starts.
std::string openmpSettings(const std::string& environment) {
  const std::string command =
      "env -u OMP_WAIT_POLICY -u GOMP_SPINCOUNT " + environment + " OMP_DISPLAY_ENV=verbose " MLMAP_CLI_PATH " --version 2>&1";
  std::string output;
  FILE* pipe = ::popen(command.c_str(), "r");
  REQUIRE(pipe != nullptr);
  char buffer[4096];
  std::size_t count = 0;
  while ((count = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0) output.append(buffer, count);
  ::pclose(pipe);
  return output;
}

}  // namespace

#ifdef MLMAP_HAVE_OPENMP
TEST_CASE("CLI: OpenMP threads wait passively unless OMP_WAIT_POLICY or GOMP_SPINCOUNT says otherwise") {
  // libgomp's verbose settings show the spin count the policy led to (0 when passive);
  // the program that runs is the last to print them.
  const auto spinCount = [](const std::string& environment) {
    const std::string settings = openmpSettings(environment);
    const std::string label = "GOMP_SPINCOUNT = '";
    const std::size_t at = settings.rfind(label);
    REQUIRE(at != std::string::npos);
    return settings.substr(at + label.size(), settings.find('\'', at + label.size()) - at - label.size());
  };
  CHECK(spinCount("") == "0");
  CHECK(spinCount("OMP_WAIT_POLICY=active") != "0");
  CHECK(spinCount("GOMP_SPINCOUNT=1000") == "1000");
  const std::string version = openmpSettings("");
  CHECK(version.find("mlmap 0.1.0") != std::string::npos);  // the program still runs, once
}
#endif
