#include "commands.hpp"

namespace mlmap::cli {

void addBuildCommand(CLI::App& app, Context& context) {
  auto* command = app.add_subcommand("build", "TODO");
  command->callback([&context] { context.run = [] { return 0; }; });
}

}  // namespace mlmap::cli
