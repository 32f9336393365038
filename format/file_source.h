#pragma once

// Where a package reader gets the bytes of a package's files: a folder, a
// single-file container, or memory (for example bytes handed in from
// JavaScript). Standard library only, no exceptions.

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "format/reader_checks.h"
#include "format/single_file.h"
#include "format/status.h"

namespace casual3d {

// A read-only set of files addressed by package-relative paths. Implementations
// must allow Read from several threads at once.
class FileSource {
 public:
  virtual ~FileSource() = default;
  // The whole content of `path`. kNotFound if it does not exist, kLimitExceeded
  // if it is larger than `max_bytes` (checked before reading), kInvalidArgument
  // if `path` is not a safe package path (IsSafePackagePath).
  virtual StatusOr<std::vector<uint8_t>> Read(const std::string& path, uint64_t max_bytes) const = 0;
};

// Files held in memory.
class MemoryFileSource : public FileSource {
 public:
  void Add(const std::string& path, std::vector<uint8_t> bytes) { files_[path] = std::move(bytes); }
  StatusOr<std::vector<uint8_t>> Read(const std::string& path, uint64_t max_bytes) const override;

 private:
  std::map<std::string, std::vector<uint8_t>> files_;
};

// The entries of a single-file container (single_file.h) held in memory.
class SingleFileSource : public FileSource {
 public:
  // Parses the container's directory; fails as ParseSingleFileDirectory does
  // with `checks`. Of entries sharing a path, the first is read.
  static StatusOr<std::unique_ptr<SingleFileSource>> Create(
      std::vector<uint8_t> container, const ReaderChecks& checks = ReaderChecks());
  StatusOr<std::vector<uint8_t>> Read(const std::string& path, uint64_t max_bytes) const override;
  const std::vector<SingleFileEntry>& entries() const { return entries_; }

 private:
  std::vector<uint8_t> bytes_;
  std::vector<SingleFileEntry> entries_;
  std::map<std::string, size_t> index_;
  ReaderChecks checks_;
};

// Files of a package folder on disk. Paths are checked with IsSafePackagePath
// before they touch the file system, so they cannot leave `root` (unless the
// path-escape check is off in `checks`: conformance tests only).
class FolderFileSource : public FileSource {
 public:
  explicit FolderFileSource(std::string root, const ReaderChecks& checks = ReaderChecks())
      : root_(std::move(root)), checks_(checks) {}
  StatusOr<std::vector<uint8_t>> Read(const std::string& path, uint64_t max_bytes) const override;

 private:
  std::string root_;
  ReaderChecks checks_;
};

// Opens a package given as a folder (holding manifest.json) or as a
// single-file container (read whole into memory, at most `max_single_file_bytes`).
// Errors name `path` and say which form was expected. `checks` as for
// FolderFileSource and SingleFileSource.
StatusOr<std::unique_ptr<FileSource>> OpenPackage(const std::string& path,
                                                  uint64_t max_single_file_bytes = 1ull << 31,
                                                  const ReaderChecks& checks = ReaderChecks());

// Reads a whole file from disk, refusing files above `max_bytes`.
StatusOr<std::vector<uint8_t>> ReadWholeFile(const std::string& path, uint64_t max_bytes);

}  // namespace casual3d
