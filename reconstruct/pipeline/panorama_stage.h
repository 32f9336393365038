#pragma once

// The panorama stages as one step of the pipeline (paper Sec. 4.4 and 5):
// warp every depth map into the central panorama, stitch the front and back
// layers, fuse them into a two-layer graph, compute normals.
//
// Inputs:
//   SPARSE/images/<name>        undistorted photos (sparse stage or synth capture)
//   SPARSE/sparse/              COLMAP model of their PINHOLE cameras
//   SPARSE/frame.json           the 3D photo's frame (optional: else computed
//                               from the cameras, or read from capture.json)
//   DEPTH/depth/<stem>.exr      depth per photo ("Z", metres along the optical
//                               axis; +inf or NaN = sky/unknown)
// Outputs (OUT/, files written atomically):
//   master.exr                  the two-layer panorama (encoder/master_file.h)
//   preview/{front,back}_{color,depth}.png, preview/normals.png, preview/labels.png,
//   preview/holes.png (field of view: grey; front-layer holes in it: red)
//   panorama.json               timings, statistics, options

#include <string>
#include <vector>

#include "format/two_layer.h"
#include "reconstruct/geometry/camera.h"
#include "reconstruct/fuse/fuse.h"
#include "reconstruct/fuse/seal.h"
#include "reconstruct/normals/normals.h"
#include "reconstruct/pipeline/coverage.h"
#include "reconstruct/pipeline/view_volume.h"
#include "reconstruct/stitch/smooth_depth.h"
#include "reconstruct/stitch/stitch.h"
#include "reconstruct/warp/warp.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::pipeline {

struct PanoramaStageOptions {
  // Output panorama width (height = width / 2); even, [64, 16384]; 0 =
  // from the photos' angular resolution (AutoPanoramaWidth), at most
  // max_auto_width. The paper uses 8192.
  int pano_width = 0;
  // Largest automatic width: a multiple of 1024 in [2048, 16384].
  int max_auto_width = 4096;
  warp::WarpOptions warp;        // pano_width/height are set from pano_width.
  stitch::StitchOptions stitch;
  // Smoothing of the stitched layers' depth along their surfaces, before
  // fusion (stitch/smooth_depth.h).
  stitch::DepthSmoothOptions depth_smooth;
  fuse::FuseOptions fuse;
  // Close the quads fusion leaves open (fuse/seal.h); false: the ablation.
  bool seal_tears = true;
  fuse::SealOptions seal;
  normals::NormalOptions normals;
  // The view hints written with the panorama (view_volume.h).
  ViewVolumeOptions view;
  // false: front layer only (the ablation of the paper's Fig. 15).
  bool back_layer = true;
  // Fill the front layer's gaps inside the photos' field of view
  // (coverage.h, FillGapsInside) before fusion: the ragged edges of the
  // photos' footprints, where near leaves or poles end at a photo's border.
  bool fill_front_gaps = true;
  // Depth given to photo pixels without a finite depth (sky), metres; 0 =
  // automatic: 1.5 x the largest finite depth of all photos.
  double sky_depth_m = 0.0;
  bool write_previews = true;
  int num_threads = 0;  // 0 = all cores.

  // Every field of this struct and of the structs nested in it is described
  // here (reconstruct/util/options_fields.h): the checks, the pipeline's cache
  // key and report come from it; panorama_options_test fails when one is missing.
  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("pano_width", o.pano_width, R::ZeroOr(R::Closed(64, 16384)),
            "Panorama width (even); 0 = from the photos' angular resolution");
    v.Field("max_auto_width", o.max_auto_width, R::Closed(2048, 16384), "Largest automatic width (a multiple of 1024)");
    v.Struct("warp", o.warp);
    v.Struct("stitch", o.stitch);
    v.Struct("depth_smooth", o.depth_smooth);
    v.Struct("fuse", o.fuse);
    v.Field("seal_tears", o.seal_tears, R::Any(), "Close the quads fusion leaves open");
    v.Struct("seal", o.seal);
    v.Struct("normals", o.normals);
    v.Struct("view", o.view);
    v.Field("back_layer", o.back_layer, R::Any(), "Build the back layer (false: front only, Fig. 15's ablation)");
    v.Field("fill_front_gaps", o.fill_front_gaps, R::Any(), "Fill the front layer's gaps inside the photos' field of view");
    v.Field("sky_depth_m", o.sky_depth_m, R::AtLeast(0), "Depth of sky pixels, metres; 0 = 1.5 x the largest finite depth");
    v.Field("write_previews", o.write_previews, R::Any(), "Write preview images");
    v.Field("num_threads", o.num_threads, R::AtLeast(0), "Worker threads; 0 = all cores", util::Keyed::kNo);
    v.Require(o.pano_width % 2 == 0, "pano_width", "must be even");
    v.Require(o.max_auto_width % 1024 == 0, "max_auto_width", "must be a multiple of 1024");
    v.Require(o.pano_width == 0 || o.stitch.solve_width <= o.pano_width, "stitch.solve_width", "must not exceed pano_width");
  }
  Status Check() const { return util::CheckFields(*this); }
};

struct PanoramaStageReport {
  int num_photos = 0;
  int width = 0, height = 0;
  double sky_depth_m = 0.0;
  // seconds_load covers the model and the sky's depth (every depth map read
  // once); seconds_warp reading each photo and its depth map, and warping;
  // seconds_fuse includes the field-of-view mask, the gap filling, the depth
  // smoothing and sealing.
  double seconds_load = 0, seconds_warp = 0, seconds_stitch_front = 0, seconds_stitch_back = 0,
         seconds_fuse = 0, seconds_normals = 0, seconds_write = 0, seconds_total = 0;
  fuse::FuseStats fuse;
  fuse::SealStats seal;
  normals::NormalStats normals;
  stitch::SeamBlendStats seam_blend_front, seam_blend_back;
  double front_coverage = 0.0;  // Fraction of pixels with a front node.
  // The front layer inside the photos' field of view: coverage and holes
  // (coverage.h); the field of view comes from the stitched front layer
  // before its gaps are filled.
  CoverageStats front_fov;
  // Front pixels filled by fill_front_gaps (already counted in front_fov).
  int64_t front_gaps_filled = 0;
  // The front layer inside the photos' footprint (union of their front
  // warps, FootprintMask): holes here are surfaces the photos saw that
  // stitching or fusion lost.
  CoverageStats front_footprint;
};

// Runs warp, stitch, fuse and normals; writes OUT (created if needed) and
// returns the panorama. Throws std::invalid_argument for bad options and
// std::runtime_error naming the file for bad inputs.
TwoLayerPanorama RunPanoramaStage(const std::string& sparse_dir, const std::string& depth_dir,
                                  const std::string& out_dir, const PanoramaStageOptions& options,
                                  PanoramaStageReport* report = nullptr);

// The panorama width that matches the photos' angular resolution: the
// median focal length f (pixels) of `cameras` gives 2 pi f pixels around the
// circle; rounded up to a multiple of 1024 and kept within [2048,
// max_width] (coarser levels are halved from it by the encoder).
int AutoPanoramaWidth(const std::vector<geometry::Camera>& cameras, int max_width);

// The 3D photo's frame for a workspace: SPARSE/frame.json if present, else the
// "frame" of SPARSE/capture.json (synthetic captures), else computed from the
// model's cameras.
PanoramaFrame LoadOrComputeFrame(const std::string& sparse_dir);

}  // namespace casual3d::pipeline
