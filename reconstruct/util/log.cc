#include "reconstruct/util/log.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace casual3d::util {
namespace {
LogOptions g_log_options;
std::mutex g_log_mutex;
}  // namespace

void SetLogOptions(const LogOptions& options) { g_log_options = options; }
const LogOptions& GetLogOptions() { return g_log_options; }

bool IsInteractive() {
  static const bool interactive = [] {
    const char* ci = std::getenv("CI");
    return isatty(fileno(stderr)) != 0 && (ci == nullptr || ci[0] == '\0');
  }();
  return interactive;
}

std::string JsonEscape(const std::string& s) {
  std::string out;
  out.reserve(s.size() + 2);
  for (unsigned char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default:
        if (c < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof(buf), "\\u%04x", c);
          out += buf;
        } else {
          out += static_cast<char>(c);
        }
    }
  }
  return out;
}

std::string FormatDuration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const long s = std::lround(seconds);
  char buf[32];
  if (s >= 3600) {
    std::snprintf(buf, sizeof(buf), "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
  } else {
    std::snprintf(buf, sizeof(buf), "%ld:%02ld", s / 60, s % 60);
  }
  return buf;
}

static void EmitLine(const char* level, const std::string& message) {
  std::lock_guard<std::mutex> lock(g_log_mutex);
  if (g_log_options.json) {
    std::fprintf(stderr, "{\"level\":\"%s\",\"message\":\"%s\"}\n", level,
                 JsonEscape(message).c_str());
  } else if (std::string(level) == "warning") {
    std::fprintf(stderr, "warning: %s\n", message.c_str());
  } else {
    std::fprintf(stderr, "%s\n", message.c_str());
  }
}

void LogInfo(const std::string& message) {
  if (g_log_options.verbose || g_log_options.json) EmitLine("info", message);
}

void LogWarning(const std::string& message) { EmitLine("warning", message); }

Progress::Progress(std::string stage, int64_t total)
    : stage_(std::move(stage)), total_(total > 0 ? total : 1),
      start_(std::chrono::steady_clock::now()), last_draw_(start_) {
  Draw(true);
}

Progress::~Progress() { Finish(); }

void Progress::Advance(int64_t n) {
  std::lock_guard<std::mutex> lock(mutex_);
  done_ += n;
  if (done_ > total_) done_ = total_;
  Draw(false);
}

void Progress::Set(int64_t done) {
  std::lock_guard<std::mutex> lock(mutex_);
  done_ = done < total_ ? done : total_;
  Draw(false);
}

double Progress::ElapsedSeconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void Progress::Finish() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  finished_ = true;
  done_ = total_;
  const double elapsed = ElapsedSeconds();
  std::lock_guard<std::mutex> log_lock(g_log_mutex);
  if (g_log_options.json) {
    std::fprintf(stderr, "{\"stage\":\"%s\",\"percent\":100,\"done\":true,\"seconds\":%.3f}\n",
                 JsonEscape(stage_).c_str(), elapsed);
  } else if (IsInteractive()) {
    std::fprintf(stderr, "\r\033[K%s: done in %s\n", stage_.c_str(),
                 FormatDuration(elapsed).c_str());
  } else if (g_log_options.verbose) {
    std::fprintf(stderr, "%s: done in %.1f s\n", stage_.c_str(), elapsed);
  }
  std::fflush(stderr);
}

// Caller holds mutex_.
void Progress::Draw(bool force) {
  const auto now = std::chrono::steady_clock::now();
  const double since_draw = std::chrono::duration<double>(now - last_draw_).count();
  const bool json = g_log_options.json;
  if (!json && !IsInteractive()) return;
  if (!force && since_draw < (json ? 0.5 : 0.1)) return;
  last_draw_ = now;
  const double fraction = static_cast<double>(done_) / static_cast<double>(total_);
  const double elapsed = ElapsedSeconds();
  const double eta = fraction > 0.0 ? elapsed * (1.0 - fraction) / fraction : -1.0;
  std::lock_guard<std::mutex> log_lock(g_log_mutex);
  if (json) {
    std::fprintf(stderr, "{\"stage\":\"%s\",\"percent\":%.1f,\"done\":false,\"eta_seconds\":%.1f}\n",
                 JsonEscape(stage_).c_str(), 100.0 * fraction, eta);
  } else {
    std::fprintf(stderr, "\r\033[K%s: %3.0f%% (%lld/%lld) ETA %s", stage_.c_str(),
                 100.0 * fraction, static_cast<long long>(done_), static_cast<long long>(total_),
                 eta >= 0 ? FormatDuration(eta).c_str() : "?");
  }
  std::fflush(stderr);
}

}  // namespace casual3d::util
