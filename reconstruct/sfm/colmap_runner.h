#pragma once

// Runs Debian's `colmap` program as a subprocess: one call per COLMAP command
// (feature_extractor, exhaustive_matcher, mapper, ...). Its stdout and stderr
// go, line by line, to a log file and to a callback that turns COLMAP's log
// lines into progress.

#include <signal.h>

#include <functional>
#include <string>
#include <vector>

namespace casual3d::sfm {

// The `colmap` executable: `configured` if not empty (must exist and be
// executable), else the first `colmap` on PATH. Throws std::runtime_error with
// the install hint ("apt-get install colmap") if there is none.
std::string FindColmap(const std::string& configured);

struct ColmapResult {
  int exit_code = 0;      // Exit status when the process exited.
  int signal = 0;         // Terminating signal, 0 if it exited.
  double seconds = 0.0;   // Wall-clock time.
  std::string last_lines;  // The last few lines of output, for error messages.
};

// Progress parsed from one COLMAP log line: done out of total, both > 0, or
// false when the line carries none. Understands "Processed file [i/N]",
// "Matching block [a/A, b/B]", "Matching image [i/N]", "Registering image #k (n)"
// (n out of `num_images`) and "Undistorting image [i/N]".
bool ParseColmapProgress(const std::string& line, int num_images, long* done, long* total);

// Runs `colmap <command> <args...>` and waits for it. Every output line is
// appended to `log_path` (created if needed) and passed to `on_line` (may be
// empty). Throws std::runtime_error only if the process cannot be started or
// the log cannot be written; a failing COLMAP is reported in the result.
ColmapResult RunColmap(const std::string& colmap, const std::string& command,
                       const std::vector<std::string>& args, const std::string& log_path,
                       const std::function<void(const std::string&)>& on_line);

// While an instance lives, SIGINT and SIGTERM no longer end this process at
// once: they are forwarded to the running COLMAP (which then exits) and
// recorded, so that the caller can clean up and stop (InterruptRequested()).
// One instance at a time; the previous handlers are restored on destruction.
class ScopedInterruptHandler {
 public:
  ScopedInterruptHandler();
  ~ScopedInterruptHandler();
  ScopedInterruptHandler(const ScopedInterruptHandler&) = delete;
  ScopedInterruptHandler& operator=(const ScopedInterruptHandler&) = delete;

 private:
  struct sigaction old_int_;
  struct sigaction old_term_;
};

// True once SIGINT or SIGTERM arrived under a ScopedInterruptHandler.
bool InterruptRequested();

// "exit status 3" or "killed by signal 9 (Killed)".
std::string DescribeExit(const ColmapResult& result);

}  // namespace casual3d::sfm
