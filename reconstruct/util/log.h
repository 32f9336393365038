#pragma once

// Logging and progress for long-running stages.
//
// On a terminal, Progress draws one updating line on stderr: stage, percent,
// count and ETA. When stderr is not a terminal or CI is set (CI logs), it stays
// quiet except for one line per finished stage with --verbose. With --json each
// update (at most 2 per second) and each log line is a JSON object on stderr.

#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace casual3d::util {

struct LogOptions {
  bool verbose = false;  // Print Info lines and per-stage summaries.
  bool json = false;     // Emit JSON lines instead of text.
};

// Set once by the program's entry point (cli/main.cc) before any stage runs.
void SetLogOptions(const LogOptions& options);
const LogOptions& GetLogOptions();

// Info: only with --verbose. Warning: always, prefixed "warning: ".
void LogInfo(const std::string& message);
void LogWarning(const std::string& message);

// True when progress lines should be drawn (stderr is a terminal and CI unset).
bool IsInteractive();

// Thread-safe progress of one stage. Advance() may be called from worker threads.
class Progress {
 public:
  Progress(std::string stage, int64_t total);
  ~Progress();  // Calls Finish() if not done.
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void Advance(int64_t n = 1);
  void Set(int64_t done);
  void Finish();
  double ElapsedSeconds() const;

 private:
  void Draw(bool force);

  std::string stage_;
  int64_t total_;
  int64_t done_ = 0;
  bool finished_ = false;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
  std::mutex mutex_;
};

// Formats seconds as "1:05" or "1:02:03".
std::string FormatDuration(double seconds);
// Escapes a string for inclusion in JSON.
std::string JsonEscape(const std::string& s);

}  // namespace casual3d::util
