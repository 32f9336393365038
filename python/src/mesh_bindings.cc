// Meshes: the full mesh of spec/mesh.md or the simplified one, as numpy
// arrays, and the colour atlas their uvs address.

#include <pybind11/pybind11.h>

#include <algorithm>
#include <optional>

#include "format/color_atlas.h"
#include "format/mesh_builder.h"
#include "format/mesh_simplify.h"
#include "python/src/bindings.h"
#include "python/src/errors.h"
#include "python/src/mesh_options.h"
#include "python/src/panorama_arrays.h"

namespace casual3d::python {
namespace py = pybind11;

StatusOr<Mesh> BuildAnyMesh(const TwoLayerPanorama& pano, const MeshChoice& choice,
                            SimplifiedMesh* facts) {
  // The whole panorama is always accepted: the limits only bound memory for
  // untrusted packages, and this one is already in memory.
  const int64_t pixels = static_cast<int64_t>(pano.width()) * pano.height();
  if (!choice.simplify) {
    MeshBuildOptions options;
    options.include_back_layer = choice.include_back_layer;
    options.num_threads = choice.num_threads;
    options.max_pixels = std::min(std::max(options.max_pixels, pixels), kMeshPixelLimit);
    return BuildMesh(pano, options);
  }
  MeshSimplifyOptions options;
  options.max_triangles = choice.max_triangles;
  options.max_relative_error = choice.max_relative_error;
  options.include_back_layer = choice.include_back_layer;
  options.num_threads = choice.num_threads;
  options.max_pixels = std::min(std::max(options.max_pixels, pixels), kMeshPixelLimit);
  StatusOr<SimplifiedMesh> simplified = BuildSimplifiedMesh(pano, options);
  if (!simplified.ok()) return simplified.status();
  *facts = std::move(simplified).value();
  return std::move(facts->mesh);
}

namespace {

py::dict MeshToPython(Mesh&& mesh, const SimplifiedMesh& facts, bool simplified) {
  const py::ssize_t vertices = static_cast<py::ssize_t>(mesh.num_vertices());
  const py::ssize_t triangles = static_cast<py::ssize_t>(mesh.num_triangles());
  py::dict out;
  out["positions"] = ToNumpy(std::move(mesh.positions), {vertices, 3});
  out["normals"] = ToNumpy(std::move(mesh.normals), {vertices, 3});
  out["uvs"] = ToNumpy(std::move(mesh.uvs), {vertices, 2});
  out["colors"] = ToNumpy(std::move(mesh.colors), {vertices, 3});
  out["indices"] = ToNumpy(std::move(mesh.indices), {triangles, 3});
  if (simplified) {
    out["error_bound"] = facts.error_bound;
    out["full_triangles"] = facts.full_triangles;
    out["merged_blocks"] = facts.merged_blocks;
    out["budget_met"] = facts.budget_met;
  }
  return out;
}

py::array AtlasToPython(Image8&& atlas) {
  const py::ssize_t w = atlas.width(), h = atlas.height();
  return ToNumpy(std::move(atlas.vector()), {h, w, 3});
}

py::dict BuildMeshFromPython(py::handle pano_object, const MeshChoice& choice) {
  const TwoLayerPanorama pano = PanoramaFromPython(pano_object);
  SimplifiedMesh facts;
  StatusOr<Mesh> mesh = Status();
  Image8 atlas;
  {
    py::gil_scoped_release release;
    mesh = BuildAnyMesh(pano, choice, &facts);
    if (mesh.ok()) atlas = BuildColorAtlas(pano, 3);
  }
  ThrowIfError(mesh.status());
  py::dict out = MeshToPython(std::move(mesh).value(), facts, choice.simplify);
  out["atlas"] = AtlasToPython(std::move(atlas));
  return out;
}

py::array ColorAtlasFromPython(py::handle pano_object) {
  const TwoLayerPanorama pano = PanoramaFromPython(pano_object);
  Image8 atlas;
  {
    py::gil_scoped_release release;
    atlas = BuildColorAtlas(pano, 3);
  }
  return AtlasToPython(std::move(atlas));
}

}  // namespace

void RegisterMeshes(py::module_& m) {
  py::class_<MeshChoice>(m, "_MeshChoice")
      .def(py::init<>())
      .def_readwrite("simplify", &MeshChoice::simplify)
      .def_readwrite("max_triangles", &MeshChoice::max_triangles)
      .def_readwrite("max_relative_error", &MeshChoice::max_relative_error)
      .def_readwrite("include_back_layer", &MeshChoice::include_back_layer)
      .def_readwrite("num_threads", &MeshChoice::num_threads);
  m.def("_build_mesh", &BuildMeshFromPython, py::arg("panorama"), py::arg("choice"));
  m.def("_color_atlas", &ColorAtlasFromPython, py::arg("panorama"));
}

}  // namespace casual3d::python
