#pragma once

// File helpers of reconstruct/: the exception reconstruct/ raises for
// input/output failures (STYLE.md, "Errors": inside reconstruct/, I/O failures
// raise an error naming the input and the reason), and the throwing forms of
// base/atomic_file.h's writes (a temporary file next to the destination,
// renamed over it only when complete, so that readers never see a
// half-written file).

#include <stdexcept>
#include <string>

#include "format/status.h"

namespace casual3d::io {

// An input/output failure; what() names the file and the reason, e.g.
// "photos/IMG_7.jpg: not a decodable image". The thrown counterpart of a
// kIoError (or kInvalidData, kNotFound) Status from the layers below.
class IoException : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Throws IoException(status.message()) unless `status` is OK.
void ThrowIfError(const Status& status);

// Writes `bytes` to `path` atomically (base::WriteFileAtomic). Creates no
// directories. Throws IoException.
void WriteFileAtomic(const std::string& path, const std::string& bytes);

// Reads a whole file. Throws IoException ("path: cannot open (No such file or directory)").
std::string ReadFile(const std::string& path);

// Creates `dir` and its parents if missing. Throws IoException if that fails or a
// non-directory is in the way.
void CreateDirectories(const std::string& dir);

}  // namespace casual3d::io
