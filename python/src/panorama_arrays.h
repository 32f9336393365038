#pragma once

// Conversion between casual3d::TwoLayerPanorama and the numpy arrays of the
// Python Panorama (python/casual3d/__init__.py). Per layer, H x W pixels:
//   colour   uint8   (H, W, 3)  sRGB; 0 where the node is absent
//   depth    float32 (H, W)     metres from the frame centre; NaN where absent
//   normals  float32 (H, W, 3)  unit vectors, (0, 0, 0) for unlit nodes (sky);
//                               NaN where absent
//   labels   uint8   (H, W)     0 = F, 1 = B (format/two_layer.h NodeLabel)
//   links    uint8   (H, W, 4)  per direction right, down, left, up: 0 none,
//                               1 the neighbour's front node, 2 its back node
// A node exists exactly where its depth is not NaN.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <vector>

#include "format/two_layer.h"

namespace casual3d::python {

// Moves `values` into a numpy array of `shape` without copying them (the
// array owns them through a capsule). The product of `shape` must equal
// values.size().
template <typename Vector>
pybind11::array ToNumpy(Vector&& values, std::vector<pybind11::ssize_t> shape) {
  using T = typename std::decay_t<Vector>::value_type;
  auto* owned = new std::decay_t<Vector>(std::move(values));
  pybind11::capsule free(owned, [](void* p) { delete static_cast<std::decay_t<Vector>*>(p); });
  return pybind11::array_t<T>(std::move(shape), owned->data(), free);
}

// A dict {"width", "height", "layers": [front, back] (dicts of the arrays
// above), "centre": (3,) float64, "rotation": (3, 3) float64, "view_hints":
// the manifest's "view" object as JSON text, or None}. Consumes `pano`.
pybind11::dict PanoramaToPython(TwoLayerPanorama&& pano);

// Builds a panorama from a Python Panorama (attributes front, back, centre,
// rotation, view_hints as JSON text or None). Throws std::invalid_argument
// (ValueError) naming the array whose shape or type is wrong, and
// FormatError for view hints that do not parse. The result is not validated.
TwoLayerPanorama PanoramaFromPython(pybind11::handle pano);

}  // namespace casual3d::python
