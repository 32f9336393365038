#pragma once

// A dense plan (dense_passes.h) as JSON, without the photos' pixels: the
// plan unit of dense_units.h records it in plan.json once, and every other
// unit reads it there instead of reading the sparse model and ranking the
// neighbours again (about a minute of CPU for a 100-photo capture with a
// million points). Numbers round-trip exactly, so a plan read back gives the
// same outputs as the one computed.

#include <string>

#include <nlohmann/json.hpp>

#include "reconstruct/depth/dense_passes.h"

namespace casual3d::depth {

// The views' names, sizes, cameras (full and working resolution) and depth
// ranges, the ranked and swept neighbours, the labels per photo and the
// diagonal ratio.
nlohmann::json DensePlanToJson(const DensePlan& plan);

// The plan `j` describes, its views without pixels (LoadViewPixels reads
// them from `images_dir`). Throws std::runtime_error when `j` is not such a
// record (a missing member, a neighbour index out of range).
DensePlan DensePlanFromJson(const nlohmann::json& j, const std::string& images_dir);

}  // namespace casual3d::depth
