// Writing: a package folder or .c3d file (encoder/package_writer.h), a
// master file (encoder/master_file.h) and a binary glTF (encoder/gltf_export.h).

#include <pybind11/pybind11.h>

#include <string>

#include "encoder/gltf_export.h"
#include "encoder/master_file.h"
#include "encoder/package_fit.h"
#include "encoder/package_writer.h"
#include "format/color_atlas.h"
#include "python/src/bindings.h"
#include "python/src/errors.h"
#include "python/src/mesh_options.h"
#include "python/src/panorama_arrays.h"

namespace casual3d::python {
namespace py = pybind11;
namespace {

// Returns the sizes written.
// `fit`: a byte budget (encoder/package_fit.h; max_bytes 0 = none).
py::dict WritePackage(py::handle pano_object, const std::string& path, bool single_file,
                      const encoder::PackageOptions& options, uint64_t max_bytes, float min_color_quality) {
  const TwoLayerPanorama pano = PanoramaFromPython(pano_object);
  encoder::PackageStats stats;
  encoder::PackageOptions used = options;
  Status status;
  {
    py::gil_scoped_release release;
    encoder::PackageFitOptions fit;
    fit.max_bytes = max_bytes;
    fit.min_color_quality = min_color_quality;
    status = options.Check();
    if (status.ok()) status = pano.Validate();
    if (status.ok()) {
      StatusOr<encoder::PackageFit> fitted = encoder::EncodePackageWithin(pano, options, fit);
      if (fitted.ok()) {
        stats = fitted->stats;
        used = fitted->options;
      }
      status = !fitted.ok() ? fitted.status()
               : single_file ? encoder::WritePackageSingleFile(fitted->files, path)
                             : encoder::WritePackageFolder(fitted->files, path);
    }
  }
  ThrowIfError(status, path);
  py::dict out;
  out["color_quality"] = used.color_quality;
  out["lossy_normals"] = used.lossy_normals;
  out["total_bytes"] = stats.total_bytes;
  py::list level_bytes;
  for (uint64_t bytes : stats.level_bytes) level_bytes.append(bytes);
  out["level_bytes"] = level_bytes;
  out["manifest_bytes"] = stats.manifest_bytes;
  out["num_files"] = stats.num_files;
  return out;
}

void WriteMaster(py::handle pano_object, const std::string& path) {
  const TwoLayerPanorama pano = PanoramaFromPython(pano_object);
  Status status;
  {
    py::gil_scoped_release release;
    status = encoder::WriteMasterFile(pano, path);
  }
  ThrowIfError(status, path);
}

py::dict ExportGlb(py::handle pano_object, const std::string& path, const MeshChoice& choice,
                   const encoder::GltfExportOptions& options) {
  const TwoLayerPanorama pano = PanoramaFromPython(pano_object);
  encoder::GltfExportStats stats;
  Status status;
  {
    py::gil_scoped_release release;
    status = options.Check();
    SimplifiedMesh facts;
    StatusOr<Mesh> mesh = status.ok() ? BuildAnyMesh(pano, choice, &facts) : status;
    if (!mesh.ok()) {
      status = mesh.status();
    } else if (mesh->num_triangles() == 0) {
      status = InvalidData("the 3D photo has no triangles to export");
    } else {
      status = encoder::ExportGlb(*mesh, BuildColorAtlas(pano, 3), options, path, &stats);
    }
  }
  ThrowIfError(status, path);
  py::dict out;
  out["num_vertices"] = stats.num_vertices;
  out["num_triangles"] = stats.num_triangles;
  out["texture_width"] = stats.texture_width;
  out["texture_height"] = stats.texture_height;
  out["texture_bytes"] = stats.texture_bytes;
  out["draco_position_bits"] = stats.draco_position_bits;
  out["mesh_bytes"] = stats.mesh_bytes;
  out["file_bytes"] = stats.file_bytes;
  return out;
}

}  // namespace

void RegisterWriting(py::module_& m) {
  using encoder::GltfExportOptions;
  using encoder::PackageOptions;
  // Fields as documented in encoder/package_writer.h and encoder/gltf_export.h.
  py::class_<PackageOptions>(m, "_PackageOptions")
      .def(py::init<>())
      .def_readwrite("tile_size", &PackageOptions::tile_size)
      .def_readwrite("levels", &PackageOptions::levels)
      .def_readwrite("omit_level_width", &PackageOptions::omit_level_width)
      .def_readwrite("color_quality", &PackageOptions::color_quality)
      .def_readwrite("color_method", &PackageOptions::color_method)
      .def_readwrite("lossless_effort", &PackageOptions::lossless_effort)
      .def_readwrite("lossless_method", &PackageOptions::lossless_method)
      .def_readwrite("depth_bits", &PackageOptions::depth_bits)
      .def_readwrite("normal_bits", &PackageOptions::normal_bits)
      .def_readwrite("lossy_normals", &PackageOptions::lossy_normals)
      .def_readwrite("normal_mean_error_deg", &PackageOptions::normal_mean_error_deg)
      .def_readwrite("normal_p99_error_deg", &PackageOptions::normal_p99_error_deg)
      .def_readwrite("threads", &PackageOptions::num_threads)
      .def_readwrite("generator", &PackageOptions::generator);
  py::enum_<encoder::TextureFormat>(m, "_TextureFormat")
      .value("png", encoder::TextureFormat::kPng)
      .value("jpeg", encoder::TextureFormat::kJpeg);
  py::class_<GltfExportOptions>(m, "_GltfExportOptions")
      .def(py::init<>())
      .def_readwrite("texture_format", &GltfExportOptions::texture_format)
      .def_readwrite("jpeg_quality", &GltfExportOptions::jpeg_quality)
      .def_readwrite("max_texture_size", &GltfExportOptions::max_texture_size)
      .def_readwrite("normals", &GltfExportOptions::normals)
      .def_readwrite("unlit", &GltfExportOptions::unlit)
      .def_readwrite("double_sided", &GltfExportOptions::double_sided)
      .def_readwrite("draco", &GltfExportOptions::draco)
      .def_readwrite("draco_position_bits", &GltfExportOptions::draco_position_bits)
      .def_readwrite("draco_normal_bits", &GltfExportOptions::draco_normal_bits)
      .def_readwrite("draco_texcoord_bits", &GltfExportOptions::draco_texcoord_bits)
      .def_readwrite("draco_compression_level", &GltfExportOptions::draco_compression_level);
  m.def("_write_package", &WritePackage, py::arg("panorama"), py::arg("path"),
        py::arg("single_file"), py::arg("options"), py::arg("max_bytes") = 0,
        py::arg("min_color_quality") = 75.0f);
  m.def("_write_master", &WriteMaster, py::arg("panorama"), py::arg("path"));
  m.def("_export_glb", &ExportGlb, py::arg("panorama"), py::arg("path"), py::arg("choice"),
        py::arg("options"));
}

}  // namespace casual3d::python
