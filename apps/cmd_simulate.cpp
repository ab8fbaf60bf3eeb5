#include "commands.hpp"

namespace mlmap::cli {

void addSimulateCommand(CLI::App& app, Context& context) {
  auto* command = app.add_subcommand("simulate", "TODO");
  command->callback([&context] { context.run = [] { return 0; }; });
}

}  // namespace mlmap::cli
