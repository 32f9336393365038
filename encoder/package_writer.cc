#include "encoder/package_writer.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <system_error>
#include <utility>

#include "base/atomic_file.h"
#include "base/parallel_for.h"

#include "encoder/absent_fill.h"
#include "encoder/level_of_detail.h"
#include "encoder/lossy_normal_tile.h"
#include "encoder/tile_image_codec.h"
#include "format/sha256.h"
#include "format/single_file.h"
#include "format/tile_codec.h"

namespace casual3d::encoder {
namespace {

namespace fs = std::filesystem;

// Number of levels for `options.levels` == 0.
int AutomaticLevels(int width, int height) {
  int levels = 1;
  while (levels < kMaxLevels && (width >> (levels - 1)) > 512 &&
         ((width >> (levels - 1)) % 2) == 0 && ((height >> (levels - 1)) % 2) == 0)
    ++levels;
  return levels;
}

DepthQuantization DepthRange(const TwoLayerPanorama& pano) {
  DepthQuantization q;
  q.near_m = q.far_m = 1.0;  // An empty panorama.
  pano.NodeDepthRange(&q.near_m, &q.far_m);
  // One depth (or none): packages need far_m > near_m (spec/package.md Sec.
  // 4.2); every node then has code 1, which decodes to near_m exactly.
  if (!(q.far_m > q.near_m)) q.far_m = 2.0 * q.near_m;
  return q;
}

Status WriteBytes(const fs::path& path, const std::vector<uint8_t>& bytes) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return IoError(path.string() + ": cannot create the file");
  const size_t written = bytes.empty() ? 0 : std::fwrite(bytes.data(), 1, bytes.size(), f);
  const bool closed = std::fclose(f) == 0;
  if (written != bytes.size() || !closed)
    return IoError(path.string() + ": write failed (disk full?)");
  return Status::Ok();
}

// ReencodeColor copies tiles by path, so the earlier encoding must have the
// levels, tile grid, version and quantization this one has (different
// omit_level_width, levels or depth_bits would put tiles of another size or
// meaning under the same names).
Status CheckSameLayout(const PackageFiles& earlier, const Manifest& now) {
  if (earlier.empty() || earlier.front().first != kManifestFileName)
    return InvalidArgument("the earlier encoding has no manifest.json first");
  const std::vector<uint8_t>& bytes = earlier.front().second;
  StatusOr<Manifest> before =
      ParseManifest(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  if (!before.ok())
    return InvalidArgument("the earlier encoding's manifest: " + before.status().message());
  bool same = before->version_major == now.version_major && before->width == now.width &&
              before->height == now.height && before->tile_size == now.tile_size &&
              before->levels.size() == now.levels.size() &&
              before->depth.bits == now.depth.bits && before->normal.type == now.normal.type &&
              before->normal.bits == now.normal.bits;
  for (size_t l = 0; same && l < now.levels.size(); ++l)
    same = before->levels[l].width == now.levels[l].width &&
           before->levels[l].height == now.levels[l].height;
  if (!same)
    return InvalidArgument("the earlier encoding has other levels, tiles, version or "
                           "quantization than these options give; only the colour quality may "
                           "differ");
  return Status::Ok();
}

}  // namespace

Status PackageOptions::Check() const {
  if (tile_size < kMinTileSize || tile_size > kMaxTileSize)
    return InvalidArgument("tile_size " + std::to_string(tile_size) + " is outside [" +
                           std::to_string(kMinTileSize) + ", " + std::to_string(kMaxTileSize) +
                           "]");
  if (levels < 0 || levels > kMaxLevels)
    return InvalidArgument("levels " + std::to_string(levels) + " is outside [0, " +
                           std::to_string(kMaxLevels) + "] (0 = automatic)");
  if (omit_level_width < 0)
    return InvalidArgument("omit_level_width " + std::to_string(omit_level_width) +
                           " is negative (0 writes every level)");
  if (!(color_quality >= 0.0f && color_quality <= 100.0f))
    return InvalidArgument("color_quality " + std::to_string(color_quality) +
                           " is outside [0, 100]");
  if (color_method < 0 || color_method > 6)
    return InvalidArgument("color_method " + std::to_string(color_method) + " is outside [0, 6]");
  if (!(lossless_effort >= 0.0f && lossless_effort <= 100.0f))
    return InvalidArgument("lossless_effort " + std::to_string(lossless_effort) +
                           " is outside [0, 100]");
  if (lossless_method < 0 || lossless_method > 6)
    return InvalidArgument("lossless_method " + std::to_string(lossless_method) +
                           " is outside [0, 6]");
  DepthQuantization depth;
  depth.bits = depth_bits;
  CASUAL3D_RETURN_IF_ERROR(depth.Check());
  NormalQuantization normal;
  normal.bits = normal_bits;
  CASUAL3D_RETURN_IF_ERROR(normal.Check());
  for (const auto& [name, value] : {std::make_pair("normal_mean_error_deg", normal_mean_error_deg),
                                    std::make_pair("normal_p99_error_deg", normal_p99_error_deg)}) {
    if (!(value >= 1.0 && value <= 90.0))
      return InvalidArgument(std::string(name) + " " + std::to_string(value) +
                             " is outside [1, 90]");
  }
  if (num_threads < 0 || num_threads > 256)
    return InvalidArgument("num_threads " + std::to_string(num_threads) +
                           " is outside [0, 256] (0 = all cores)");
  return Status::Ok();
}

PackageOptions DeliveryPackageOptions() {
  PackageOptions options;
  options.normal_bits = 5;
  options.depth_bits = 9;
  options.lossless_method = 4;
  options.lossless_effort = 75.0f;
  options.fill_absent = true;
  options.compact_manifest = true;
  options.omit_level_width = 2048;
  return options;
}

namespace {

// EncodePackage; with `earlier`, the tiles other than colour are copied from
// it (ReencodeColor).
StatusOr<PackageFiles> Encode(const TwoLayerPanorama& pano, const PackageOptions& options,
                              const PackageFiles* earlier, PackageStats* stats) {
  CASUAL3D_RETURN_IF_ERROR(options.Check());
  if (pano.width() > kMaxPackageWidth || pano.height() > kMaxPackageHeight)
    return InvalidArgument("panorama " + std::to_string(pano.width()) + "x" +
                           std::to_string(pano.height()) + " exceeds the package limit of " +
                           std::to_string(kMaxPackageWidth) + "x" +
                           std::to_string(kMaxPackageHeight));
  Status valid = pano.Validate();
  if (!valid.ok()) return InvalidArgument("the panorama is invalid: " + valid.message());
  const int num_levels =
      options.levels > 0 ? options.levels : AutomaticLevels(pano.width(), pano.height());
  const int divisor = 1 << (num_levels - 1);
  if (pano.width() % divisor != 0 || pano.height() % divisor != 0)
    return InvalidArgument(std::to_string(num_levels) + " levels need width and height divisible "
                           "by " + std::to_string(divisor) + ", but the panorama is " +
                           std::to_string(pano.width()) + "x" + std::to_string(pano.height()) +
                           "; use fewer levels");

  // Coarser levels by repeated halving; the one omit_level_width names is
  // computed for those below it but not stored, unless it is the last.
  std::vector<TwoLayerPanorama> coarse;
  std::vector<const TwoLayerPanorama*> level_pano = {&pano};
  coarse.reserve(num_levels);
  for (int l = 1; l < num_levels; ++l) {
    CASUAL3D_ASSIGN_OR_RETURN(TwoLayerPanorama half,
                              HalvePanorama(coarse.empty() ? pano : coarse.back()));
    coarse.push_back(std::move(half));
    const int w = coarse.back().width();
    if (l + 1 == num_levels || !(w > options.omit_level_width / 2 && w <= options.omit_level_width))
      level_pano.push_back(&coarse.back());
  }
  const int stored_levels = static_cast<int>(level_pano.size());

  Manifest manifest;
  manifest.generator = options.generator;
  manifest.width = pano.width();
  manifest.height = pano.height();
  manifest.frame = pano.frame();
  // The lowest minor version whose members the manifest uses.
  manifest.view = pano.view_hints();
  if (stored_levels < num_levels) {
    manifest.version_major = 2;  // A level left out: 2.0 has every 1.x member.
    manifest.version_minor = 0;
  } else {
    manifest.version_minor = options.lossy_normals ? 2 : manifest.view ? 1 : 0;
  }
  manifest.tile_size = options.tile_size;
  manifest.depth = DepthRange(pano);
  manifest.depth.bits = options.depth_bits;
  if (options.lossy_normals) {
    manifest.normal.type = NormalEncoding::kOctahedralLossy;
    manifest.normal.bits = 8;
    manifest.normal.mean_error_deg = options.normal_mean_error_deg;
    manifest.normal.p99_error_deg = options.normal_p99_error_deg;
  } else {
    manifest.normal.bits = options.normal_bits;
  }
  CASUAL3D_ASSIGN_OR_RETURN(const TileImageFormat* image_format, TileImageFormatOf(manifest));
  CASUAL3D_ASSIGN_OR_RETURN(const TileImageCodec* codec, TileImageCodecFor(*image_format));

  struct Job {
    int level, tile;
    TileImageKind kind;
    std::string path;
    std::vector<uint8_t> bytes;
  };
  std::vector<Job> jobs;
  for (int l = 0; l < stored_levels; ++l) {
    LevelEntry L;
    L.width = level_pano[l]->width();
    L.height = level_pano[l]->height();
    L.columns = (L.width + options.tile_size - 1) / options.tile_size;
    L.rows = (L.height + options.tile_size - 1) / options.tile_size;
    if (L.columns * L.rows > kMaxTilesPerLevel)
      return InvalidArgument("tile_size " + std::to_string(options.tile_size) + " gives " +
                             std::to_string(L.columns * L.rows) + " tiles at level " +
                             std::to_string(l) + ", more than " +
                             std::to_string(kMaxTilesPerLevel) + "; use larger tiles");
    L.tiles.resize(static_cast<size_t>(L.columns) * L.rows);
    for (int t = 0; t < L.columns * L.rows; ++t) {
      for (int k = 0; k < kNumTileImageKinds; ++k) {
        const TileImageKind kind = static_cast<TileImageKind>(k);
        const std::string path =
            TileFileName(l, t / L.columns, t % L.columns, kind, *image_format);
        L.tiles[t].files[k] = path;
        jobs.push_back({l, t, kind, path, {}});
      }
    }
    manifest.levels.push_back(std::move(L));
  }

  // The earlier encoding's tiles by path.
  std::map<std::string, const std::vector<uint8_t>*> earlier_tiles;
  if (earlier != nullptr) {
    CASUAL3D_RETURN_IF_ERROR(CheckSameLayout(*earlier, manifest));
    for (const auto& [path, bytes] : *earlier) earlier_tiles[path] = &bytes;
  }

  // Tiles are encoded in parallel; after a failure no further tile starts,
  // and the first failing tile in job order is reported.
  std::vector<Status> job_status(jobs.size());
  std::atomic<bool> failed{false};
  base::ParallelFor(0, static_cast<int64_t>(jobs.size()), base::ResolveThreads(options.num_threads),
                    [&](int64_t j) {
    if (failed.load()) return;
    Job& job = jobs[j];
    if (earlier != nullptr && job.kind != TileImageKind::kColor) {
      const auto it = earlier_tiles.find(job.path);
      if (it == earlier_tiles.end()) {
        job_status[j] = InternalError(job.path + ": not among the earlier encoding's files");
        failed.store(true);
        return;
      }
      job.bytes = *it->second;
      return;
    }
    int x, y, w, h;
    manifest.TileRect(job.level, job.tile, &x, &y, &w, &h);
    Image8 image =
        EncodeTileImage(*level_pano[job.level], x, y, w, h, job.kind, manifest.quantization());
    if (options.fill_absent &&
        (job.kind == TileImageKind::kDepth || job.kind == TileImageKind::kNormal))
      FillAbsentCodes(*level_pano[job.level], x, y, w, h, &image);
    TileEncodeSettings lossless;
    lossless.lossless = true;
    lossless.quality = options.lossless_effort;
    lossless.method = options.lossless_method;
    TileEncodeSettings color;
    color.quality = options.color_quality;
    color.method = options.color_method;
    // Lossy normals choose their own quality per tile, the colour's method.
    StatusOr<std::vector<uint8_t>> bytes =
        job.kind == TileImageKind::kNormal && manifest.normal.lossy()
            ? EncodeLossyNormalTile(*level_pano[job.level], x, y, w, h, image, manifest.normal,
                                    *codec, options.color_method, lossless)
            : codec->Encode(static_cast<const Image8&>(image).view(),
                            TileImageIsLossless(job.kind, manifest.normal.type) ? lossless : color);
    if (!bytes.ok()) {
      job_status[j] = Status(bytes.status().code(), job.path + ": " + bytes.status().message());
      failed.store(true);
      return;
    }
    job.bytes = std::move(*bytes);
  });
  for (const Status& s : job_status) CASUAL3D_RETURN_IF_ERROR(s);

  std::sort(jobs.begin(), jobs.end(), [](const Job& a, const Job& b) { return a.path < b.path; });
  PackageFiles files;
  files.reserve(jobs.size() + 1);
  files.emplace_back(kManifestFileName, std::vector<uint8_t>());
  PackageStats s;
  s.level_bytes.assign(stored_levels, 0);
  for (Job& job : jobs) {
    manifest.files.push_back(
        {job.path, job.bytes.size(), Sha256Hex(job.bytes.data(), job.bytes.size())});
    s.level_bytes[job.level] += job.bytes.size();
    s.total_bytes += job.bytes.size();
    files.emplace_back(job.path, std::move(job.bytes));
  }
  Status manifest_ok = manifest.Validate();
  if (!manifest_ok.ok()) return InternalError("encoder built an invalid manifest: " +
                                              manifest_ok.message());
  const std::string text = SerializeManifest(manifest, options.compact_manifest);
  files[0].second.assign(text.begin(), text.end());
  s.manifest_bytes = text.size();
  s.total_bytes += text.size();
  s.num_files = static_cast<int>(files.size());
  if (stats != nullptr) *stats = std::move(s);
  return files;
}

}  // namespace

StatusOr<PackageFiles> EncodePackage(const TwoLayerPanorama& pano, const PackageOptions& options,
                                     PackageStats* stats) {
  return Encode(pano, options, nullptr, stats);
}

StatusOr<PackageFiles> ReencodeColor(const TwoLayerPanorama& pano, const PackageOptions& options,
                                     const PackageFiles& earlier, PackageStats* stats) {
  return Encode(pano, options, &earlier, stats);
}

Status WritePackageFolder(const PackageFiles& files, const std::string& dir) {
  if (dir.empty()) return InvalidArgument("the output folder name is empty");
  std::error_code ec;
  const fs::path target = fs::path(dir).lexically_normal();
  const fs::path clean = target.filename().empty() ? target.parent_path() : target;
  if (fs::exists(clean, ec)) {
    if (!fs::is_directory(clean, ec))
      return InvalidArgument(dir + ": exists and is not a folder; choose another output name");
    const bool is_package = fs::exists(clean / kManifestFileName, ec);
    if (!is_package && !fs::is_empty(clean, ec))
      return InvalidArgument(dir + ": exists and is not a casual3d package (no manifest.json); "
                                   "refusing to replace it, choose another output folder");
  }
  const fs::path tmp = base::TemporaryPathFor(clean.string());
  fs::create_directories(tmp, ec);
  if (ec) return IoError(tmp.string() + ": cannot create the folder: " + ec.message());
  auto cleanup = [&] {
    std::error_code ignored;
    fs::remove_all(tmp, ignored);
  };
  for (const auto& [path, bytes] : files) {
    if (!IsSafePackagePath(path)) {
      cleanup();
      return InternalError("unsafe package path \"" + path + "\"");
    }
    const fs::path file = tmp / path;
    fs::create_directories(file.parent_path(), ec);
    Status s = ec ? IoError(file.parent_path().string() + ": " + ec.message())
                  : WriteBytes(file, bytes);
    if (!s.ok()) {
      cleanup();
      return s;
    }
  }
  const Status swapped = base::ReplaceFolder(tmp.string(), clean.string());
  if (!swapped.ok()) cleanup();
  return swapped;
}

Status WritePackageSingleFile(const PackageFiles& files, const std::string& path) {
  CASUAL3D_ASSIGN_OR_RETURN(std::vector<uint8_t> container, BuildSingleFile(files));
  return base::WriteFileAtomic(path, container);
}

}  // namespace casual3d::encoder
