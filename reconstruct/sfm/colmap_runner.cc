#include "reconstruct/sfm/colmap_runner.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <regex>
#include <sstream>
#include <stdexcept>

namespace casual3d::sfm {
namespace {

volatile sig_atomic_t g_interrupted = 0;
volatile sig_atomic_t g_child_pid = 0;

void OnInterrupt(int sig) {
  g_interrupted = 1;
  const pid_t child = static_cast<pid_t>(g_child_pid);
  if (child > 0) ::kill(child, sig);
}

bool IsExecutable(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(path.c_str(), X_OK) == 0;
}

}  // namespace

std::string FindColmap(const std::string& configured) {
  if (!configured.empty()) {
    if (IsExecutable(configured)) return configured;
    throw std::runtime_error(configured +
                             ": not an executable COLMAP program; fix --colmap or install "
                             "COLMAP with `apt-get install colmap`");
  }
  const char* path_env = std::getenv("PATH");
  std::istringstream dirs(path_env != nullptr ? path_env : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (dir.empty()) continue;
    const std::string candidate = dir + "/colmap";
    if (IsExecutable(candidate)) return candidate;
  }
  throw std::runtime_error(
      "colmap: program not found on PATH; install it with `apt-get install colmap` (Debian 12 "
      "ships COLMAP 3.8) or pass its path with --colmap");
}

bool ParseColmapProgress(const std::string& line, int num_images, long* done, long* total) {
  static const std::regex kBracket(
      R"((Processed file|Matching image|Undistorting image) \[(\d+)/(\d+)\])");
  static const std::regex kBlock(R"(Matching block \[(\d+)/(\d+), (\d+)/(\d+)\])");
  static const std::regex kRegister(R"(Registering image #\d+ \((\d+)\))");
  std::smatch m;
  if (std::regex_search(line, m, kBracket)) {
    *done = std::stol(m[2]);
    *total = std::stol(m[3]);
  } else if (std::regex_search(line, m, kBlock)) {
    const long a = std::stol(m[1]), na = std::stol(m[2]);
    const long b = std::stol(m[3]), nb = std::stol(m[4]);
    *done = (a - 1) * nb + b;
    *total = na * nb;
  } else if (std::regex_search(line, m, kRegister) && num_images > 0) {
    *done = std::stol(m[1]);
    *total = num_images;
  } else {
    return false;
  }
  if (*total <= 0) return false;
  if (*done > *total) *done = *total;
  return *done >= 0;
}

ColmapResult RunColmap(const std::string& colmap, const std::string& command,
                       const std::vector<std::string>& args, const std::string& log_path,
                       const std::function<void(const std::string&)>& on_line) {
  std::FILE* log = std::fopen(log_path.c_str(), "ab");
  if (log == nullptr) {
    throw std::runtime_error(log_path + ": cannot write the log: " + std::strerror(errno));
  }
  std::fprintf(log, "$ %s %s", colmap.c_str(), command.c_str());
  for (const auto& a : args) std::fprintf(log, " %s", a.c_str());
  std::fprintf(log, "\n");
  std::fflush(log);

  int fds[2];
  if (::pipe(fds) != 0) {
    std::fclose(log);
    throw std::runtime_error(std::string("cannot create a pipe for colmap: ") + std::strerror(errno));
  }
  // COLMAP prints its progress through std::cout, which is block-buffered into
  // a pipe; coreutils' stdbuf makes it line-buffered so progress is live.
  std::vector<std::string> argv_storage;
  if (IsExecutable("/usr/bin/stdbuf")) argv_storage = {"/usr/bin/stdbuf", "-oL", "-eL"};
  argv_storage.push_back(colmap);
  argv_storage.push_back(command);
  argv_storage.insert(argv_storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_storage) argv.push_back(a.data());
  argv.push_back(nullptr);

  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int err = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    std::fclose(log);
    throw std::runtime_error(std::string("cannot start colmap: ") + std::strerror(err));
  }
  if (pid == 0) {
    // Child: output to the pipe, no stdin, headless Qt.
    ::dup2(fds[1], STDOUT_FILENO);
    ::dup2(fds[1], STDERR_FILENO);
    ::close(fds[0]);
    ::close(fds[1]);
    const int devnull = ::open("/dev/null", O_RDONLY);
    if (devnull >= 0) ::dup2(devnull, STDIN_FILENO);
    ::setenv("QT_QPA_PLATFORM", "offscreen", 1);
    ::execv(argv[0], argv.data());
    std::fprintf(stderr, "cannot execute %s: %s\n", colmap.c_str(), std::strerror(errno));
    ::_exit(127);
  }
  ::close(fds[1]);
  g_child_pid = pid;

  ColmapResult result;
  std::deque<std::string> tail;
  std::string pending;
  char buf[4096];
  auto emit = [&](const std::string& line) {
    std::fprintf(log, "%s\n", line.c_str());
    tail.push_back(line);
    if (tail.size() > 8) tail.pop_front();
    if (on_line) on_line(line);
  };
  for (;;) {
    const ssize_t n = ::read(fds[0], buf, sizeof(buf));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    pending.append(buf, static_cast<size_t>(n));
    size_t pos;
    while ((pos = pending.find_first_of("\r\n")) != std::string::npos) {
      std::string line = pending.substr(0, pos);
      pending.erase(0, pos + 1);
      if (!line.empty()) emit(line);
    }
  }
  if (!pending.empty()) emit(pending);
  ::close(fds[0]);

  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  g_child_pid = 0;
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (WIFEXITED(status)) result.exit_code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) result.signal = WTERMSIG(status);
  for (const auto& l : tail) result.last_lines += l + "\n";
  std::fprintf(log, "# %s: %s after %.1f s\n", command.c_str(), DescribeExit(result).c_str(),
               result.seconds);
  const bool log_ok = std::fflush(log) == 0;
  std::fclose(log);
  if (!log_ok) throw std::runtime_error(log_path + ": cannot write the log (disk full?)");
  return result;
}

ScopedInterruptHandler::ScopedInterruptHandler() {
  g_interrupted = 0;
  struct sigaction sa;
  std::memset(&sa, 0, sizeof(sa));
  sa.sa_handler = OnInterrupt;
  sigemptyset(&sa.sa_mask);
  ::sigaction(SIGINT, &sa, &old_int_);
  ::sigaction(SIGTERM, &sa, &old_term_);
}

ScopedInterruptHandler::~ScopedInterruptHandler() {
  ::sigaction(SIGINT, &old_int_, nullptr);
  ::sigaction(SIGTERM, &old_term_, nullptr);
}

bool InterruptRequested() { return g_interrupted != 0; }

std::string DescribeExit(const ColmapResult& result) {
  if (result.signal != 0) {
    return "killed by signal " + std::to_string(result.signal) + " (" +
           ::strsignal(result.signal) + ")";
  }
  return "exit status " + std::to_string(result.exit_code);
}

}  // namespace casual3d::sfm
