#pragma once

// Held-out views for honest evaluation (`casual3d reconstruct --holdout-every N`,
// then `casual3d evaluate`): every photo is registered by the sparse stage, so
// that the held-out photos have poses in the same world, but the dense and
// panorama stages see a training workspace without them. The held-out photos
// thus contribute neither depth, nor colour, nor matching evidence to the 3D
// photo, and rephotographing them tests novel views (LLFF protocol: N = 8,
// photos 0, 8, 16, ... of the sorted names).

#include <string>
#include <vector>

namespace casual3d::pipeline {

// The names at indices 0, every, 2 every, ... of `names` sorted; empty when
// every <= 0. Throws std::invalid_argument if every > 0 would hold out all
// photos but one or fewer remain (fewer than 2 training photos).
std::vector<std::string> HoldoutNames(std::vector<std::string> names, int every);

// Writes the training workspace `train_dir` from the sparse workspace
// `sparse_dir` (SPARSE/images, SPARSE/sparse and the files at its top level
// such as frame.json and depth_ranges.json): the model without the images
// named in `holdout` (their observations removed from the tracks; points seen
// by fewer than 2 remaining photos dropped; image and camera ids kept, so
// per-image files stay valid), and images/ linking to the remaining photos
// (symbolic links, or copies where links are not possible). frame.json is
// written if missing, computed from ALL registered cameras, so the 3D photo's
// frame does not depend on the held-out set. Replaces `train_dir` atomically
// (written under a temporary name, then renamed). Throws std::runtime_error
// naming the file on failure.
void WriteTrainingWorkspace(const std::string& sparse_dir, const std::vector<std::string>& holdout,
                            const std::string& train_dir);

}  // namespace casual3d::pipeline
