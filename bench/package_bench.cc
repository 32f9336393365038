// Web package benchmark (docs/PERFORMANCE.md): encode a two-layer panorama at
// default settings, decode it natively, and report sizes and fidelity against
// the master as counters.
//
// Input: the master file named by $CASUAL3D_BENCH_MASTER (for example the
// ground truth of `casual3d synth --rig sphere --panorama-width 4096`), else a
// procedural 4096x2048 panorama.
//
//   build/bench/package_bench --benchmark_counters_tabular=true

#include <benchmark/benchmark.h>

#include <sys/resource.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <thread>

#include "encoder/master_file.h"
#include "encoder/package_writer.h"
#include "encoder/webp_codec.h"
#include "format/file_source.h"
#include "format/package_reader.h"
#include "format/package_test_scene.h"

namespace casual3d {
namespace {

const TwoLayerPanorama& Master() {
  static const TwoLayerPanorama pano = [] {
    if (const char* path = std::getenv("CASUAL3D_BENCH_MASTER")) {
      StatusOr<TwoLayerPanorama> read = encoder::ReadMasterFile(path);
      if (!read.ok()) {
        std::fprintf(stderr, "package_bench: %s\n", read.status().ToString().c_str());
        std::exit(1);
      }
      return std::move(*read);
    }
    return testing::MakePackageTestPanorama(4096, 2048);
  }();
  return pano;
}

const encoder::PackageFiles& Package() {
  static const encoder::PackageFiles files = *encoder::EncodePackage(Master(), {});
  return files;
}

// CPU seconds of the whole process (all threads), user + system.
double ProcessCpuSeconds() {
  rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
         1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

MemoryFileSource Source() {
  MemoryFileSource source;
  for (const auto& [path, bytes] : Package()) source.Add(path, bytes);
  return source;
}

void BM_Encode(benchmark::State& state) {
  const TwoLayerPanorama& pano = Master();
  encoder::PackageStats stats;
  const double cpu_start = ProcessCpuSeconds();
  for (auto _ : state) {
    StatusOr<encoder::PackageFiles> files = encoder::EncodePackage(pano, {}, &stats);
    if (!files.ok()) state.SkipWithError(files.status().ToString().c_str());
    benchmark::DoNotOptimize(files);
  }
  state.counters["all_threads_cpu_s"] =
      (ProcessCpuSeconds() - cpu_start) / static_cast<double>(state.iterations());
  state.counters["total_KB"] = stats.total_bytes / 1024.0;
  state.counters["level0_KB"] = stats.level_bytes.front() / 1024.0;
  state.counters["coarsest_KB"] = (stats.level_bytes.back() + stats.manifest_bytes) / 1024.0;
  state.counters["levels"] = static_cast<double>(stats.level_bytes.size());
}

void BM_Decode(benchmark::State& state) {
  const MemoryFileSource source = Source();
  encoder::WebpImageDecoder decoder;
  ReadOptions options;
  options.num_threads = std::max(1u, std::thread::hardware_concurrency());
  Manifest manifest;
  ReadPackage(source, decoder, options, &manifest);
  options.level = state.range(0) < 0 ? static_cast<int>(manifest.levels.size()) - 1
                                     : static_cast<int>(state.range(0));
  TwoLayerPanorama decoded;
  const double cpu_start = ProcessCpuSeconds();
  for (auto _ : state) {
    StatusOr<TwoLayerPanorama> pano = ReadPackage(source, decoder, options);
    if (!pano.ok()) {
      state.SkipWithError(pano.status().ToString().c_str());
      return;
    }
    decoded = std::move(*pano);
  }
  state.counters["all_threads_cpu_s"] =
      (ProcessCpuSeconds() - cpu_start) / static_cast<double>(state.iterations());
  state.counters["pixels"] = static_cast<double>(decoded.width()) * decoded.height();
  if (options.level != 0) return;
  // Fidelity of the full-resolution level against the master.
  const TwoLayerPanorama& master = Master();
  double se = 0, worst_depth = 0, worst_normal_deg = 0;
  size_t samples = 0, graph_mismatch = 0;
  for (int l = 0; l < kNumLayers; ++l) {
    const LayerData& M = master.layer(l);
    const LayerData& D = decoded.layer(l);
    for (size_t i = 0; i < M.present.size(); ++i) {
      if (M.present[i] != D.present[i] || M.links[i] != D.links[i] || M.label[i] != D.label[i])
        ++graph_mismatch;
      if (!M.present[i]) continue;
      for (int c = 0; c < 3; ++c) {
        const double d = double(M.rgb[3 * i + c]) - D.rgb[3 * i + c];
        se += d * d;
        ++samples;
      }
      worst_depth = std::max(worst_depth, std::fabs(double(D.depth_m[i]) / M.depth_m[i] - 1));
      double dot = 0;
      for (int c = 0; c < 3; ++c) dot += double(M.normal[3 * i + c]) * D.normal[3 * i + c];
      if (dot != 0) worst_normal_deg = std::max(worst_normal_deg, std::acos(std::fmin(1.0, dot)) * 180 / M_PI);
    }
  }
  state.counters["color_PSNR_dB"] = 10 * std::log10(255.0 * 255.0 / (se / samples));
  state.counters["depth_max_rel_err_pct"] = 100 * worst_depth;
  state.counters["normal_max_err_deg"] = worst_normal_deg;
  state.counters["graph_mismatches"] = static_cast<double>(graph_mismatch);
}

BENCHMARK(BM_Encode)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
BENCHMARK(BM_Decode)->Arg(0)->Arg(-1)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

}  // namespace
}  // namespace casual3d

BENCHMARK_MAIN();
