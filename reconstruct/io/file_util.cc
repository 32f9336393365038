#include "reconstruct/io/file_util.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace casual3d::io {

std::string TemporaryPathFor(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  return path + ".tmp-" + std::to_string(static_cast<long>(::getpid())) + "-" +
         std::to_string(counter.fetch_add(1));
}

void CommitTemporary(const std::string& tmp_path, const std::string& path) {
  if (std::rename(tmp_path.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    std::remove(tmp_path.c_str());
    throw IoError(path + ": cannot write (" + reason + ")");
  }
}

void WriteFileAtomic(const std::string& path, const std::string& bytes) {
  const std::string tmp = TemporaryPathFor(path);
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (f == nullptr) {
    throw IoError(path + ": cannot write (" + std::strerror(errno) + ")");
  }
  const size_t written = std::fwrite(bytes.data(), 1, bytes.size(), f);
  const int flush_error = std::fflush(f);
  const int close_error = std::fclose(f);
  if (written != bytes.size() || flush_error != 0 || close_error != 0) {
    const std::string reason = std::strerror(errno);
    std::remove(tmp.c_str());
    throw IoError(path + ": cannot write (" + reason + ")");
  }
  CommitTemporary(tmp, path);
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw IoError(path + ": cannot open (" + std::strerror(errno) + ")");
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw IoError(path + ": read error");
  return ss.str();
}

void CreateDirectories(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir)) {
    throw IoError(dir + ": cannot create directory (" +
                  (ec ? ec.message() : std::string("a file is in the way")) + ")");
  }
}

}  // namespace casual3d::io
