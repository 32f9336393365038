#include "reconstruct/io/file_util.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "base/atomic_file.h"

namespace casual3d::io {

void ThrowIfError(const Status& status) {
  if (!status.ok()) throw IoException(status.message());
}

void WriteFileAtomic(const std::string& path, const std::string& bytes) {
  ThrowIfError(base::WriteFileAtomic(path, bytes));
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw IoException(path + ": cannot open (" + std::strerror(errno) + ")");
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw IoException(path + ": read error");
  return ss.str();
}

void CreateDirectories(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir)) {
    throw IoException(dir + ": cannot create directory (" +
                      (ec ? ec.message() : std::string("a file is in the way")) + ")");
  }
}

}  // namespace casual3d::io
