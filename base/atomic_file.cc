#include "base/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <system_error>

namespace casual3d::base {
namespace {

Status CannotWrite(const std::string& path, const std::string& reason) {
  return IoError(path + ": cannot write (" + reason + ")");
}

}  // namespace

std::string TemporaryPathFor(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  return path + ".tmp-" + std::to_string(static_cast<long>(::getpid())) + "-" +
         std::to_string(counter.fetch_add(1));
}

Status CommitTemporary(const std::string& tmp_path, const std::string& path) {
  if (std::rename(tmp_path.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    std::remove(tmp_path.c_str());
    return CannotWrite(path, reason);
  }
  return Status::Ok();
}

Status WriteAtomically(const std::string& path,
                       const std::function<Status(const std::string& tmp_path)>& write) {
  const std::string tmp = TemporaryPathFor(path);
  Status written;
  try {
    written = write(tmp);
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
  if (!written.ok()) {
    std::remove(tmp.c_str());
    return written;
  }
  return CommitTemporary(tmp, path);
}

Status WriteFileAtomic(const std::string& path, const void* data, size_t size) {
  return WriteAtomically(path, [&](const std::string& tmp) {
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    if (f == nullptr) return CannotWrite(path, std::strerror(errno));
    const size_t written = size == 0 ? 0 : std::fwrite(data, 1, size, f);
    const int write_errno = errno;
    const bool flushed = std::fflush(f) == 0;
    const int flush_errno = errno;
    const bool closed = std::fclose(f) == 0;
    if (written != size) return CannotWrite(path, std::strerror(write_errno));
    if (!flushed) return CannotWrite(path, std::strerror(flush_errno));
    if (!closed) return CannotWrite(path, std::strerror(errno));
    return Status::Ok();
  });
}

Status ReplaceFolder(const std::string& staged, const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  std::string old;
  if (fs::exists(dir, ec)) {
    old = TemporaryPathFor(dir);
    fs::rename(dir, old, ec);
    if (ec) return IoError(dir + ": cannot move the previous folder aside (" + ec.message() + ")");
  }
  fs::rename(staged, dir, ec);
  if (ec) {
    const std::string reason = ec.message();
    if (!old.empty()) fs::rename(old, dir, ec);
    return IoError(dir + ": cannot move the new folder into place (" + reason + ")");
  }
  if (!old.empty()) fs::remove_all(old, ec);
  return Status::Ok();
}

}  // namespace casual3d::base
