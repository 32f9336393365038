#include "format/package_reader.h"

#include <algorithm>
#include <atomic>
#include <mutex>
#include <thread>

#include "format/sha256.h"

namespace casual3d {

PackageReader::PackageReader(Manifest manifest, const ReaderChecks& checks)
    : manifest_(std::move(manifest)),
      checks_(checks),
      image_format_(&WebpTileImageFormat()),
      file_kinds_(manifest_.files.size(), -1),
      tile_decoder_(std::make_shared<TileDecoder>(manifest_.quantization(), checks)) {
  for (const LevelEntry& L : manifest_.levels)
    for (const TileEntry& t : L.tiles)
      for (int k = 0; k < kNumTileImageKinds; ++k)
        if (const FileEntry* f = manifest_.FindFile(t.files[k]))
          file_kinds_[f - manifest_.files.data()] = static_cast<int8_t>(k);
  // A manifest of another major gets here only with the unknown-major check
  // off: its tiles are read as those of 1.x.
  if (StatusOr<const TileImageFormat*> format = TileImageFormatOf(manifest_); format.ok())
    image_format_ = *format;
}

StatusOr<PackageReader> PackageReader::Create(std::string_view manifest_bytes,
                                              const ReaderChecks& checks) {
  CASUAL3D_ASSIGN_OR_RETURN(Manifest manifest, ParseManifest(manifest_bytes, checks));
  return PackageReader(std::move(manifest), checks);
}

std::vector<std::string> PackageReader::FilesForLevel(int level) const {
  std::vector<std::string> paths;
  if (level < 0 || level >= num_levels()) return paths;
  for (const TileEntry& t : manifest_.levels[level].tiles)
    for (const std::string& p : t.files) paths.push_back(p);
  return paths;
}

Status PackageReader::VerifyFile(const std::string& path, const uint8_t* data,
                                 size_t size) const {
  const FileEntry* f = manifest_.FindFile(path);
  if (f == nullptr) return NotFound(path + ": not listed in the manifest");
  if (size != f->bytes && checks_.on(ReaderCheck::kSizeMismatch))
    return InvalidData(path + ": " + std::to_string(size) + " bytes, the manifest says " +
                       std::to_string(f->bytes) + " (truncated or replaced file)");
  if (checks_.on(ReaderCheck::kChecksumMismatch) && Sha256Hex(data, size) != f->sha256)
    return InvalidData(path + ": SHA-256 does not match the manifest (corrupt file)");
  const int kind = file_kinds_[f - manifest_.files.data()];
  if (kind >= 0 &&
      TileImageIsLossless(static_cast<TileImageKind>(kind), manifest_.normal.type) &&
      checks_.on(ReaderCheck::kLossyDataTile)) {
    CASUAL3D_RETURN_IF_ERROR(image_format_->check_lossless(
        path, TileImageKindName(static_cast<TileImageKind>(kind)), data, size));
  }
  return Status::Ok();
}

const std::string& PackageReader::TileFileAt(int x, int y, TileImageKind kind) const {
  const LevelEntry& L = manifest_.levels[level_];
  const int tile = y / manifest_.tile_size * L.columns + x / manifest_.tile_size;
  return L.tiles[tile].files[static_cast<int>(kind)];
}

Status PackageReader::BeginLevel(int level, int64_t max_pixels) {
  if (level < 0 || level >= num_levels())
    return InvalidArgument("level " + std::to_string(level) + " does not exist (the package has " +
                           std::to_string(num_levels()) + " levels, 0 = full resolution)");
  const LevelEntry& L = manifest_.levels[level];
  if (static_cast<int64_t>(L.width) * L.height > max_pixels)
    return LimitExceeded("level " + std::to_string(level) + " is " + std::to_string(L.width) +
                         "x" + std::to_string(L.height) + ", more than the limit of " +
                         std::to_string(max_pixels) + " pixels");
  level_ = level;
  // The level's tiles cover it and FinishLevel requires every image of every
  // tile, whose decoding writes every field of every node.
  pano_ = TwoLayerPanorama::Unfilled(L.width, L.height);
  pano_.frame() = manifest_.frame;
  pano_.view_hints() = manifest_.view;
  received_.assign(L.tiles.size() * kNumTileImageKinds, 0);
  return Status::Ok();
}

Status PackageReader::AddTileImage(int tile, TileImageKind kind, ImageView<const uint8_t> pixels,
                                   int num_threads) {
  if (level_ < 0) return InvalidArgument("AddTileImage before BeginLevel");
  const LevelEntry& L = manifest_.levels[level_];
  const int k = static_cast<int>(kind);
  if (tile < 0 || static_cast<size_t>(tile) >= L.tiles.size() || k < 0 || k >= kNumTileImageKinds)
    return InvalidArgument("tile " + std::to_string(tile) + " or image kind " + std::to_string(k) +
                           " is out of range");
  int x, y, w, h;
  manifest_.TileRect(level_, tile, &x, &y, &w, &h);
  Status s = DecodeTileImage(pixels, kind, x, y, w, h, *tile_decoder_, &pano_, num_threads);
  if (!s.ok()) return Status(s.code(), L.tiles[tile].files[k] + ": " + s.message());
  received_[static_cast<size_t>(tile) * kNumTileImageKinds + k] = 1;
  return Status::Ok();
}

Status PackageReader::AddTileFile(int tile, TileImageKind kind, const uint8_t* data, size_t size,
                                  const ImageDecoder& decoder) {
  StatusOr<Image8> image = decoder.Decode(data, size);
  if (!image.ok()) {
    std::string path = "tile " + std::to_string(tile);
    if (level_ >= 0 && tile >= 0 && static_cast<size_t>(tile) < manifest_.levels[level_].tiles.size())
      path = manifest_.levels[level_].tiles[tile].files[static_cast<int>(kind) & 3];
    return Status(image.status().code(), path + ": " + image.status().message());
  }
  const Image8& decoded = *image;
  return AddTileImage(tile, kind, decoded.view());
}

StatusOr<TwoLayerPanorama> PackageReader::FinishLevel(int num_threads) {
  if (level_ < 0) return InvalidArgument("FinishLevel before BeginLevel");
  const LevelEntry& L = manifest_.levels[level_];
  for (size_t i = 0; i < received_.size(); ++i) {
    if (!received_[i])
      return InvalidArgument(L.tiles[i / kNumTileImageKinds].files[i % kNumTileImageKinds] +
                             ": not added; the level needs every image of every tile");
  }
  DecodedNodeProblem problem;
  Status nodes = FinishDecodedPanorama(&pano_, num_threads, checks_, &problem);
  if (!nodes.ok())
    return Status(nodes.code(), TileFileAt(problem.x, problem.y, problem.kind) + ": " +
                                    nodes.message());
  if (tile_decoder_->quantization().right_down_links) {
    Status completed = CompleteLinks(&pano_, checks_, &problem);
    if (!completed.ok())
      return Status(completed.code(), TileFileAt(problem.x, problem.y, problem.kind) + ": " +
                                          completed.message());
  }
  // FinishDecodedPanorama leaves only valid node values, so the links are
  // what remains to check. A link is stored in the graph image of its node's
  // tile; one to a node of another tile also names that tile's graph image.
  if (checks_.on(ReaderCheck::kLinkNotMutual)) {
    NodeProblem where;
    Status valid = pano_.ValidateLinks(num_threads, &where);
    if (!valid.ok() && where.link) {
      const std::string& file = TileFileAt(where.x, where.y, TileImageKind::kGraph);
      std::string message = file + ": " + valid.message();
      if (where.target_x >= 0) {
        const std::string& target =
            TileFileAt(where.target_x, where.target_y, TileImageKind::kGraph);
        if (target != file) message += " (the node it points at is in " + target + ")";
      }
      return Status(valid.code(), std::move(message));
    }
    if (!valid.ok()) return valid;
  }
  level_ = -1;
  received_.clear();
  return std::move(pano_);
}

Status ReadOptions::Check() const {
  if (level < 0 || level >= kMaxLevels)
    return InvalidArgument("level " + std::to_string(level) + " is outside [0, " +
                           std::to_string(kMaxLevels - 1) + "]");
  if (num_threads < 1 || num_threads > 256)
    return InvalidArgument("num_threads " + std::to_string(num_threads) + " is outside [1, 256]");
  if (max_pixels < 1) return InvalidArgument("max_pixels must be positive");
  return Status::Ok();
}

StatusOr<Manifest> ReadManifest(const FileSource& source, const ReaderChecks& checks) {
  CASUAL3D_ASSIGN_OR_RETURN(std::vector<uint8_t> bytes,
                            source.Read(kManifestFileName, kMaxManifestBytes));
  return ParseManifest(
      std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), checks);
}

namespace {

// One decoder whatever the format.
class SingleDecoder : public ImageDecoderFactory {
 public:
  explicit SingleDecoder(const ImageDecoder& decoder) : decoder_(decoder) {}
  StatusOr<const ImageDecoder*> DecoderFor(const TileImageFormat&) const override {
    return &decoder_;
  }

 private:
  const ImageDecoder& decoder_;
};

}  // namespace

StatusOr<TwoLayerPanorama> ReadPackage(const FileSource& source, const ImageDecoder& decoder,
                                       const ReadOptions& options, Manifest* manifest_out) {
  return ReadPackage(source, SingleDecoder(decoder), options, manifest_out);
}

StatusOr<TwoLayerPanorama> ReadPackage(const FileSource& source,
                                       const ImageDecoderFactory& decoders,
                                       const ReadOptions& options, Manifest* manifest_out) {
  CASUAL3D_RETURN_IF_ERROR(options.Check());
  ReaderChecks checks = options.checks;
  if (!options.verify_checksums) checks.Disable(ReaderCheck::kChecksumMismatch);
  CASUAL3D_ASSIGN_OR_RETURN(Manifest manifest, ReadManifest(source, checks));
  PackageReader reader(std::move(manifest), checks);
  if (manifest_out != nullptr) *manifest_out = reader.manifest();
  CASUAL3D_ASSIGN_OR_RETURN(const ImageDecoder* decoder, decoders.DecoderFor(reader.image_format()));
  CASUAL3D_RETURN_IF_ERROR(reader.BeginLevel(options.level, options.max_pixels));
  const size_t num_tiles = reader.manifest().levels[options.level].tiles.size();
  const size_t num_jobs = num_tiles * kNumTileImageKinds;

  std::atomic<size_t> next{0};
  std::atomic<bool> failed{false};
  std::mutex error_mutex;
  Status first_error;
  auto work = [&] {
    while (!failed.load()) {
      const size_t job = next.fetch_add(1);
      if (job >= num_jobs) return;
      const int tile = static_cast<int>(job / kNumTileImageKinds);
      const TileImageKind kind = static_cast<TileImageKind>(job % kNumTileImageKinds);
      const std::string& path =
          reader.manifest().levels[options.level].tiles[tile].files[static_cast<int>(kind)];
      const FileEntry* entry = reader.manifest().FindFile(path);
      Status s;
      StatusOr<std::vector<uint8_t>> bytes = source.Read(path, entry->bytes);
      if (!bytes.ok()) {
        s = bytes.status();
      } else {
        s = reader.VerifyFile(path, bytes->data(), bytes->size());
        if (s.ok()) s = reader.AddTileFile(tile, kind, bytes->data(), bytes->size(), *decoder);
      }
      if (!s.ok()) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!failed.exchange(true)) first_error = s;
        return;
      }
    }
  };
  const int threads = static_cast<int>(
      std::min<size_t>(static_cast<size_t>(options.num_threads), num_jobs));
  if (threads <= 1) {
    work();
  } else {
    std::vector<std::thread> pool;
    for (int i = 0; i < threads; ++i) pool.emplace_back(work);
    for (std::thread& t : pool) t.join();
  }
  if (failed.load()) return first_error;
  return reader.FinishLevel();
}

}  // namespace casual3d
