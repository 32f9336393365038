#pragma once

// Atomic file writes for every writer of encoder/, reconstruct/ and cli/: the
// data goes to a temporary file beside the destination (the same folder, so
// the same file system) and is renamed over it only once complete, so that a
// reader sees the old file or the new one, never half of one. A failed write
// leaves the destination as it was and no temporary file behind. Folders
// written whole (a package, a stage's output) are swapped in the same way.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "format/status.h"

namespace casual3d::base {

// A temporary path beside `path`, unique to this process and call:
// "<path>.tmp-<pid>-<counter>".
std::string TemporaryPathFor(const std::string& path);

// Renames `tmp_path` over `path`. On failure removes `tmp_path` and returns
// kIoError "<path>: cannot write (<reason>)".
Status CommitTemporary(const std::string& tmp_path, const std::string& path);

// Calls write(tmp) with a temporary path beside `path` (TemporaryPathFor),
// then renames the file it wrote over `path`. If `write` returns a non-OK
// status or throws, or the rename fails, the temporary file is removed and
// `path` is left untouched; the status is returned, the exception rethrown.
// Creates no folders.
Status WriteAtomically(const std::string& path,
                       const std::function<Status(const std::string& tmp_path)>& write);

// Writes `size` bytes from `data` to `path` atomically. kIoError
// "<path>: cannot write (<reason>)" when the folder is missing or not
// writable, or the disk is full.
Status WriteFileAtomic(const std::string& path, const void* data, size_t size);
inline Status WriteFileAtomic(const std::string& path, std::string_view bytes) {
  return WriteFileAtomic(path, bytes.data(), bytes.size());
}
inline Status WriteFileAtomic(const std::string& path, const std::vector<uint8_t>& bytes) {
  return WriteFileAtomic(path, bytes.data(), bytes.size());
}

// Puts the folder `staged`, written beside `dir`, in the place of `dir`: an
// existing `dir` is first renamed aside (TemporaryPathFor), then `staged` is
// renamed to `dir` and the old folder removed. Readers see the old folder or
// the new one, never a mix. If `staged` cannot be moved into place the old
// folder is put back and kIoError "<dir>: cannot move the new folder into
// place (<reason>)" returned ("... the previous folder aside ..." when the old
// one cannot be moved); `staged` is then left for the caller to remove.
Status ReplaceFolder(const std::string& staged, const std::string& dir);

}  // namespace casual3d::base
