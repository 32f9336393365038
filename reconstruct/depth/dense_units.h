#pragma once

// The dense stage as units of work over a shared output folder, so that its
// per-photo passes (dense_passes.h) can run as separate processes on
// separate machines. Running every unit gives the same depth/,
// confidence/ and envelope/ files as RunDenseStage (dense.json differs in
// its timings only).
//
//   plan    checks the workspace and records its photos, cameras, depth ranges and
//           neighbours (OUT/.dense-units/plan.json), which the other units read
//           instead of the sparse model
//   sweep   per photo: cost volume and WTA map;    needs: plan
//   depth   per photo: envelope, MRF, upsampling;  needs: the sweeps of the
//           photo and of its first gc.max_views ranked neighbours
//   finish  the free-space check, OUT/depth/, OUT/dense.json; needs: every
//           photo's depth unit; reads the photos and the depth maps when it
//           needs them (dense_finish.h); then removes OUT/.dense-units/
//
// Intermediate results live in OUT/.dense-units/ (cost caches, WTA maps,
// unchecked depth maps). Every file is written to a temporary name and
// renamed; a photo's unit is done when its record (<pass>/<stem>.json) exists,
// which is written last, so a unit killed half-way leaves nothing a rerun
// trusts, and a rerun skips the photos already done. Every unit must be
// given the same options (plan.json records the ones that shape the
// intermediate files and refuses a unit whose differ).

#include <string>
#include <vector>

#include "reconstruct/depth/dense_stage.h"

namespace casual3d::depth {

enum class DensePass { kPlan, kSweep, kDepth, kFinish };

// "plan", "sweep", "depth", "finish"; false for anything else.
bool DensePassFromName(const std::string& name, DensePass* pass);

// Parses a photo list such as "0,3,5-9" (indices in the workspace's photos
// sorted by name). Throws std::invalid_argument naming `text` on a bad list.
std::vector<int> ParsePhotoList(const std::string& text);

struct DenseUnitResult {
  std::vector<std::string> photos;  // The workspace's photos, by index.
  // kPlan only: the order in which to sweep the photos so that depth units
  // can run early and free their cost caches, and per photo the sweeps its
  // depth unit reads (dense_schedule.h).
  std::vector<int> sweep_order;
  std::vector<std::vector<int>> needs;
  int ran = 0;                      // Photos this unit computed.
  int skipped = 0;                  // Photos already done.
  DenseReport report;               // kFinish only.
};

// Runs one unit: `pass` over `photos` (empty: all; ignored by plan and
// finish). Throws std::invalid_argument for bad options or photo indices,
// std::runtime_error naming the missing unit or file otherwise.
DenseUnitResult RunDenseUnit(const std::string& workspace_dir, const std::string& out_dir,
                             const DenseOptions& options, DensePass pass, const std::vector<int>& photos);

}  // namespace casual3d::depth
