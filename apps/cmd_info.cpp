#include "commands.hpp"

namespace mlmap::cli {

void addInfoCommand(CLI::App& app, Context& context) {
  auto* command = app.add_subcommand("info", "TODO");
  command->callback([&context] { context.run = [] { return 0; }; });
}

}  // namespace mlmap::cli
