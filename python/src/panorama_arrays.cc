#include "python/src/panorama_arrays.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "format/manifest.h"
#include "format/view_hints.h"
#include "python/src/errors.h"

namespace casual3d::python {
namespace py = pybind11;
namespace {

constexpr const char* kLayerNames[kNumLayers] = {"front", "back"};
constexpr float kAbsent = std::numeric_limits<float>::quiet_NaN();

py::dict LayerToPython(LayerData&& d, int width, int height) {
  const size_t n = static_cast<size_t>(width) * height;
  std::vector<float> depth(n), normals(3 * n);
  std::vector<uint8_t> links(4 * n);
  for (size_t i = 0; i < n; ++i) {
    const bool present = d.present[i] != 0;
    depth[i] = present ? d.depth_m[i] : kAbsent;
    for (int c = 0; c < 3; ++c) normals[3 * i + c] = present ? d.normal[3 * i + c] : kAbsent;
    for (int dir = 0; dir < kNumDirections; ++dir)
      links[4 * i + dir] = static_cast<uint8_t>(GetLink(d.links[i], static_cast<Direction>(dir)));
  }
  py::dict out;
  out["color"] = ToNumpy(std::move(d.rgb), {height, width, 3});
  out["depth"] = ToNumpy(std::move(depth), {height, width});
  out["normals"] = ToNumpy(std::move(normals), {height, width, 3});
  out["labels"] = ToNumpy(std::move(d.label), {height, width});
  out["links"] = ToNumpy(std::move(links), {height, width, 4});
  return out;
}

// The array `name` of `layer` as a C-contiguous array of T with `shape`.
template <typename T>
py::array_t<T, py::array::c_style> LayerArray(py::handle layer, const std::string& layer_name,
                                              const char* name,
                                              const std::vector<py::ssize_t>& shape) {
  const std::string what = layer_name + "." + name;
  py::object value = layer.attr(name);
  if (value.is_none()) throw std::invalid_argument(what + " is missing");
  auto array = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!array) throw std::invalid_argument(what + ": not convertible to a numpy array");
  bool same = array.ndim() == static_cast<py::ssize_t>(shape.size());
  for (size_t k = 0; same && k < shape.size(); ++k) same = array.shape(k) == shape[k];
  if (!same) {
    std::string want, got;
    for (py::ssize_t s : shape) want += (want.empty() ? "" : ", ") + std::to_string(s);
    for (py::ssize_t k = 0; k < array.ndim(); ++k)
      got += (k ? ", " : "") + std::to_string(array.shape(k));
    throw std::invalid_argument(what + ": shape (" + got + "), expected (" + want + ")");
  }
  return array;
}

void LayerFromPython(py::handle layer, const std::string& name, int width, int height,
                     LayerData* d) {
  const py::ssize_t h = height, w = width;
  const auto depth = LayerArray<float>(layer, name, "depth", {h, w});
  const auto color = LayerArray<uint8_t>(layer, name, "color", {h, w, 3});
  const auto normals = LayerArray<float>(layer, name, "normals", {h, w, 3});
  const auto labels = LayerArray<uint8_t>(layer, name, "labels", {h, w});
  const auto links = LayerArray<uint8_t>(layer, name, "links", {h, w, 4});
  const float* depth_p = depth.data();
  const float* normal_p = normals.data();
  const uint8_t* rgb_p = color.data();
  const uint8_t* label_p = labels.data();
  const uint8_t* link_p = links.data();
  // Absent nodes keep the zeros of TwoLayerPanorama(width, height).
  for (size_t i = 0; i < static_cast<size_t>(width) * height; ++i) {
    if (std::isnan(depth_p[i])) continue;
    d->present[i] = 1;
    d->depth_m[i] = depth_p[i];
    std::memcpy(&d->normal[3 * i], normal_p + 3 * i, 3 * sizeof(float));
    std::memcpy(&d->rgb[3 * i], rgb_p + 3 * i, 3);
    d->label[i] = label_p[i];
    uint8_t packed = 0;
    for (int dir = 0; dir < kNumDirections; ++dir) {
      const uint8_t l = link_p[4 * i + dir];
      if (l > 2) {
        throw std::invalid_argument(name + ".links: value " + std::to_string(l) + " at pixel (" +
                                    std::to_string(i % width) + ", " + std::to_string(i / width) +
                                    "), expected 0 (none), 1 (front) or 2 (back)");
      }
      packed = SetLink(packed, static_cast<Direction>(dir), static_cast<Link>(l));
    }
    d->links[i] = packed;
  }
}

}  // namespace

py::dict PanoramaToPython(TwoLayerPanorama&& pano) {
  const int w = pano.width(), h = pano.height();
  py::dict out;
  out["width"] = w;
  out["height"] = h;
  py::list layers;
  for (int l = 0; l < kNumLayers; ++l) layers.append(LayerToPython(std::move(pano.layer(l)), w, h));
  out["layers"] = layers;
  const PanoramaFrame& f = pano.frame();
  out["centre"] = ToNumpy(std::vector<double>(f.centre, f.centre + 3), {3});
  out["rotation"] = ToNumpy(std::vector<double>(f.rotation, f.rotation + 9), {3, 3});
  if (pano.view_hints()) {
    out["view_hints"] = SerializeViewHints(*pano.view_hints());
  } else {
    out["view_hints"] = py::none();
  }
  return out;
}

TwoLayerPanorama PanoramaFromPython(py::handle pano) {
  const auto front_depth = py::array::ensure(pano.attr("front").attr("depth"));
  if (!front_depth || front_depth.ndim() != 2 || front_depth.shape(0) < 1 ||
      front_depth.shape(1) < 1) {
    throw std::invalid_argument("front.depth: expected a 2-d array (height, width)");
  }
  const py::ssize_t height = front_depth.shape(0), width = front_depth.shape(1);
  if (width > kMaxPackageWidth || height > kMaxPackageHeight) {
    throw std::invalid_argument("front.depth: " + std::to_string(width) + "x" +
                                std::to_string(height) + " pixels, more than the " +
                                std::to_string(kMaxPackageWidth) + "x" +
                                std::to_string(kMaxPackageHeight) + " a 3D photo may have");
  }
  TwoLayerPanorama out(static_cast<int>(width), static_cast<int>(height));
  for (int l = 0; l < kNumLayers; ++l) {
    LayerFromPython(pano.attr(kLayerNames[l]), kLayerNames[l], out.width(), out.height(),
                    &out.layer(l));
  }
  const auto centre =
      py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(pano.attr("centre"));
  const auto rotation =
      py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(pano.attr("rotation"));
  if (!centre || centre.size() != 3) throw std::invalid_argument("centre: expected 3 numbers");
  if (!rotation || rotation.size() != 9)
    throw std::invalid_argument("rotation: expected 3x3 numbers");
  std::memcpy(out.frame().centre, centre.data(), 3 * sizeof(double));
  std::memcpy(out.frame().rotation, rotation.data(), 9 * sizeof(double));
  py::object hints = pano.attr("view_hints");
  if (!hints.is_none()) {
    const std::string text = py::str(py::module_::import("json").attr("dumps")(hints));
    StatusOr<ViewHints> parsed = ParseViewHints(text);
    ThrowIfError(parsed.status(), "view_hints");
    out.view_hints() = *parsed;
  }
  return out;
}

}  // namespace casual3d::python
