#pragma once

// The single-file form of a package (".c3d"): the same files as the package
// folder in one container, for sharing and for tools. Standard library only.
//
// Layout (all integers little-endian):
//   offset 0   8 bytes  magic 0x89 'C' '3' 'D' 0x0D 0x0A 0x1A 0x0A
//   offset 8   u16      major version (1)
//   offset 10  u16      minor version (0)
//   offset 12  u32      entry count N (1 .. kMaxSingleFileEntries)
//   offset 16  N directory entries, each:
//                u16 path length P (1..255), P bytes of path,
//                u64 data offset (from the start of the file), u64 data size
//   then the data of the entries, in any order, within the file.
// The first entry is "manifest.json". Paths follow IsSafePackagePath and are
// unique. Readers refuse an unknown major version and ignore bytes they do not
// reference (a later minor version may add entries after the data). The
// header's version is the container's own, independent of the manifest's.
// Entries may share bytes (identical files stored once); entries the manifest
// does not list are ignored by package readers.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "format/reader_checks.h"
#include "format/status.h"

namespace casual3d {

constexpr uint8_t kSingleFileMagic[8] = {0x89, 'C', '3', 'D', 0x0D, 0x0A, 0x1A, 0x0A};
constexpr uint16_t kSingleFileVersionMajor = 1;
constexpr uint16_t kSingleFileVersionMinor = 0;
constexpr uint32_t kMaxSingleFileEntries = 1u << 20;

// A named byte range inside a single-file container.
struct SingleFileEntry {
  std::string path;
  uint64_t offset = 0;
  uint64_t size = 0;
};

// Serializes `files` (path, bytes) into a container; the manifest must be the
// first file. Returns kInvalidArgument for an unsafe or duplicate path.
StatusOr<std::vector<uint8_t>> BuildSingleFile(
    const std::vector<std::pair<std::string, std::vector<uint8_t>>>& files);

// Parses the header and directory of a container of `size` bytes (only the
// first bytes are read; `data` must hold all `size` bytes). Checks magic,
// version, limits, paths, that paths are unique, that the first entry is the
// manifest and that each entry lies inside the container; the named rules
// among these (container-unknown-major, path-escape, duplicate-entry,
// manifest-not-first, entry-outside-file) only when on in `checks`. An entry
// kept with entry-outside-file off is refused when read (SingleFileSource).
StatusOr<std::vector<SingleFileEntry>> ParseSingleFileDirectory(
    const uint8_t* data, size_t size, const ReaderChecks& checks = ReaderChecks());

}  // namespace casual3d
