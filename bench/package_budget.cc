// Delivery budget of a web package (docs/PERFORMANCE.md, "Package size"):
// encodes a master file with the reference settings (PackageOptions' defaults:
// 12-bit depth, 8-bit normals) and with candidate settings (by default
// DeliveryPackageOptions()), decodes both through the package reader
// and prints the bytes by level and tile image kind, and what the candidate
// changes: normals' angle to the reference package's (mean, 99th percentile,
// largest) and to the master's (largest: the declared bound), depth's relative
// error to the master (99th percentile, largest). Optionally writes a
// side-by-side Lambert shading of the front layer's normals (reference |
// candidate), the effect the viewer's lights have.
//
// Also prints the candidate as a row of docs/PERFORMANCE.md's table, and can
// write the candidate package as a folder (for `casual3d evaluate`).
// --against OTHER.exr encodes the reference package from another master of
// the same capture (today's, when the panorama stage changes), so that the
// errors are those of the new master and its encoding together, over the
// nodes both have.
//
//   build/bench/package_budget MASTER.exr [--normal-bits B] [--depth-bits B]
//       [--lossless-effort F] [--lossless-method M] [--tile-size T]
//       [--color-quality Q] [--color-method M] [--no-fill-absent]
//       [--omit-level-width W] [--reference-only] [--shading out.png]
//       [--write-package DIR] [--against OTHER.exr]

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "encoder/master_file.h"
#include "encoder/package_writer.h"
#include "encoder/tile_image_codec.h"
#include "format/file_source.h"
#include "format/package_reader.h"
#include "reconstruct/io/image_io.h"

namespace casual3d {
namespace {

struct Encoded {
  encoder::PackageFiles files;
  encoder::PackageStats stats;
  double seconds = 0;
  std::vector<TwoLayerPanorama> levels;  // Decoded, finest first.
};

Encoded EncodeAndDecode(const TwoLayerPanorama& master, const encoder::PackageOptions& options) {
  Encoded e;
  const auto start = std::chrono::steady_clock::now();
  StatusOr<encoder::PackageFiles> files = encoder::EncodePackage(master, options, &e.stats);
  e.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!files.ok()) {
    std::fprintf(stderr, "package_budget: %s\n", files.status().ToString().c_str());
    std::exit(1);
  }
  e.files = std::move(*files);
  MemoryFileSource source;
  for (const auto& [path, bytes] : e.files) source.Add(path, bytes);
  ReadOptions read;
  read.num_threads = std::max(1u, std::thread::hardware_concurrency());
  for (size_t l = 0; l < e.stats.level_bytes.size(); ++l) {
    read.level = static_cast<int>(l);
    StatusOr<TwoLayerPanorama> pano = ReadPackage(source, encoder::TileImageDecoders(), read);
    if (!pano.ok()) {
      std::fprintf(stderr, "package_budget: level %zu: %s\n", l, pano.status().ToString().c_str());
      std::exit(1);
    }
    e.levels.push_back(std::move(*pano));
  }
  return e;
}

// Bytes of the tile files of `level` whose name ends in ".<kind>.webp" (the
// names EncodePackage gives, TileFileName).
uint64_t KindBytes(const encoder::PackageFiles& files, int level, const char* kind) {
  const std::string prefix = "l" + std::to_string(level) + "/";
  const std::string suffix = std::string(".") + kind + WebpTileImageFormat().extension;
  uint64_t sum = 0;
  for (const auto& [path, bytes] : files)
    if (path.compare(0, prefix.size(), prefix) == 0 && path.size() > suffix.size() &&
        path.compare(path.size() - suffix.size(), suffix.size(), suffix) == 0)
      sum += bytes.size();
  return sum;
}

void PrintSizes(const char* name, const Encoded& e) {
  std::printf("%s: %.0f KB in all (manifest %.1f KB), encoded in %.1f s\n", name,
              e.stats.total_bytes / 1024.0, e.stats.manifest_bytes / 1024.0, e.seconds);
  std::printf("  level | color KB | depth KB | normal KB | graph KB | level KB\n");
  for (size_t l = 0; l < e.stats.level_bytes.size(); ++l) {
    std::printf("  %5zu", l);
    for (const char* kind : {"color", "depth", "normal", "graph"})
      std::printf(" | %8.0f", KindBytes(e.files, static_cast<int>(l), kind) / 1024.0);
    std::printf(" | %8.0f\n", e.stats.level_bytes[l] / 1024.0);
  }
}

// The row of docs/PERFORMANCE.md, "Package size of reconstructions": level 0
// by kind, level 0, the other levels, the whole package (KB).
void PrintTableRow(const Encoded& e) {
  std::printf("table row: | ");
  const char* sep = "";
  for (const char* kind : {"color", "depth", "normal", "graph"}) {
    std::printf("%s%.0f", sep, KindBytes(e.files, 0, kind) / 1024.0);
    sep = " / ";
  }
  std::printf(" | %.0f | ", e.stats.level_bytes[0] / 1024.0);
  sep = "";
  for (size_t l = 1; l < e.stats.level_bytes.size(); ++l) {
    std::printf("%s%.0f", sep, e.stats.level_bytes[l] / 1024.0);
    sep = " / ";
  }
  std::printf(" | **%.0f** |\n", e.stats.total_bytes / 1024.0);
}

double Percentile(std::vector<float>* values, double p) {
  if (values->empty()) return 0;
  const size_t k = std::min(values->size() - 1, static_cast<size_t>(p * values->size()));
  std::nth_element(values->begin(), values->begin() + k, values->end());
  return (*values)[k];
}

double AngleDeg(const float* a, const float* b) {
  const double dot = double(a[0]) * b[0] + double(a[1]) * b[1] + double(a[2]) * b[2];
  return std::acos(std::clamp(dot, -1.0, 1.0)) * 180.0 / M_PI;
}

// Errors of level `level` of the candidate against the reference package and
// the master's values (the master's level 0 only). `other_master`: the
// reference comes from another master (--against), whose node at a pixel may
// be another surface or missing; only nodes present in both within 2% of
// each other's depth are compared, and the count of the others is printed.
void PrintErrors(int level, const TwoLayerPanorama& reference, const TwoLayerPanorama& candidate,
                 const TwoLayerPanorama* master, bool other_master) {
  std::vector<float> normal_deg, depth_rel;
  double normal_sum = 0, normal_to_master = 0;
  int64_t compared = 0, skipped = 0;
  for (int l = 0; l < kNumLayers; ++l) {
    const LayerData& R = reference.layer(l);
    const LayerData& C = candidate.layer(l);
    for (size_t i = 0; i < R.present.size(); ++i) {
      if (!R.present[i]) continue;
      if (other_master &&
          (!C.present[i] || std::fabs(C.depth_m[i] / R.depth_m[i] - 1.0f) > 0.02f)) {
        ++skipped;
        continue;
      }
      ++compared;
      const float* nr = &R.normal[3 * i];
      if (nr[0] != 0 || nr[1] != 0 || nr[2] != 0) {
        normal_deg.push_back(static_cast<float>(AngleDeg(nr, &C.normal[3 * i])));
        normal_sum += normal_deg.back();
        if (master != nullptr)
          normal_to_master = std::max(
              normal_to_master, AngleDeg(&master->layer(l).normal[3 * i], &C.normal[3 * i]));
      }
      const float truth = master != nullptr ? master->layer(l).depth_m[i] : R.depth_m[i];
      depth_rel.push_back(std::fabs(C.depth_m[i] / truth - 1.0f));
    }
  }
  const double mean = normal_deg.empty() ? 0 : normal_sum / normal_deg.size();
  const double normal_max = normal_deg.empty() ? 0 : *std::max_element(normal_deg.begin(), normal_deg.end());
  const double depth_max = depth_rel.empty() ? 0 : *std::max_element(depth_rel.begin(), depth_rel.end());
  std::printf("  level %d normals vs reference: mean %.2f, p99 %.2f, max %.2f deg", level, mean,
              Percentile(&normal_deg, 0.99), normal_max);
  if (master != nullptr) std::printf("; vs master: max %.2f deg", normal_to_master);
  std::printf("; depth vs %s: p99 %.4f%%, max %.4f%%", master != nullptr ? "master" : "reference",
              100 * Percentile(&depth_rel, 0.99), 100 * depth_max);
  if (other_master)
    std::printf(" (%lld nodes of both, %lld of the reference's left out: absent from or another surface in the candidate)",
                static_cast<long long>(compared), static_cast<long long>(skipped));
  std::printf("\n");
}

// Lambert shading (ambient 0.25, one light from the upper left in front of
// the viewer) of the front layer's normals in the 90 x 45 degree window
// around the forward direction, grey levels.
void Shade(const TwoLayerPanorama& pano, int x0, Image8* out) {
  const int w = pano.width() / 4, h = pano.height() / 4, y0 = pano.height() * 3 / 8;
  const double light[3] = {-0.48, 0.48, 0.73};  // Unit vector; +Z points back at the viewer.
  const LayerData& F = pano.layer(kFront);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = pano.index(pano.width() * 3 / 8 + x, y0 + y);
      const float* n = &F.normal[3 * i];
      const double lit = std::max(0.0, n[0] * light[0] + n[1] * light[1] + n[2] * light[2]);
      const double shade = F.present[i] ? 0.25 + 0.75 * lit : 0.0;
      out->at(x0 + x, y) = static_cast<uint8_t>(std::lround(255 * std::min(1.0, shade)));
    }
}

int Main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: package_budget MASTER.exr [--normal-bits B] [--depth-bits B] "
                         "[--lossless-effort F] [--lossless-method M] [--tile-size T] "
                         "[--color-quality Q] [--color-method M] [--no-fill-absent] "
                         "[--lossy-normals | --lossless-normals] [--normal-mean-error DEG] "
                         "[--normal-p99-error DEG] [--omit-level-width W] "
                         "[--reference-only] [--shading out.png] [--write-package DIR] "
                         "[--against OTHER.exr]\n");
    return 2;
  }
  encoder::PackageOptions candidate = encoder::DeliveryPackageOptions();
  std::string shading, package_dir, against;
  bool reference_only = false;
  for (int a = 2; a < argc; ++a) {
    const std::string arg = argv[a];
    const bool has_value = a + 1 < argc;
    if (arg == "--reference-only") reference_only = true;
    else if (arg == "--normal-bits" && has_value) candidate.normal_bits = std::atoi(argv[++a]);
    else if (arg == "--depth-bits" && has_value) candidate.depth_bits = std::atoi(argv[++a]);
    else if (arg == "--lossless-effort" && has_value) candidate.lossless_effort = static_cast<float>(std::atof(argv[++a]));
    else if (arg == "--lossless-method" && has_value) candidate.lossless_method = std::atoi(argv[++a]);
    else if (arg == "--tile-size" && has_value) candidate.tile_size = std::atoi(argv[++a]);
    else if (arg == "--color-quality" && has_value) candidate.color_quality = static_cast<float>(std::atof(argv[++a]));
    else if (arg == "--color-method" && has_value) candidate.color_method = std::atoi(argv[++a]);
    else if (arg == "--no-fill-absent") candidate.fill_absent = false;
    else if (arg == "--lossless-normals") candidate.lossy_normals = false;
    else if (arg == "--lossy-normals") candidate.lossy_normals = true;
    else if (arg == "--normal-mean-error" && has_value) candidate.normal_mean_error_deg = std::atof(argv[++a]);
    else if (arg == "--normal-p99-error" && has_value) candidate.normal_p99_error_deg = std::atof(argv[++a]);
    else if (arg == "--omit-level-width" && has_value) candidate.omit_level_width = std::atoi(argv[++a]);
    else if (arg == "--shading" && has_value) shading = argv[++a];
    else if (arg == "--write-package" && has_value) package_dir = argv[++a];
    else if (arg == "--against" && has_value) against = argv[++a];
    else {
      std::fprintf(stderr, "package_budget: unknown or incomplete option %s\n", arg.c_str());
      return 2;
    }
  }
  if (Status s = candidate.Check(); !s.ok()) {
    std::fprintf(stderr, "package_budget: %s\n", s.message().c_str());
    return 2;
  }
  StatusOr<TwoLayerPanorama> master = encoder::ReadMasterFile(argv[1]);
  if (!master.ok()) {
    std::fprintf(stderr, "package_budget: %s\n", master.status().ToString().c_str());
    return 1;
  }
  StatusOr<TwoLayerPanorama> other =
      against.empty() ? StatusOr<TwoLayerPanorama>(TwoLayerPanorama()) : encoder::ReadMasterFile(against);
  if (!other.ok()) {
    std::fprintf(stderr, "package_budget: --against: %s\n", other.status().ToString().c_str());
    return 1;
  }
  if (!against.empty() && (other->width() != master->width() || other->height() != master->height())) {
    std::fprintf(stderr, "package_budget: --against %s: %dx%d, but the master is %dx%d (give a master of the same size)\n",
                 against.c_str(), other->width(), other->height(), master->width(), master->height());
    return 2;
  }
  const Encoded reference =
      EncodeAndDecode(against.empty() ? *master : *other, encoder::PackageOptions());
  if (reference_only) {
    PrintSizes("reference", reference);
    return 0;
  }
  PrintSizes("reference", reference);
  const Encoded encoded = EncodeAndDecode(*master, candidate);
  std::printf("candidate: normals %s, depth bits %d, lossless effort %g method %d, "
              "tile size %d, colour quality %g method %d, absent nodes %s\n",
              candidate.lossy_normals
                  ? ("lossy within " + std::to_string(candidate.normal_mean_error_deg) + " / " +
                     std::to_string(candidate.normal_p99_error_deg) + " deg").c_str()
                  : (std::to_string(candidate.normal_bits) + " bits").c_str(),
              candidate.depth_bits, candidate.lossless_effort,
              candidate.lossless_method, candidate.tile_size, candidate.color_quality,
              candidate.color_method, candidate.fill_absent ? "filled" : "zero");
  PrintSizes("candidate", encoded);
  PrintTableRow(encoded);
  if (!package_dir.empty()) {
    if (Status s = encoder::WritePackageFolder(encoded.files, package_dir); !s.ok()) {
      std::fprintf(stderr, "package_budget: %s\n", s.ToString().c_str());
      return 1;
    }
    std::printf("wrote %s\n", package_dir.c_str());
  }
  // Each candidate level against the reference level of its size (the
  // candidate may leave out a level the reference, which keeps every one, has).
  for (size_t l = 0; l < encoded.levels.size(); ++l)
    for (const TwoLayerPanorama& same : reference.levels)
      if (same.width() == encoded.levels[l].width())
        PrintErrors(static_cast<int>(l), same, encoded.levels[l],
                    l == 0 && against.empty() ? &*master : nullptr, !against.empty());
  if (!shading.empty()) {
    const TwoLayerPanorama& a = reference.levels[0];
    Image8 image(2 * (a.width() / 4) + 8, a.height() / 4, 1, 255);
    Shade(a, 0, &image);
    Shade(encoded.levels[0], a.width() / 4 + 8, &image);
    io::WritePng(shading, image);
    std::printf("wrote %s (reference | candidate)\n", shading.c_str());
  }
  return 0;
}

}  // namespace
}  // namespace casual3d

int main(int argc, char** argv) { return casual3d::Main(argc, argv); }
