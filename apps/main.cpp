// The mlmap command line: argument handling and progress only; the work is the library's.
#include <CLI/CLI.hpp>

#include <iostream>

#include "commands.hpp"
#include "mlmap/error.hpp"

int main(int argc, char** argv) {
  CLI::App app{"mlmap: Multi-Level maps from 3D laser scans, and the planes in them"};
  app.set_version_flag("--version", "mlmap 0.1.0");
  app.require_subcommand(1);
  app.fallthrough();  // --quiet also after the subcommand
  mlmap::cli::Context context;
  app.add_flag("-q,--quiet", context.quiet, "No progress on stderr");
  mlmap::cli::addCommands(app, context);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app.exit(error);
  }
  try {
    return context.run();
  } catch (const mlmap::Error& error) {
    std::cerr << "mlmap: " << error.what() << "\n";
    return 1;
  } catch (const std::exception& error) {
    std::cerr << "mlmap: " << error.what() << "\n";
    return 2;
  }
}
