#pragma once

// Runs the built `casual3d` program ($CASUAL3D_BINARY_DIR/cli/casual3d, set by
// the tests' CMake helper) for end-to-end tests.

#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <string>

namespace casual3d::testing {

struct CommandRun {
  int exit_code = -1;  // -1: did not start or did not exit.
  std::string output;  // stdout and stderr.
};

// `casual3d <args>` through the shell (quote arguments with spaces).
inline CommandRun Casual3d(const std::string& args) {
  const char* bin = std::getenv("CASUAL3D_BINARY_DIR");
  const std::string cmd = std::string(bin != nullptr ? bin : ".") + "/cli/casual3d " + args + " 2>&1";
  CommandRun run;
  FILE* pipe = popen(cmd.c_str(), "r");
  char buf[4096];
  size_t n;
  while (pipe && (n = fread(buf, 1, sizeof(buf), pipe)) > 0) run.output.append(buf, n);
  const int status = pipe ? pclose(pipe) : -1;
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

}  // namespace casual3d::testing
