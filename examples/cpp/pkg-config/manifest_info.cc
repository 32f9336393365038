// Prints the manifest of a 3D photo package (a folder or a .c3d file): its
// size, levels of detail and files, after the checks every reader makes. Uses
// the format library alone (C++17 standard library only).
//
//   manifest_info <package>

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <casual3d/format/file_source.h>
#include <casual3d/format/manifest.h>
#include <casual3d/format/version.h>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s <package>  (casual3d %s)\n", argv[0], casual3d::kVersion);
    return 2;
  }
  const std::string path = argv[1];
  casual3d::StatusOr<std::unique_ptr<casual3d::FileSource>> source = casual3d::OpenPackage(path);
  if (!source.ok()) {
    std::fprintf(stderr, "manifest_info: %s\n", source.status().ToString().c_str());
    return 1;
  }
  casual3d::StatusOr<std::vector<uint8_t>> bytes =
      (*source)->Read(casual3d::kManifestFileName, casual3d::kMaxManifestBytes);
  if (!bytes.ok()) {
    std::fprintf(stderr, "manifest_info: %s: %s\n", path.c_str(), bytes.status().ToString().c_str());
    return 1;
  }
  casual3d::StatusOr<casual3d::Manifest> manifest = casual3d::ParseManifest(
      std::string_view(reinterpret_cast<const char*>(bytes->data()), bytes->size()));
  if (!manifest.ok()) {
    std::fprintf(stderr, "manifest_info: %s: %s\n", path.c_str(),
                 manifest.status().ToString().c_str());
    return 1;
  }
  std::printf("%s: %dx%d, package format %d.%d, %zu levels, %zu files\n", path.c_str(),
              manifest->width, manifest->height, manifest->version_major, manifest->version_minor,
              manifest->levels.size(), manifest->files.size());
  for (size_t l = 0; l < manifest->levels.size(); ++l) {
    const casual3d::LevelEntry& level = manifest->levels[l];
    std::printf("level %zu: %dx%d in %dx%d tiles, %llu bytes\n", l, level.width, level.height,
                level.columns, level.rows,
                static_cast<unsigned long long>(manifest->LevelBytes(static_cast<int>(l))));
  }
  return 0;
}
