#pragma once

// The captured field of view of a 3D photo: what part of a viewer's image the
// capture saw, against which the rendering is judged (viewer_views.h).
//
// Content mask: the panorama divided into square cells of
// max(1, round(width / 512)) pixels; a cell holds content when more than half
// of its pixels have a front node and its centre direction lies within the
// content's angular extent of the view hints (ViewHints::content_yaw_*_deg,
// content_pitch_*_deg; longitudes modulo 360). Its holes narrower than
// about 2 closing_deg then count as captured: the 4-connected components of
// non-content cells (columns wrapping around the seam, rows not) that lie
// wholly inside the mask's closing (dilated, then eroded; square window,
// rows clamped) with a radius of ceil(closing_deg / cell angle) cells. The
// outline stays where it is, notches included: a notch of a ragged outline
// is part of what no photo saw, not a hole in what they saw.
//
// Proxy: the mask's cells as one closed surface, a node at each content
// cell's centre direction at the median front depth of its pixels (cells
// without front nodes, filled by the closing, take the mean of their
// neighbours, repeatedly), every pair of neighbouring content cells linked.
//
// A pixel of a view is inside the captured field when the proxy, rendered
// from the view's eye (mesh_renderer.h), covers it. Seen from the centre that
// is the pixel's ray direction falling in the mask (Contains); seen from
// elsewhere the content's outline moves with parallax as the content does,
// so that the black beyond the edge of a partial capture is outside the field
// and a missing surface inside the content is inside it.

#include <vector>

#include "format/equirect.h"
#include "format/image.h"
#include "format/mesh.h"
#include "format/two_layer.h"
#include "format/view_hints.h"
#include "reconstruct/render/mesh_renderer.h"

namespace casual3d::eval {

class CapturedField {
 public:
  // `closing_deg` in [0, 45]: the closing radius in degrees (0: no closing).
  // Throws std::invalid_argument when it is out of range.
  CapturedField(const TwoLayerPanorama& pano, const ViewHints& hints, double closing_deg = 2.0);

  // Whether direction `d` (any length > 0, panorama frame, from the centre)
  // falls in a content cell.
  bool Contains(const Vec3d& d) const;

  // The field of `view`: width x height x 1, 255 inside, 0 outside. `options`
  // give the clipping planes and threads (colour and ids are ignored).
  Image8 Mask(const render::PinholeView& view, const render::RenderOptions& options) const;

  int grid_width() const { return grid_width_; }
  int grid_height() const { return grid_height_; }
  bool cell(int cx, int cy) const { return cells_[size_t(cy) * grid_width_ + cx] != 0; }

 private:
  int width_ = 0, height_ = 0, cell_px_ = 1;  // Panorama size, cell side in pixels.
  int grid_width_ = 0, grid_height_ = 0;
  std::vector<unsigned char> cells_;
  Mesh proxy_;
};

}  // namespace casual3d::eval
