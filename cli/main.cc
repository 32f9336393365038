// casual3d: casual 3D photography from the command line.

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>

#if defined(__linux__) && defined(__GLIBC__)
#include <unistd.h>
#endif

#include <CLI/CLI.hpp>

#include "cli/command.h"
#include "format/version.h"
#include "reconstruct/util/log.h"

namespace casual3d::cli {
namespace {
GlobalOptions g_options;
}  // namespace

const GlobalOptions& Globals() { return g_options; }

namespace {

// The reconstruction allocates and frees buffers of tens to hundreds of
// megabytes per photo, and faulting their pages in 4 KiB at a time is slow;
// glibc's allocator asks for transparent huge pages (2 MiB) only when its
// glibc.malloc.hugetlb tunable is set before the process starts
// (docs/DECISIONS.md, "Dense: huge pages and reused buffers"). So the command
// restarts itself once with the tunable added, unless the environment
// already sets it (which also stops a second restart). Nothing changes when
// the restart fails.
void RestartWithHugePages(char** argv) {
#if defined(__linux__) && defined(__GLIBC__)
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (tunables && std::strstr(tunables, "glibc.malloc.hugetlb")) return;
  std::string value = tunables && *tunables ? std::string(tunables) + ":" : std::string();
  value += "glibc.malloc.hugetlb=1";
  if (setenv("GLIBC_TUNABLES", value.c_str(), 1) != 0) return;
  execv("/proc/self/exe", argv);
  // Still here: run as we are, without leaving the variable to children.
  if (tunables) {
    setenv("GLIBC_TUNABLES", tunables, 1);
  } else {
    unsetenv("GLIBC_TUNABLES");
  }
#else
  (void)argv;
#endif
}

}  // namespace
}  // namespace casual3d::cli

int main(int argc, char** argv) {
  casual3d::cli::RestartWithHugePages(argv);
  using casual3d::cli::g_options;
  CLI::App app{"casual3d: turns a few dozen hand-held photos into a 3D photo"};
  app.set_version_flag("--version", std::string("casual3d ") + casual3d::kVersion);
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
  } catch (const CLI::ValidationError& e) {
    // A value outside its option's range: one line naming the flag and the range.
    std::fprintf(stderr, "casual3d: error: %s\n", e.what());
    return 1;
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "casual3d: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
