#pragma once

// The backdrop of a 3D photo (spec/mesh.md Sec. 8, informative): a coarse,
// hole-free surface that a viewer draws with the mesh of spec/mesh.md so that
// a tear in the mesh (a cut link nothing stands behind, a disocclusion wider
// than the back layer) shows the background at about the right depth and
// parallax instead of the view's background.
//
// The panorama is divided into cells of cell_px x cell_px pixels. Backdrop
// vertices lie on the rays of the pixel centres (i * cell_px, j * cell_px);
// vertex (i, j) takes the largest node depth (either layer) of the cells
// within r = 1 + ceil(spread_px / cell_px) cells of cell (i, j) (a square
// window), times depth_factor: behind a foreground object the backdrop lies
// at the depth of the background beside it, so that its steps from the
// foreground's depth to the background's lie spread_px inside the object,
// hidden behind it from the viewing volume, instead of at its edge, where an
// eye off the centre would see them as a sheet stretched across the gap. Every cell holding at least one node
// gets the two triangles of the quad (i, j)..(i + 1, j + 1) (columns wrap,
// with seam copies as in the mesh; rows stop at the last vertex row). A quad's
// pixels lie in the cells of its corners' windows, so the backdrop lies behind
// every node it covers: seen from the centre it is hidden wherever the mesh
// has a surface, and it only shows through the mesh's openings.
//
// Colour (Mesh::colors, interpolated across each triangle): each cell's
// colour is the mean colour of its nodes within 5% of its largest depth; a
// vertex takes the mean of those colours over the cells with nodes within
// q = min(16, max(1, r / 4)) of its own cell, each weighted by (f / F)^4: f
// the cell's largest depth, clipped to 1.5 times the mean largest depth of
// the other cells with nodes within q of it, F the largest f. A blurred fill
// in the colour of the farther surfaces around the vertex, as an inpainting
// would give, which a few far outliers of a noisy capture do not take over.
// Vertex uvs point into the back half of the colour atlas at the
// vertex's pixel (for readers that can only texture; format/color_atlas.h).
// Normals are (0, 0, 0): the backdrop is unlit.
//
// Deterministic like BuildMesh: the same panorama gives the same floats
// natively and in the Emscripten build.

#include "format/mesh.h"
#include "format/status.h"
#include "format/two_layer.h"

namespace casual3d {

struct BackdropOptions {
  // Cell side in pixels; 0: automatic, max(1, round(width / 1024)) (4 at
  // 4096 px: 0.35 degrees, small enough that a backdrop triangle is about as
  // large on screen as a few of the mesh's). Range [0, 256].
  int cell_px = 0;
  // How far the background's depth spreads behind nearer nodes, pixels; 0:
  // automatic, 0.012 * width (49 at 4096: the back layer's growth,
  // reconstruct/fuse/fuse.h, which bounds the viewing volume). [0, 4096].
  int spread_px = 0;
  // Factor on the farthest depth of a vertex's cells, so that the backdrop
  // never competes with the surface it lies behind; [1, 2].
  double depth_factor = 1.02;
  // Largest panorama accepted, pixels; as MeshBuildOptions::max_pixels.
  int64_t max_pixels = int64_t{8192} * 4096;

  // InvalidArgument naming the field when a value is out of range.
  Status Check() const;
};

// The cell side and the spread that `options` resolve to for a panorama
// `width` wide.
int BackdropCellPixels(const BackdropOptions& options, int width);
int BackdropSpreadPixels(const BackdropOptions& options, int width);

// Builds the backdrop of `pano` (its nodes' depths only; links are not used,
// so the panorama needs no validation beyond consistent array sizes). Errors:
// options out of range (kInvalidArgument), a panorama larger than
// options.max_pixels (kLimitExceeded), width below 2 or inconsistent arrays
// (kInvalidArgument). A panorama without nodes gives an empty mesh.
StatusOr<Mesh> BuildBackdrop(const TwoLayerPanorama& pano, const BackdropOptions& options = {});

// Appends `extra`'s vertices and triangles to `mesh` (indices offset).
void AppendMesh(const Mesh& extra, Mesh* mesh);

}  // namespace casual3d
