#pragma once

// Loading a dense-stage workspace: WORKSPACE/images/<name> (undistorted
// photos) and WORKSPACE/sparse/ (COLMAP model of PINHOLE or SIMPLE_PINHOLE
// cameras), with per-photo depth ranges from WORKSPACE/sparse/depth_ranges.json
// or WORKSPACE/depth_ranges.json when the sparse stage wrote one, otherwise
// computed from the model (sfm::ComputeDepthRanges). This is the one place
// where geometry:: types are converted to the dense stage's PinholeCamera.

#include <string>
#include <vector>

#include "reconstruct/depth/neighbor_selection.h"
#include "reconstruct/depth/view.h"

namespace casual3d::depth {

struct LoadedWorkspace {
  std::vector<DenseView> views;                  // Sorted by image name.
  std::vector<std::vector<int>> ranked_neighbors;  // Per view, the others best first.
  std::string images_dir;
};

// Reads the model and, with `load_pixels`, the photos (LoadViewPixels for
// every view), and ranks neighbours. Without `load_pixels` the views have
// their names, cameras and depth ranges but no images, for a unit of work that
// needs a few photos of a large capture (dense_units.h). Throws
// std::runtime_error naming the file and the problem (missing folder,
// undecodable photo, distorted camera model, ...).
LoadedWorkspace LoadWorkspace(const std::string& workspace_dir, double working_scale,
                              const NeighborOptions& neighbor_options, bool load_pixels = true);

// Reads view `i`'s photo from ws->images_dir into its images: full-resolution
// grey, and colour and grey downscaled to its working camera's size (area
// averaging). Does nothing when they are already there. Throws
// std::runtime_error naming the photo when it cannot be decoded or its size is
// not its camera's.
void LoadViewPixels(LoadedWorkspace* ws, int i);

// View `i`'s full-resolution grey image as LoadViewPixels makes it (the same
// bytes), read from ws.images_dir without keeping anything in `ws`, for the
// free-space check, which needs it photo by photo. Throws as LoadViewPixels.
ImageF ReadViewGrayFull(const LoadedWorkspace& ws, int i);

// Decodes view `i`'s photo and checks its size as LoadViewPixels does,
// keeping nothing (the plan unit's check of every photo).
void CheckViewPhoto(const LoadedWorkspace& ws, int i);

// Whether view `i` has its images (LoadViewPixels ran).
bool HasViewPixels(const LoadedWorkspace& ws, int i);

// Reads one photo at full resolution as RGB float in [0, 1].
ImageF ReadPhotoFloat(const std::string& path);

// Resizes an RGB or grey float image with area averaging (OpenCV INTER_AREA).
ImageF ResizeArea(const ImageF& image, int width, int height);

// Luma (0.299 R + 0.587 G + 0.114 B) of an RGB float image.
ImageF GrayOf(const ImageF& rgb);

// File stem used for a photo's outputs: the image name without its
// extension, with path separators replaced by '_'.
std::string OutputStem(const std::string& image_name);

}  // namespace casual3d::depth
