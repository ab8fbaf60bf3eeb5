// The mlmap command line: argument handling and progress only; the work is the library's.
#if __has_include(<malloc.h>)
#include <malloc.h>
#endif
#include <CLI/CLI.hpp>

#include <iostream>
#include <string>

#include "commands.hpp"
#include "passive_wait.hpp"
#include "mlmap/error.hpp"
#include "mlmap/io/atomic_file.hpp"

namespace {

// The CLI runs one job and exits: memory it frees is better kept for its next large
// buffer than handed back to the kernel. Each pass of eRMSM and the map builder
// allocates arrays of a few MB, which glibc maps fresh and zero-fills page by page
// on first touch (about 1.7 µs per 4 KB page on the project machine): the 2 cm lab's
// eRMSM block grid took 10.6 ms that way, 4.8 ms from kept memory.
void keepFreedMemory() {
#if defined(__GLIBC__) && defined(M_TOP_PAD)
  mallopt(M_MMAP_THRESHOLD, 32 << 20);  // glibc's largest
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
  mallopt(M_TOP_PAD, 64 << 20);
#endif
}

// One line in one style for every error: CLI11's messages may hold line breaks.
std::string oneLine(std::string text) {
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

}  // namespace

int main(int argc, char** argv) {
  mlmap::cli::preferPassiveWaiting(argv);
  keepFreedMemory();
  mlmap::io::removeTemporaryFilesOnSignal();
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
    // --help and --version end parsing too, successfully.
    if (error.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(error);
    // CLI11 reports a typo'd command as "A subcommand is required": name the word instead.
    if (app.get_subcommands().empty() && argc > 1) {
      for (int k = 1; k < argc; ++k) {
        if (argv[k][0] == '-') continue;
        std::cerr << "mlmap: '" << argv[k] << "' is not a command (see mlmap --help)\n";
        return 1;
      }
    }
    std::cerr << "mlmap: " << oneLine(error.what()) << " (see mlmap --help)\n";
    return 1;
  }
  try {
    return context.run();
  } catch (const std::exception& error) {  // mlmap::Error names the file; anything else is a failure too
    std::cerr << "mlmap: " << oneLine(error.what()) << "\n";
    return 1;
  }
}
