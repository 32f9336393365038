#include "format/file_source.h"

#include <cstdio>

#include "format/manifest.h"

namespace casual3d {
namespace {

Status CheckPath(const std::string& path, const ReaderChecks& checks = ReaderChecks()) {
  if (!IsSafePackagePath(path) && checks.on(ReaderCheck::kPathEscape))
    return InvalidArgument("\"" + path.substr(0, 80) +
                           "\" is not a safe relative path inside the package");
  return Status::Ok();
}

Status TooLarge(const std::string& path, uint64_t size, uint64_t max_bytes) {
  return LimitExceeded(path + ": " + std::to_string(size) + " bytes, more than the " +
                       std::to_string(max_bytes) + " expected");
}

}  // namespace

StatusOr<std::vector<uint8_t>> MemoryFileSource::Read(const std::string& path,
                                                      uint64_t max_bytes) const {
  CASUAL3D_RETURN_IF_ERROR(CheckPath(path));
  auto it = files_.find(path);
  if (it == files_.end()) return NotFound(path + ": no such file in the package");
  if (it->second.size() > max_bytes) return TooLarge(path, it->second.size(), max_bytes);
  return it->second;
}

StatusOr<std::unique_ptr<SingleFileSource>> SingleFileSource::Create(
    std::vector<uint8_t> container, const ReaderChecks& checks) {
  CASUAL3D_ASSIGN_OR_RETURN(std::vector<SingleFileEntry> entries,
                            ParseSingleFileDirectory(container.data(), container.size(), checks));
  std::unique_ptr<SingleFileSource> source(new SingleFileSource());
  source->bytes_ = std::move(container);
  source->entries_ = std::move(entries);
  source->checks_ = checks;
  for (size_t i = 0; i < source->entries_.size(); ++i)
    source->index_.emplace(source->entries_[i].path, i);
  return source;
}

StatusOr<std::vector<uint8_t>> SingleFileSource::Read(const std::string& path,
                                                      uint64_t max_bytes) const {
  CASUAL3D_RETURN_IF_ERROR(CheckPath(path, checks_));
  auto it = index_.find(path);
  if (it == index_.end()) return NotFound(path + ": no such entry in the single file");
  const SingleFileEntry& e = entries_[it->second];
  // Kept by the directory only with the entry-outside-file check off.
  if (e.offset > bytes_.size() || e.size > bytes_.size() - e.offset)
    return InvalidData(path + ": the entry's data range lies outside the single file");
  if (e.size > max_bytes) return TooLarge(path, e.size, max_bytes);
  const uint8_t* begin = bytes_.data() + e.offset;
  return std::vector<uint8_t>(begin, begin + e.size);
}

StatusOr<std::vector<uint8_t>> ReadWholeFile(const std::string& path, uint64_t max_bytes) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) return NotFound(path + ": cannot open (missing file?)");
  std::vector<uint8_t> bytes;
  // Read in chunks so that the size limit holds even for special files.
  std::vector<uint8_t> chunk(1 << 16);
  while (true) {
    const size_t n = std::fread(chunk.data(), 1, chunk.size(), f);
    if (n > 0) {
      if (bytes.size() + n > max_bytes) {
        std::fclose(f);
        return TooLarge(path, bytes.size() + n, max_bytes);
      }
      bytes.insert(bytes.end(), chunk.data(), chunk.data() + n);
    }
    if (n < chunk.size()) break;
  }
  const bool failed = std::ferror(f) != 0;
  std::fclose(f);
  // A folder opens but does not read.
  if (failed) return IoError(path + ": read error (a folder?)");
  return bytes;
}

StatusOr<std::vector<uint8_t>> FolderFileSource::Read(const std::string& path,
                                                      uint64_t max_bytes) const {
  CASUAL3D_RETURN_IF_ERROR(CheckPath(path, checks_));
  return ReadWholeFile(root_ + "/" + path, max_bytes);
}

StatusOr<std::unique_ptr<FileSource>> OpenPackage(const std::string& path,
                                                  uint64_t max_single_file_bytes,
                                                  const ReaderChecks& checks) {
  if (std::FILE* f = std::fopen((path + "/" + kManifestFileName).c_str(), "rb")) {
    std::fclose(f);
    return std::unique_ptr<FileSource>(new FolderFileSource(path, checks));
  }
  StatusOr<std::vector<uint8_t>> bytes = ReadWholeFile(path, max_single_file_bytes);
  if (!bytes.ok())
    return Status(bytes.status().code(),
                  path + ": not a package folder (no manifest.json) nor a readable .c3d file: " +
                      bytes.status().message());
  StatusOr<std::unique_ptr<SingleFileSource>> single = SingleFileSource::Create(std::move(*bytes), checks);
  if (!single.ok())
    return Status(single.status().code(), path + ": not a package folder (no manifest.json) "
                                                 "nor a valid .c3d file: " +
                                              single.status().message());
  return std::unique_ptr<FileSource>(std::move(*single));
}

}  // namespace casual3d
