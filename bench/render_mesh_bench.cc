// Speed of the native software renderer (reconstruct/render/mesh_renderer.h)
// on the mesh of a procedural two-layer room panorama, rendered at the
// rephotography size of 1008 x 756 from the centre and from a parallax
// offset. Arguments: panorama width, threads.
// Run: build/bench/render_mesh_bench (--benchmark_filter=... to pick one).

#include <algorithm>
#include <map>

#include <benchmark/benchmark.h>

#include "format/mesh_builder.h"
#include "format/testing/test_panoramas.h"
#include "reconstruct/render/mesh_renderer.h"

namespace casual3d::render {
namespace {

struct Scene {
  Mesh mesh;
  Image8 atlas;
};

const Scene& RoomScene(int width) {
  static std::map<int, Scene> scenes;
  auto it = scenes.find(width);
  if (it != scenes.end()) return it->second;
  const TwoLayerPanorama pano = testing::MakeRoomPanorama(width, width / 2);
  Scene scene;
  scene.mesh = *BuildMesh(pano);
  scene.atlas = Image8(width, width, 3);
  for (int l = 0; l < kNumLayers; ++l) {
    const NodeArray<uint8_t>& rgb = pano.layer(l).rgb;
    std::copy(rgb.begin(), rgb.end(),
              scene.atlas.data() + static_cast<size_t>(l) * width * (width / 2) * 3);
  }
  return scenes.emplace(width, std::move(scene)).first->second;
}

void BM_RenderRoom(benchmark::State& state) {
  const Scene& scene = RoomScene(static_cast<int>(state.range(0)));
  GlCamera camera;
  camera.yaw_deg = 10.0;
  camera.pitch_deg = -5.0;
  camera.fov_y_deg = 60.0;
  camera.position[0] = 0.1;
  camera.position[2] = -0.1;
  const PinholeView view = ViewFromGlCamera(camera, 1008, 756);
  RenderOptions options;
  options.num_threads = static_cast<int>(state.range(1));
  int64_t covered = 0;
  for (auto _ : state) {
    const RenderResult result = RenderMesh(scene.mesh, scene.atlas.view(), view, options);
    covered = result.covered_pixels;
    benchmark::DoNotOptimize(result.color.data());
  }
  state.counters["triangles"] = static_cast<double>(scene.mesh.num_triangles());
  state.counters["covered"] = static_cast<double>(covered);
}
BENCHMARK(BM_RenderRoom)
    ->Args({1024, 1})
    ->Args({2048, 1})
    ->Args({2048, 2})
    ->Args({4096, 2})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace casual3d::render

BENCHMARK_MAIN();
