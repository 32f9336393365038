// Timings of the synthetic capture generator (reconstruct/synth): one photo of
// the default partial rig (1152x864, adaptive anti-aliasing) and the
// ground-truth two-surface panorama at 2048x1024 and 4096x2048.

#include <benchmark/benchmark.h>

#include "reconstruct/synth/default_scene.h"
#include "reconstruct/synth/ground_truth_panorama.h"
#include "reconstruct/synth/render_photo.h"
#include "reconstruct/synth/rig.h"

namespace casual3d::synth {
namespace {

void BM_RenderPhoto(benchmark::State& state) {
  const Scene scene = BuildDefaultScene(1);
  const Rig rig = MakeRig(RigOptions::Defaults(RigKind::kPartial), DefaultRigCentre());
  RenderOptions options;
  options.num_threads = static_cast<int>(state.range(0));
  int edges = 0;
  for (auto _ : state) {
    const PhotoRender r = RenderPhoto(scene, rig.camera, rig.poses[5], options);
    edges = r.edge_pixels;
    benchmark::DoNotOptimize(r.radiance.data());
  }
  state.counters["edge_pixels"] = edges;
  state.counters["pixels_per_s"] =
      benchmark::Counter(1152.0 * 864.0, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_RenderPhoto)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_GroundTruthPanorama(benchmark::State& state) {
  const Scene scene = BuildDefaultScene(1);
  PanoramaFrame frame;
  frame.centre[1] = DefaultRigCentre().y();
  const int width = static_cast<int>(state.range(0));
  for (auto _ : state) {
    const GroundTruthPanorama gt = RenderGroundTruthPanorama(scene, frame, width, width / 2, 0);
    benchmark::DoNotOptimize(gt.pixels.data());
  }
}
BENCHMARK(BM_GroundTruthPanorama)->Arg(2048)->Arg(4096)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace casual3d::synth

BENCHMARK_MAIN();
