#include "format/single_file.h"

#include <algorithm>
#include <cstring>
#include <set>

#include "format/manifest.h"

namespace casual3d {
namespace {

void PutU16(std::vector<uint8_t>* out, uint16_t v) {
  out->push_back(static_cast<uint8_t>(v));
  out->push_back(static_cast<uint8_t>(v >> 8));
}
void PutU32(std::vector<uint8_t>* out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<uint8_t>(v >> (8 * i)));
}
void PutU64(std::vector<uint8_t>* out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out->push_back(static_cast<uint8_t>(v >> (8 * i)));
}
uint64_t GetLE(const uint8_t* p, int bytes) {
  uint64_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

}  // namespace

StatusOr<std::vector<uint8_t>> BuildSingleFile(
    const std::vector<std::pair<std::string, std::vector<uint8_t>>>& files) {
  if (files.empty() || files[0].first != kManifestFileName)
    return InvalidArgument("single file: the first entry must be manifest.json");
  if (files.size() > kMaxSingleFileEntries)
    return InvalidArgument("single file: more than " + std::to_string(kMaxSingleFileEntries) +
                           " entries");
  std::set<std::string> seen;
  uint64_t header = 16;
  for (const auto& [path, bytes] : files) {
    if (!IsSafePackagePath(path))
      return InvalidArgument("single file: unsafe entry path \"" + path + "\"");
    if (!seen.insert(path).second)
      return InvalidArgument("single file: duplicate entry path \"" + path + "\"");
    header += 2 + path.size() + 16;
  }
  std::vector<uint8_t> out;
  out.insert(out.end(), kSingleFileMagic, kSingleFileMagic + 8);
  PutU16(&out, kSingleFileVersionMajor);
  PutU16(&out, kSingleFileVersionMinor);
  PutU32(&out, static_cast<uint32_t>(files.size()));
  uint64_t offset = header;
  for (const auto& [path, bytes] : files) {
    PutU16(&out, static_cast<uint16_t>(path.size()));
    out.insert(out.end(), path.begin(), path.end());
    PutU64(&out, offset);
    PutU64(&out, bytes.size());
    offset += bytes.size();
  }
  for (const auto& file : files) out.insert(out.end(), file.second.begin(), file.second.end());
  return out;
}

StatusOr<std::vector<SingleFileEntry>> ParseSingleFileDirectory(const uint8_t* data,
                                                                size_t size,
                                                                const ReaderChecks& checks) {
  if (size < 16) return InvalidData("single file: " + std::to_string(size) +
                                    " bytes is shorter than the 16-byte header");
  if (std::memcmp(data, kSingleFileMagic, 8) != 0)
    return InvalidData("single file: bad magic (not a casual3d .c3d file)");
  const uint16_t major = static_cast<uint16_t>(GetLE(data + 8, 2));
  const uint16_t minor = static_cast<uint16_t>(GetLE(data + 10, 2));
  if (major != kSingleFileVersionMajor && checks.on(ReaderCheck::kContainerUnknownMajor))
    return UnsupportedVersion("single file: version " + std::to_string(major) + "." +
                              std::to_string(minor) + " is not supported (this reader reads 1.x)");
  const uint32_t count = static_cast<uint32_t>(GetLE(data + 12, 4));
  if (count == 0) return InvalidData("single file: no entries");
  if (count > kMaxSingleFileEntries)
    return LimitExceeded("single file: " + std::to_string(count) + " entries exceed the limit of " +
                         std::to_string(kMaxSingleFileEntries));
  // Each entry needs at least 19 bytes, which bounds the reservation below.
  if (static_cast<uint64_t>(count) * 19 > size - 16)
    return InvalidData("single file: directory of " + std::to_string(count) +
                       " entries is truncated");
  std::vector<SingleFileEntry> entries;
  entries.reserve(count);
  std::set<std::string> seen;
  size_t pos = 16;
  for (uint32_t i = 0; i < count; ++i) {
    const std::string where = "single file: entry " + std::to_string(i);
    if (size - pos < 2) return InvalidData(where + ": directory truncated");
    const size_t len = static_cast<size_t>(GetLE(data + pos, 2));
    pos += 2;
    if (size - pos < len + 16) return InvalidData(where + ": directory truncated");
    SingleFileEntry e;
    e.path.assign(reinterpret_cast<const char*>(data + pos), len);
    pos += len;
    e.offset = GetLE(data + pos, 8);
    e.size = GetLE(data + pos + 8, 8);
    pos += 16;
    if (!IsSafePackagePath(e.path) && checks.on(ReaderCheck::kPathEscape))
      return InvalidData(where + ": \"" + e.path.substr(0, 80) +
                         "\" is not a safe relative path inside the package");
    if (!seen.insert(e.path).second && checks.on(ReaderCheck::kDuplicateEntry))
      return InvalidData(where + ": duplicate path \"" + e.path + "\"");
    if ((e.offset > size || e.size > size - e.offset) && checks.on(ReaderCheck::kEntryOutsideFile))
      return InvalidData(where + " (\"" + e.path + "\"): data range lies outside the " +
                         std::to_string(size) + "-byte file");
    entries.push_back(std::move(e));
  }
  if (entries[0].path != kManifestFileName && checks.on(ReaderCheck::kManifestNotFirst))
    return InvalidData("single file: the first entry is \"" + entries[0].path +
                       "\", expected manifest.json");
  return entries;
}

}  // namespace casual3d
