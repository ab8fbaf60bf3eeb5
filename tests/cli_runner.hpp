// Runs the mlmap CLI built beside the tests and collects what it prints.
#pragma once

#include <doctest/doctest.h>
#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace mlmap::test {

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

// With `timeout_seconds` > 0 the CLI runs under `timeout`: a command that never returns
// (a reader of a device or a pipe) fails its test with 124 instead of hanging it.
inline CommandResult runCli(const std::string& arguments, int timeout_seconds = 0) {
  const std::string deadline = timeout_seconds > 0 ? "timeout " + std::to_string(timeout_seconds) + " " : "";
  const std::string command = deadline + std::string(MLMAP_CLI_PATH) + " " + arguments + " 2>&1";
  CommandResult result;
  FILE* pipe = ::popen(command.c_str(), "r");
  REQUIRE(pipe != nullptr);
  char buffer[4096];
  std::size_t count = 0;
  while ((count = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0) result.output.append(buffer, count);
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

}  // namespace mlmap::test
