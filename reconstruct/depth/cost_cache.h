#pragma once

// A photo's cost volume on disk between the dense stage's sweep and its MRF
// (dense_passes.h): E_photo as 16-bit fixed point (in [0, 1]; 1/65535 is far
// below the costs' noise), then w_photo as 32-bit floats. The file holds no
// header: the volume's size comes from the sweep's record of it.

#include <string>
#include <vector>

#include "format/image.h"
#include "reconstruct/depth/plane_sweep.h"

namespace casual3d::depth {

// Writes `vol`'s costs and photo weights to `path` atomically, converting in
// chunks (no second copy of the volume in memory). Throws io::IoException.
void WriteCostCache(const std::string& path, const CostVolume& vol);

// Reads a cache's costs into `*cost` (resized to `total` floats, its old
// contents overwritten) and, when `photo_weight` is given (allocated to the
// volume's size), its photo weights. Throws io::IoException naming `path` when
// the file is missing or shorter than that.
void ReadCostCache(const std::string& path, size_t total, std::vector<float>* cost, ImageF* photo_weight);

}  // namespace casual3d::depth
