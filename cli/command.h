#pragma once

// Each subcommand lives in its own cli/<name>_command.cc and registers itself
// with main() through an Add*Command function declared here. Commands parse
// options, check them and call the library; they report failure by throwing
// (std::exception), which main() turns into one line on stderr and exit code 1.

#include <CLI/CLI.hpp>

namespace casual3d::cli {

// Options every command understands (set by main before the command runs).
struct GlobalOptions {
  bool verbose = false;  // --verbose: more detail on stderr.
  bool json = false;     // --json: machine-readable log lines (JSON) on stderr.
};
const GlobalOptions& Globals();

}  // namespace casual3d::cli
