// Reading: packages (folder or .c3d) level by level, master files, and the
// complete check of `casual3d validate`.

#include <pybind11/pybind11.h>

#include <algorithm>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "encoder/master_file.h"
#include "encoder/tile_image_codec.h"
#include "format/file_source.h"
#include "format/manifest.h"
#include "format/package_reader.h"
#include "python/src/bindings.h"
#include "python/src/errors.h"
#include "python/src/panorama_arrays.h"

namespace casual3d::python {
namespace py = pybind11;
namespace {

// 0: all hardware threads; otherwise clamped to ReadOptions' 1..256.
int ReadThreads(int threads) {
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return std::min(threads, 256);
}

// An opened package: its files and its manifest, read level by level.
class NativePackage {
 public:
  explicit NativePackage(std::string path) : path_(std::move(path)) {
    StatusOr<std::unique_ptr<FileSource>> source = Status();
    StatusOr<std::vector<uint8_t>> manifest = Status();
    {
      py::gil_scoped_release release;
      source = OpenPackage(path_);
      if (source.ok()) manifest = (*source)->Read(kManifestFileName, kMaxManifestBytes);
    }
    ThrowIfError(source.status(), path_);
    ThrowIfError(manifest.status(), path_);
    manifest_json_.assign(manifest->begin(), manifest->end());
    StatusOr<Manifest> parsed = ParseManifest(manifest_json_);
    ThrowIfError(parsed.status(), path_);  // Its messages name manifest.json.
    num_levels_ = static_cast<int>(parsed->levels.size());
    source_ = std::move(source).value();
  }

  const std::string& path() const { return path_; }
  const std::string& manifest_json() const { return manifest_json_; }
  int num_levels() const { return num_levels_; }

  py::dict ReadLevel(int level, int threads, bool verify_checksums) const {
    if (level < 0 || level >= num_levels_) {
      throw py::index_error(path_ + ": level " + std::to_string(level) + " does not exist (" +
                            std::to_string(num_levels_) + " levels)");
    }
    ReadOptions options;
    options.level = level;
    options.num_threads = ReadThreads(threads);
    options.verify_checksums = verify_checksums;
    options.max_pixels = int64_t{kMaxPackageWidth} * kMaxPackageHeight;
    StatusOr<TwoLayerPanorama> pano = Status();
    {
      py::gil_scoped_release release;
      pano = ReadPackage(*source_, encoder::TileImageDecoders(), options);
    }
    ThrowIfError(pano.status(), path_ + ": level " + std::to_string(level));
    return PanoramaToPython(std::move(pano).value());
  }

 private:
  std::string path_;
  std::string manifest_json_;
  int num_levels_ = 0;
  std::unique_ptr<FileSource> source_;
};

py::dict ReadMaster(const std::string& path) {
  StatusOr<TwoLayerPanorama> pano = Status();
  {
    py::gil_scoped_release release;
    pano = encoder::ReadMasterFile(path);
  }
  ThrowIfError(pano.status(), path);
  return PanoramaToPython(std::move(pano).value());
}

// What `casual3d validate` checks (cli/validate_command.cc), with its
// messages: the package opens, its manifest parses (a problem of it named as
// manifest.json's, not a level's), then every level reads with every file's size
// and SHA-256 verified, every tile decoded and the panorama validated.
py::list Validate(const std::string& path, int threads) {
  StatusOr<std::unique_ptr<FileSource>> source = Status();
  {
    py::gil_scoped_release release;
    source = OpenPackage(path);
  }
  if (!source.ok()) throw FormatError(source.status().message());
  StatusOr<Manifest> parsed = Status();
  {
    py::gil_scoped_release release;
    parsed = ReadManifest(**source);
  }
  if (!parsed.ok()) throw FormatError(path + ": " + parsed.status().message());
  const Manifest& manifest = *parsed;
  ReadOptions options;
  options.num_threads = ReadThreads(threads);
  options.max_pixels = int64_t{kMaxPackageWidth} * kMaxPackageHeight;
  py::list levels;
  for (int level = 0; level < static_cast<int>(manifest.levels.size()); ++level) {
    options.level = level;
    StatusOr<TwoLayerPanorama> pano = Status();
    {
      py::gil_scoped_release release;
      pano = ReadPackage(**source, encoder::TileImageDecoders(), options);
    }
    if (!pano.ok()) {
      throw FormatError(path + ": level " + std::to_string(level) + ": " + pano.status().message());
    }
    py::dict summary;
    summary["level"] = level;
    summary["width"] = pano->width();
    summary["height"] = pano->height();
    for (int l = 0; l < kNumLayers; ++l) {
      const auto& present = pano->layer(l).present;
      summary[l == kFront ? "front_nodes" : "back_nodes"] =
          std::count(present.begin(), present.end(), uint8_t{1});
    }
    summary["files"] = static_cast<int>(manifest.levels[level].tiles.size()) * kNumTileImageKinds;
    levels.append(summary);
  }
  return levels;
}

}  // namespace

void RegisterReading(py::module_& m) {
  py::class_<NativePackage>(m, "_Package", "An opened package (see casual3d.Package).")
      .def(py::init<std::string>(), py::arg("path"))
      .def_property_readonly("path", &NativePackage::path)
      .def_property_readonly("manifest_json",
                             [](const NativePackage& p) { return py::bytes(p.manifest_json()); })
      .def_property_readonly("num_levels", &NativePackage::num_levels)
      .def("read_level", &NativePackage::ReadLevel, py::arg("level"), py::arg("threads"),
           py::arg("verify_checksums"));
  m.def("_read_master", &ReadMaster, py::arg("path"));
  m.def("_validate", &Validate, py::arg("path"), py::arg("threads"));
}

}  // namespace casual3d::python
