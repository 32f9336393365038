#pragma once

// File helpers shared by every writer in reconstruct/: atomic writes (data goes
// to a temporary file next to the destination, renamed over it only when
// complete, so that readers never see a half-written file) and the error type
// that reconstruct/io raises.

#include <stdexcept>
#include <string>

namespace casual3d::io {

// An input/output failure; what() names the file and the reason, e.g.
// "photos/IMG_7.jpg: not a decodable image".
class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A temporary path in the same directory as `path` (so that rename() is atomic),
// unique to this process and call: "<path>.tmp-<pid>-<counter>".
std::string TemporaryPathFor(const std::string& path);

// Renames `tmp_path` over `path`; on failure removes `tmp_path` and throws IoError.
void CommitTemporary(const std::string& tmp_path, const std::string& path);

// Writes `bytes` to `path` atomically. Creates no directories. Throws IoError.
void WriteFileAtomic(const std::string& path, const std::string& bytes);

// Reads a whole file. Throws IoError ("path: cannot open (No such file or directory)").
std::string ReadFile(const std::string& path);

// Creates `dir` and its parents if missing. Throws IoError if that fails or a
// non-directory is in the way.
void CreateDirectories(const std::string& dir);

}  // namespace casual3d::io
