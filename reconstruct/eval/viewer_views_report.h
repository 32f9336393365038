#pragma once

// The viewer-side measure (viewer_views.h) in the reports of `casual3d
// evaluate`: an HTML section with the figures and a grid of heatmaps, the
// JSON member, the one-line summary of the command line, and the heatmaps as
// PNG files.
//
// Grid layout (8 columns, 3 rows): the middle row holds the 8 level views by
// azimuth (0 = ahead of the viewing direction, then clockwise seen from
// above: 45, ..., 315); the top row the 4 views above and the bottom row the 4
// below, each in the column of its azimuth (45, 135, 225, 315: columns 1, 3,
// 5, 7); the centre view sits in the top-left corner.

#include <string>

#include "format/image.h"
#include "reconstruct/eval/viewer_views.h"

namespace casual3d::eval {

// Grid cell (column, row) of view `index` (0 the centre, as ViewerCameras).
void ViewerGridCell(int index, int* column, int* row);

// The heatmap of a view reduced by an integer `factor` >= 1: a reduced pixel
// is red if any of its pixels is a tear, else orange if any is stretched,
// else the mean of the full heatmap's pixels, so that single-pixel tears stay
// visible in thumbnails.
Image8 ViewerHeatmapThumbnail(const ViewerViewResult& view, int factor);

// All 17 thumbnails (factor as above) in the grid layout, one pixel of dark
// grey between cells; empty if the views kept no images.
Image8 ViewerHeatmapGrid(const ViewerViewsEvaluation& eval, int factor);

// The HTML section (heading level 3) for one 3D photo, with thumbnails
// `thumbnail_width` pixels wide (at most the view's width).
std::string ViewerViewsHtml(const ViewerViewsEvaluation& eval, int thumbnail_width);

// The JSON object: {width, height, stretch_factor, hints: {...}, hints_derived,
// centre_tears, boundary_tears_mean, boundary_tears_max, centre_stretched,
// boundary_stretched_mean, boundary_stretched_max, views: [{name, position,
// captured_pixels, tear_pixels, stretched_pixels, tear_fraction,
// stretched_fraction, median_triangle_px}]}, serialised.
std::string ViewerViewsJson(const ViewerViewsEvaluation& eval);

// "viewer views (17 at 640x400, hints derived): tears centre 0.012%, ..."
std::string ViewerViewsSummary(const ViewerViewsEvaluation& eval);

// Writes DIR/<prefix>viewer_<k>_<name>.png (each view's full-size heatmap)
// and DIR/<prefix>viewer_grid.png (factor 2). Throws std::runtime_error
// naming the file when it cannot be written.
void WriteViewerHeatmaps(const ViewerViewsEvaluation& eval, const std::string& dir,
                         const std::string& prefix);

}  // namespace casual3d::eval
