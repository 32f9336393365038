// casual3d: casual 3D photography from the command line.

#include <cstdio>
#include <exception>
#include <string>

#include <CLI/CLI.hpp>

#include "cli/command.h"
#include "reconstruct/util/log.h"

namespace casual3d::cli {
namespace {
GlobalOptions g_options;
}  // namespace

const GlobalOptions& Globals() { return g_options; }

}  // namespace casual3d::cli

int main(int argc, char** argv) {
  using casual3d::cli::g_options;
  CLI::App app{"casual3d: turns a few dozen hand-held photos into a 3D photo"};
  app.set_version_flag("--version", std::string("casual3d 0.1.0"));
  app.require_subcommand(1);
  app.add_flag("--verbose,-v", g_options.verbose, "More detail on stderr");
  app.add_flag("--json", g_options.json, "Log as JSON lines on stderr");

  casual3d::cli::AddSynthCommand(app);
  casual3d::cli::AddReconstructCommand(app);
  casual3d::cli::AddPanoramaCommand(app);
  casual3d::cli::AddViewCommand(app);
  casual3d::cli::AddSparseCommand(app);
  casual3d::cli::AddDenseCommand(app);
  casual3d::cli::AddEncodeCommand(app);
  casual3d::cli::AddInfoCommand(app);
  casual3d::cli::AddValidateCommand(app);
  casual3d::cli::AddExportCommand(app);
  casual3d::cli::AddEvaluateCommand(app);

  app.parse_complete_callback([&] {
    casual3d::util::SetLogOptions({g_options.verbose, g_options.json});
  });
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "casual3d: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
