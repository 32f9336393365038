// Speed of the data model and mesh construction on a 4096 x 2048 procedural
// room (spec/mesh.md): validation, the full mesh, the simplified mesh at
// the default budget, and the viewer's backdrop (format/backdrop.h). Run: build/bench/format_mesh_bench
// (--benchmark_filter=... to pick one).

#include <benchmark/benchmark.h>

#include "format/backdrop.h"
#include "format/mesh_builder.h"
#include "format/mesh_simplify.h"
#include "format/testing/test_panoramas.h"

namespace casual3d {
namespace {

const TwoLayerPanorama& Room(int width) {
  static TwoLayerPanorama small = testing::MakeRoomPanorama(1024, 512);
  static TwoLayerPanorama large = testing::MakeRoomPanorama(4096, 2048);
  return width == 1024 ? small : large;
}

void BM_Validate(benchmark::State& state) {
  const TwoLayerPanorama& pano = Room(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    Status s = pano.Validate();
    if (!s.ok()) state.SkipWithError(s.ToString().c_str());
    benchmark::DoNotOptimize(s);
  }
}
BENCHMARK(BM_Validate)->Arg(4096)->Unit(benchmark::kMillisecond);

void BM_BuildMesh(benchmark::State& state) {
  const TwoLayerPanorama& pano = Room(static_cast<int>(state.range(0)));
  MeshBuildOptions options;
  options.validate_input = state.range(1) != 0;
  size_t triangles = 0, vertices = 0;
  for (auto _ : state) {
    auto mesh = BuildMesh(pano, options);
    if (!mesh.ok()) state.SkipWithError(mesh.status().ToString().c_str());
    triangles = mesh->num_triangles();
    vertices = mesh->num_vertices();
  }
  state.counters["triangles"] = static_cast<double>(triangles);
  state.counters["vertices"] = static_cast<double>(vertices);
}
BENCHMARK(BM_BuildMesh)
    ->Args({1024, 0})
    ->Args({4096, 0})
    ->Args({4096, 1})
    ->ArgNames({"width", "validate"})
    ->Unit(benchmark::kMillisecond);

void BM_BuildSimplifiedMesh(benchmark::State& state) {
  const TwoLayerPanorama& pano = Room(static_cast<int>(state.range(0)));
  MeshSimplifyOptions options;
  options.max_triangles = state.range(1);
  options.validate_input = false;
  SimplifiedMesh result;
  for (auto _ : state) {
    auto s = BuildSimplifiedMesh(pano, options);
    if (!s.ok()) state.SkipWithError(s.status().ToString().c_str());
    result = std::move(*s);
  }
  state.counters["triangles"] = static_cast<double>(result.mesh.num_triangles());
  state.counters["full_triangles"] = static_cast<double>(result.full_triangles);
  state.counters["error_bound"] = result.error_bound;
}
BENCHMARK(BM_BuildSimplifiedMesh)
    ->Args({1024, 100000})
    ->Args({4096, 0})
    ->Args({4096, 500000})
    ->ArgNames({"width", "budget"})
    ->Unit(benchmark::kMillisecond);

void BM_BuildBackdrop(benchmark::State& state) {
  const TwoLayerPanorama& pano = Room(static_cast<int>(state.range(0)));
  size_t triangles = 0;
  for (auto _ : state) {
    auto mesh = BuildBackdrop(pano);
    if (!mesh.ok()) state.SkipWithError(mesh.status().ToString().c_str());
    triangles = mesh->num_triangles();
  }
  state.counters["triangles"] = static_cast<double>(triangles);
}
BENCHMARK(BM_BuildBackdrop)->Arg(1024)->Arg(4096)->ArgName("width")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace casual3d

BENCHMARK_MAIN();
