#pragma once

// The dense stage's report: the summary over photos, dense.json
// (spec/stage-dense.md), and a photo's report as exact JSON for the stage's
// units (dense_units.h), which hand it from one process to the next.

#include <string>

#include <nlohmann/json.hpp>

#include "reconstruct/depth/dense_stage.h"

namespace casual3d::depth {

// Fills `report`'s means over its evaluated photos (pixel-weighted) and its
// mean cross-view consistency from `report->photos`.
void SummariseDenseReport(DenseReport* report);

// Writes dense.json for `report` and `options` to `path` atomically.
void WriteDenseJson(const std::string& path, const DenseReport& report, const DenseOptions& options);

// Every field of a photo's report; doubles are written with 17 significant
// digits, so PhotoReportFromJson(PhotoReportToJson(r)) == r exactly.
nlohmann::json PhotoReportToJson(const PhotoReport& report);
// Throws nlohmann::json::exception on a missing or mistyped field.
PhotoReport PhotoReportFromJson(const nlohmann::json& json);

}  // namespace casual3d::depth
