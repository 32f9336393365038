#pragma once

// What a viewer sees of a 3D photo: the mesh (format/mesh_builder.h) rendered
// by the reference renderer (reconstruct/render/mesh_renderer.h) from a fixed
// set of viewer cameras spread over the viewing volume, and two measures of
// what goes wrong there. It needs the 3D photo only, no photos.
//
// Views (ViewerCameras): the view hints (format/view_hints.h; derived from the
// panorama by render::DeriveViewHints when the 3D photo has none) give the
// direction (yaw, pitch), the vertical field of view and the viewing volume, a
// ball of radius R around the panorama centre. 17 eyes: the centre, then 16 on
// the ball's surface at azimuths measured from the hints' yaw in the
// horizontal plane (longitude offsets; 0 = straight ahead along the viewing
// direction, 90 = to its right):
//   1-8   latitude 0, azimuths 0, 45, ..., 315;
//   9-12  latitude +45 (above), azimuths 45, 135, 225, 315;
//   13-16 latitude -45 (below), azimuths 45, 135, 225, 315.
// Every view looks along the hints' direction (the viewer turns the view, it
// does not aim at a point) with the hints' field of view, at width x height
// pixels (square pixels, no roll; render::ViewFromGlCamera).
//
// Measures, per view, over the pixels inside the captured field of view
// (captured_field.h: those that a hole-free proxy of the captured content, a
// coarse closed surface over the cells of the panorama holding front nodes,
// covers when rendered from the same eye):
//  * Tears: the fraction of those pixels that no triangle covers (the viewer
//    shows its background there).
//  * Stretched fill: a triangle's screen size is the largest visual angle, at
//    the eye, of its three edges times the view's focal length (its longest
//    edge in pixels at the image centre; defined for triangles crossing the
//    near plane too). The typical size is the median screen size of the
//    distinct triangles drawing at least one pixel of the view. A drawn pixel
//    is stretched when its triangle's screen size exceeds stretch_factor
//    times the typical size. Stretched fill is the fraction of the covered
//    pixels inside the captured field of view that are stretched. Seen from
//    the centre, every triangle of the full mesh spans one panorama pixel
//    quad, so stretched fill appears only away from the centre: depth edges
//    bridged by links, fill fanned across a gap.
// Aggregates: the centre view alone, and the mean and the maximum over the 16
// boundary views.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "format/sheet_stretch.h"
#include "format/status.h"
#include "format/image.h"
#include "format/mesh.h"
#include "format/two_layer.h"
#include "format/view_hints.h"
#include "reconstruct/render/mesh_renderer.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::eval {

struct ViewerViewsOptions {
  // Rendered view size, pixels; [16, 4096] each.
  int width = 640;
  int height = 400;
  // k of stretched fill: a triangle is stretched when its screen size exceeds
  // k times the view's median; [1, 1000].
  double stretch_factor = 8.0;
  // Closing radius of the captured field's content mask, degrees; [0, 45].
  double closing_deg = 2.0;
  // Derive the view hints from the panorama even when the 3D photo has its
  // own (to compare 3D photos with and without them on the same footing).
  bool derive_hints = false;
  // Keep the rendering and the heatmap of each view (for the report).
  bool keep_images = true;
  int num_threads = 0;  // Rendering threads; 0 = all cores. [0, 256].
  // Triangles of the mesh from this index on are a backdrop drawn in its
  // vertex colours (render::RenderOptions::vertex_colors_from_triangle).
  uint64_t vertex_colors_from_triangle = UINT64_MAX;
  // With a backdrop (vertex_colors_from_triangle set): mesh triangles
  // stretched beyond this seen from the eye are not drawn, as the viewer
  // does (format/sheet_stretch.h); 0 draws them all. [0, 1000].
  double sheet_stretch = kDefaultSheetStretch;

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("width", o.width, R::Closed(16, 4096), "Width of the viewer views, pixels");
    v.Field("height", o.height, R::Closed(16, 4096), "Height of the viewer views, pixels");
    v.Field("stretch_factor", o.stretch_factor, R::Closed(1, 1000),
            "A triangle is stretched when longer on screen than this many times the view's "
            "median triangle");
    v.Field("closing_deg", o.closing_deg, R::Closed(0, 45),
            "Closing radius of the captured field's content mask, degrees");
    v.Field("derive_hints", o.derive_hints, R::Any(),
            "Derive the view hints from the panorama even when the 3D photo carries its own");
    v.Field("keep_images", o.keep_images, R::Any(),
            "Keep the rendering and the heatmap of each view (for the report)");
    v.Field("num_threads", o.num_threads, R::Closed(0, 256), "Rendering threads; 0 = all cores",
            util::Keyed::kNo);
    v.Field("vertex_colors_from_triangle", o.vertex_colors_from_triangle, R::Any(),
            "Triangles from this index on are a backdrop drawn in its vertex colours");
    v.Field("sheet_stretch", o.sheet_stretch, R::Closed(0, 1000),
            "Viewer views with the backdrop: triangles that look more than this many times "
            "larger from the eye than from the centre (sheets across depth steps) are left out, "
            "as the viewer does (format/sheet_stretch.h); 0 draws them");
  }
  Status Check() const { return util::CheckFields(*this); }  // Names the field and its range.
};

// The 17 viewer cameras of `hints` (index 0 the centre), and their names
// ("centre", "level az 45", "above az 135", ...). Pitch is clamped to
// [-89, 89] and the field of view to [10, 120].
std::vector<render::GlCamera> ViewerCameras(const ViewHints& hints);
std::vector<std::string> ViewerCameraNames();

// Pixel classes of a measured view (the heatmap's legend).
enum class ViewerPixel : uint8_t {
  kOutside = 0,    // Outside the captured field of view.
  kGood = 1,       // Inside, covered by a triangle of typical size.
  kTear = 2,       // Inside, not covered.
  kStretched = 3,  // Inside, covered by a stretched triangle.
};

struct ViewerViewResult {
  std::string name;
  render::GlCamera camera;
  int64_t captured_pixels = 0;   // Inside the captured field of view.
  int64_t tear_pixels = 0;       // Of those, uncovered.
  int64_t stretched_pixels = 0;  // Of those, covered by stretched triangles.
  double tear_fraction = 0;      // tear_pixels / captured_pixels (0 if none).
  // stretched_pixels / (captured_pixels - tear_pixels) (0 if none).
  double stretched_fraction = 0;
  double median_triangle_px = 0;  // Typical screen size of the view's triangles.
  // With keep_images: the rendering (RGB) and the per-pixel ViewerPixel class.
  Image8 render;
  Image8 classes;
};

struct ViewerViewsEvaluation {
  ViewHints hints;
  bool hints_derived = false;  // Derived from the panorama (the 3D photo had none).
  int width = 0, height = 0;
  double stretch_factor = 0;
  // The sheets left out (render::RenderOptions::sheet_stretch); 0: all drawn.
  double sheet_stretch = 0;
  std::vector<ViewerViewResult> views;  // 17, the centre first.
  double centre_tears = 0, boundary_tears_mean = 0, boundary_tears_max = 0;
  double centre_stretched = 0, boundary_stretched_mean = 0, boundary_stretched_max = 0;
};

// Measures the 17 views of `mesh`, the mesh of `pano` (BuildMesh), with its
// colour atlas `atlas`. `hints`: the 3D photo's own, or nullopt to derive them
// (render::ResolveViewHints; always derived with options.derive_hints).
// Throws std::invalid_argument for invalid options or the renderer's errors.
ViewerViewsEvaluation EvaluateViewerViews(const TwoLayerPanorama& pano, const Mesh& mesh,
                                          ImageView<const uint8_t> atlas,
                                          const std::optional<ViewHints>& hints,
                                          const ViewerViewsOptions& options = {});

// One view measured: `r` rendered with triangle ids from `camera`, `field`
// pixels (width x height x 1, non-zero = inside the captured field).
ViewerViewResult MeasureViewerView(const Mesh& mesh, const render::GlCamera& camera,
                                   const render::RenderResult& r, const Image8& field,
                                   double stretch_factor);

// The heatmap of a view: its rendering dimmed to 40%, tears red, stretched
// fill orange, and pixels outside the captured field darkened further and
// tinted blue.
Image8 ViewerHeatmap(const ViewerViewResult& view);

}  // namespace casual3d::eval
