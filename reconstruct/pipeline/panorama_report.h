#pragma once

// OUT/panorama.json, the panorama stage's report (panorama_stage.h): size,
// sky depth, the front layer's coverage of the photos' field of view and
// footprint, the view hints, fusion, sealing and normals figures and the
// seconds of each step.

#include <string>

#include "format/view_hints.h"
#include "reconstruct/pipeline/panorama_stage.h"

namespace casual3d::pipeline {

// The report's JSON text (two-space indent, ending in a newline).
std::string PanoramaReportJson(const PanoramaStageReport& report,
                               const PanoramaStageOptions& options, const ViewHints& hints);

}  // namespace casual3d::pipeline
