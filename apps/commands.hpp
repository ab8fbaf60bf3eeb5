// The subcommands of the mlmap CLI. Each adds itself to the CLI11 app and sets the
// context's action, so main() runs it after parsing and turns errors into exit codes.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>

namespace mlmap::cli {

struct Context {
  bool quiet = false;
  std::function<int()> run = [] { return 0; };
};

void addBuildCommand(CLI::App& app, Context& context);
void addInfoCommand(CLI::App& app, Context& context);
void addSimulateCommand(CLI::App& app, Context& context);
void addRegisterCommand(CLI::App& app, Context& context);
void addCalibrateCommand(CLI::App& app, Context& context);
void addPlanesCommand(CLI::App& app, Context& context);
void addLabelCommand(CLI::App& app, Context& context);
void addScanCommand(CLI::App& app, Context& context);
void addReplayCommand(CLI::App& app, Context& context);
void addEmulateCommand(CLI::App& app, Context& context);
void addExportCommand(CLI::App& app, Context& context);
void addMergeCommand(CLI::App& app, Context& context);

inline void addCommands(CLI::App& app, Context& context) {
  addSimulateCommand(app, context);
  addBuildCommand(app, context);
  addInfoCommand(app, context);
  addRegisterCommand(app, context);
  addCalibrateCommand(app, context);
  addPlanesCommand(app, context);
  addLabelCommand(app, context);
  addMergeCommand(app, context);
  addExportCommand(app, context);
  addScanCommand(app, context);
  addReplayCommand(app, context);
  addEmulateCommand(app, context);
}

}  // namespace mlmap::cli
