// `casual3d validate <package>`: checks a package (folder or .c3d) completely:
// the manifest, every tile file's size, SHA-256 and image coding (lossless for
// depth, normal and graph; format/tile_image_format.h), every tile image decodes, and every level's
// panorama passes TwoLayerPanorama::Validate(). Prints one line
// per level; on the first problem, throws with one clear line (exit code 1).

#include <chrono>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "base/parallel_for.h"
#include "cli/command.h"
#include "encoder/tile_image_codec.h"
#include "format/file_source.h"
#include "format/package_reader.h"

namespace casual3d::cli {
namespace {

void RunValidate(const std::string& path, int threads) {
  StatusOr<std::unique_ptr<FileSource>> source = OpenPackage(path);
  if (!source.ok()) throw std::runtime_error(source.status().message());
  ReadOptions options;
  options.num_threads = base::ResolveThreads(threads);
  options.max_pixels = int64_t{kMaxPackageWidth} * kMaxPackageHeight;
  // The manifest first, so that its problems are not reported as level 0's.
  StatusOr<Manifest> parsed = ReadManifest(**source);
  if (!parsed.ok()) throw std::runtime_error(path + ": " + parsed.status().message());
  const Manifest& manifest = *parsed;
  for (int level = 0; level < static_cast<int>(manifest.levels.size()); ++level) {
    options.level = level;
    const auto start = std::chrono::steady_clock::now();
    StatusOr<TwoLayerPanorama> pano = ReadPackage(**source, encoder::TileImageDecoders(), options);
    if (!pano.ok())
      throw std::runtime_error(path + ": level " + std::to_string(level) + ": " +
                               pano.status().message());
    size_t nodes[2] = {0, 0};
    for (int l = 0; l < kNumLayers; ++l)
      for (uint8_t p : pano->layer(l).present) nodes[l] += p;
    std::printf("level %d: %dx%d ok, %zu front and %zu back nodes, %d files verified (%.0f ms)\n",
                level, pano->width(), pano->height(), nodes[0], nodes[1],
                static_cast<int>(manifest.levels[level].tiles.size()) * kNumTileImageKinds,
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                    .count());
  }
  // Entries no tile uses are for files of a later minor version: readers
  // ignore them, present or not (spec/package.md Sec. 3).
  size_t tile_files = 0;
  for (const LevelEntry& L : manifest.levels) tile_files += L.tiles.size() * kNumTileImageKinds;
  if (manifest.files.size() > tile_files)
    std::printf("%zu files entries no tile uses (ignored, not verified)\n",
                manifest.files.size() - tile_files);
  std::printf("%s: valid casual3d %d.%d package\n", path.c_str(), manifest.version_major,
              manifest.version_minor);
}

}  // namespace

void AddValidateCommand(CLI::App& app) {
  auto path = std::make_shared<std::string>();
  auto threads = std::make_shared<int>(0);
  CLI::App* cmd = app.add_subcommand(
      "validate", "Check every file, checksum, tile and level of a package (folder or .c3d)");
  cmd->add_option("package", *path, "Package folder or .c3d file")->required();
  cmd->add_option("--threads", *threads, "Decoding threads; 0 = all cores");
  cmd->callback([path, threads] { RunValidate(*path, *threads); });
}

}  // namespace casual3d::cli
