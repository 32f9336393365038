#pragma once

// The dense stage (Sec. 4.3): a depth map per photo from a workspace of
// undistorted photos and their COLMAP model.
//
// Inputs:  WORKSPACE/images/<name>, WORKSPACE/sparse/ (PINHOLE cameras),
//          optional WORKSPACE/{sparse/,}depth_ranges.json.
// Outputs (OUT/, every file written atomically; spec/stage-dense.md):
//   depth/<stem>.exr       float "Z": depth in metres along the optical axis, full resolution
//   confidence/<stem>.exr  float "Y" in [0, 1]: w_photo * (1 - E_photo) of the chosen depth
//   envelope/<stem>.exr    float "Z": the near envelope (metres), full resolution
//   dense.json             per photo: neighbours, depth range, anchor counts, timings,
//                          cross-view consistency (and accuracy when ground truth is given)
//   debug/<stem>_{wta,gc,median,bilateral,propagated,envelope,trws,mrf,upsampled,depth}.png
//                          with debug
//   debug/<stem>_{gt,error}.png  with debug and ground truth
//
// Per photo: neighbour selection; plane sweep with ZNCC (plane_sweep.h);
// WTA; near envelope: GC filter (gc_filter.h), median and bilateral median
// pruning (median_prune.h), Poisson propagation, scaling and min filter
// (near_envelope.h); MRF of Eq. 1-4 solved by TRW-S (mrf_trws.h); sub-label
// edge-aware median against window fattening (edge_median.h); sub-label
// refinement (sublabel_refine.h); joint bilateral weighted-median upsampling
// (upsample.h);
// boundary relabelling and a full-resolution search (fullres_refine.h). Once
// every photo has its map: the free-space check of the maps against each
// other (visibility_filter.h).
//
// These run as three passes (dense_passes.h): sweep and depth per photo,
// finish over all. RunDenseStage runs them in one process; dense_units.h
// runs them as separate units of work over a shared OUT, with the same files.

#include <string>
#include <vector>

#include "format/status.h"
#include "reconstruct/depth/edge_median.h"
#include "reconstruct/depth/flat_regions.h"
#include "reconstruct/depth/fullres_refine.h"
#include "reconstruct/depth/gc_filter.h"
#include "reconstruct/depth/median_prune.h"
#include "reconstruct/depth/near_envelope.h"
#include "reconstruct/depth/neighbor_selection.h"
#include "reconstruct/depth/plane_sweep.h"
#include "reconstruct/depth/sublabel_refine.h"
#include "reconstruct/depth/upsample.h"
#include "reconstruct/depth/visibility_filter.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::depth {

// Terms of Eq. 1, 2 and 4.
struct MrfTermOptions {
  double lambda_smooth = 0.25;  // Sec. 4.3.1: lambda_smooth. [0, 100].
  double lambda_near = 1.0;     // Sec. 4.3.2: lambda_near (Eq. 4). [0, 100].
  double sigma_color = 0.04;    // w_color = exp(-|c_i - c_j|^2 / (2 sigma^2)), colour in [0, 1]. (0, 10].
  double color_floor = 0.02;    // Lower bound of w_color, so strong edges still regularise a little. [0, 1].
  // A cost far_bias * (1 - w_photo) * (1 - k / (L - 1)) on label k that leans
  // textureless pixels away from the camera, towards the sweep's far plane
  // (spec/stage-dense.md). Off by default: a weakly textured ceiling or wall
  // has too little evidence to resist it and went to the far plane, 100 times
  // the near depth, in patches that tore from off the centre; the free-space
  // check, the flat-region priors and the panorama's front support keep the
  // floaters it was for in check (synthetic near floaters 0.47% -> 0.50%;
  // docs/DECISIONS.md, "Dense: no far bias"). [0, 1].
  double far_bias = 0.0;
  int truncation_labels = 8;    // w_depth = min(|k_i - k_j|, T) / T, labels (inverse depth). [1, 4096].
  // TRW-S passes (docs/DECISIONS.md, "Dense: 6 TRW-S passes"). [1, 1000].
  int max_iterations = 6;
  // Our addition: pixels with a flat-region prior (flat_regions.h) pay
  // lambda_flat * (1 - w_photo) * min(|k - prior|, T_flat) / T_flat, and the
  // far bias does not apply to them. [0, 100], [1, 100].
  double lambda_flat = 0.3;
  double flat_truncation_labels = 4.0;

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("lambda_smooth", o.lambda_smooth, R::Closed(0, 100), "Smoothness weight (Eq. 1, Sec. 4.3.1)");
    v.Field("lambda_near", o.lambda_near, R::Closed(0, 100), "Near envelope penalty (Eq. 4, Sec. 4.3.2)");
    v.Field("sigma_color", o.sigma_color, R::OpenClosed(0, 10), "w_color colour sigma, colour in [0, 1]");
    v.Field("color_floor", o.color_floor, R::Closed(0, 1), "Lower bound of w_color");
    v.Field("far_bias", o.far_bias, R::Closed(0, 1), "Cost leaning textureless pixels away from the camera (MRF data term)");
    v.Field("truncation_labels", o.truncation_labels, R::Closed(1, 4096), "Smoothness truncation T, labels");
    v.Field("max_iterations", o.max_iterations, R::Closed(1, 1000),
            "Most TRW-S passes (each forward and backward); fewer is faster, at a higher energy");
    v.Field("lambda_flat", o.lambda_flat, R::Closed(0, 100), "Weight of the textureless-region prior in the MRF data term");
    v.Field("flat_truncation_labels", o.flat_truncation_labels, R::Closed(1, 100), "Truncation T_flat of that prior, labels");
  }
  Status Check() const { return util::CheckFields(*this); }
};

struct DenseOptions {
  double working_scale = 0.5;  // Sweep, envelope and MRF resolution relative to the photos. (0, 1].
  // Neighbours per sweep. [1, 16]. Why 12: docs/DECISIONS.md, "Dense: 12
  // neighbours per sweep".
  int num_neighbors = 12;
  // Filter sizes below are given for a 900x1350 image (Sec. 4.3.2) and scaled
  // with the working image's diagonal.
  double reference_diagonal = 1622.5;  // sqrt(900^2 + 1350^2), pixels.
  // The sweep's far plane lies at least this many times farther than its near
  // plane. Structure-from-motion triangulates no point whose triangulation
  // angle is tiny, so with a casual capture's short baseline the sparse
  // points, and the far bound taken from them, stop at a few metres while
  // facades and trees stand at tens. Labels are added beyond the sparse far
  // bound at the sparse range's spacing (sweep.num_depths over the sparse
  // range; at most 4 * num_depths in all), so near content keeps its
  // precision (docs/DECISIONS.md, "Dense: far plane at least 100 times the
  // near plane"). [1, 1e6].
  double min_far_over_near = 100.0;
  NeighborOptions neighbors;
  SweepOptions sweep;
  GcFilterOptions gc;
  MedianPruneOptions prune;
  EnvelopeOptions envelope;
  MrfTermOptions mrf;
  EdgeMedianOptions edge_median;  // In working pixels, like the sweep's window (fattening scale).
  SubLabelOptions sublabel;
  UpsampleOptions upsample;
  BoundaryRelabelOptions relabel;  // After upsampling, before fullres.
  FullResRefineOptions fullres;    // After upsampling.
  FlatRegionOptions flat;          // Priors for textureless regions (MRF data term, sub-label step).
  VisibilityFilterOptions visibility;  // Once all final maps exist: the free-space check.
  bool use_near_envelope = true;  // false: the "MRF without near envelope" baseline (Fig. 5).
  bool use_gc_filter = true;      // false: skip the GC filter when building anchors.
  bool debug = false;             // Colour-mapped PNGs of every intermediate.
  int num_threads = 0;            // 0 = all cores.
  // Optional: folder with ground-truth depth <stem>.exr ("Z", metres, +inf sky)
  // to evaluate against (reported in dense.json).
  std::string ground_truth_dir;

  // Every field of this struct and of the structs nested in it is described
  // here (reconstruct/util/options_fields.h): the checks, the pipeline's cache
  // key, dense.json's "options" and the dense command's help come from it.
  // dense_options_test fails when a field is missing.
  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("working_scale", o.working_scale, R::OpenClosed(0, 1), "Sweep/MRF resolution relative to the photos");
    v.Field("num_neighbors", o.num_neighbors, R::Closed(1, 16), "Neighbour photos per sweep");
    v.Field("reference_diagonal", o.reference_diagonal, R::Above(0), "Image diagonal the filter sizes are given for, pixels");
    v.Field("min_far_over_near", o.min_far_over_near, R::Closed(1, 1e6),
            "The sweep's far plane is at least this many times farther than its near plane");
    v.Struct("neighbors", o.neighbors);
    v.Struct("sweep", o.sweep);
    v.Struct("gc", o.gc);
    v.Struct("prune", o.prune);
    v.Struct("envelope", o.envelope);
    v.Struct("mrf", o.mrf);
    v.Struct("edge_median", o.edge_median);
    v.Struct("sublabel", o.sublabel);
    v.Struct("upsample", o.upsample);
    v.Struct("relabel", o.relabel);
    v.Struct("fullres", o.fullres);
    v.Struct("flat", o.flat);
    v.Struct("visibility", o.visibility);
    v.Field("use_near_envelope", o.use_near_envelope, R::Any(), "MRF with the near envelope term (Eq. 4)");
    v.Field("use_gc_filter", o.use_gc_filter, R::Any(), "Build anchors with the GC filter");
    v.Field("debug", o.debug, R::Any(), "Also write colour-mapped PNGs of every step to OUT/debug/");
    v.Field("num_threads", o.num_threads, R::AtLeast(0), "Worker threads; 0 = all cores", util::Keyed::kNo);
    v.Field("ground_truth_dir", o.ground_truth_dir, R::Any(),
            "Folder of ground-truth depth <stem>.exr to evaluate against; results go to dense.json");
  }
  Status Check() const { return util::CheckFields(*this); }
};

struct StageQuality {
  std::string stage;  // "wta", "gc", "median", "bilateral".
  double completeness = 0.0;
  double precision = 0.0;
};

struct PhotoReport {
  std::string name;
  std::vector<std::string> neighbors;
  double near_m = 0.0, far_m = 0.0;
  int width = 0, height = 0;              // Output size.
  int work_width = 0, work_height = 0;    // Working size.
  int num_labels = 0;                     // Depth labels swept (far-plane extension included).
  std::vector<int> anchors;               // Surviving pixels after wta, gc, median, bilateral.
  int cg_iterations = 0;
  double mrf_energy = 0.0;
  // Fraction of pixels whose depth agrees within 2% with >= 2 other views'
  // output depth maps, sampled at the working resolution (needs no ground truth).
  double cross_view_consistency = 0.0;
  int mrf_iterations = 0;
  // Seconds per step.
  double t_sweep = 0, t_envelope = 0, t_mrf = 0, t_refine = 0, t_upsample = 0;
  double t_flat = 0, t_fullres = 0;  // Parts of t_mrf and t_upsample.
  int flat_groups = 0, flat_fitted = 0;  // Flat regions found and given a plane.
  long long flat_pixels = 0;             // Working pixels with a flat-region prior.
  long long relabelled = 0, refined = 0; // Full-resolution pixels changed by relabel / fullres.
  long long seen_through = 0, moved_back = 0;  // Free-space check: flagged / replaced pixels (all rounds).
  double t_visibility = 0;
  // Filled when ground truth is available.
  bool evaluated = false;
  double median_rel_error = 0, within_3pct = 0, near_floaters = 0, sky_near = 0;
  double within_half_label = 0, within_two_labels = 0;  // Label-step error (depth_metrics.h).
  // The same over the pixels whose true surface >= 2 swept neighbours see
  // (depth_metrics.h, AgreeingViews of the ground truth).
  long long pixels = 0, observed_pixels = 0;
  double median_rel_error_observed = 0, within_3pct_observed = 0, near_floaters_observed = 0;
  std::vector<StageQuality> stages;
  double envelope_error = 0, envelope_tightness = 0;
};

struct DenseReport {
  std::vector<PhotoReport> photos;
  double seconds_total = 0.0;
  double seconds_load = 0.0;
  size_t peak_rss_bytes = 0;
  // Means over evaluated photos (pixel-weighted for accuracy).
  bool evaluated = false;
  double median_rel_error = 0, within_3pct = 0, near_floaters = 0;
  double within_half_label = 0, within_two_labels = 0;
  double observed_fraction = 0;  // Of the evaluated pixels: seen by >= 2 swept neighbours.
  double median_rel_error_observed = 0, within_3pct_observed = 0, near_floaters_observed = 0;
  double cross_view_consistency = 0.0;  // Mean over photos.
};

// Runs the stage. Throws std::invalid_argument for bad options and
// std::runtime_error (naming the file) for bad inputs.
DenseReport RunDenseStage(const std::string& workspace_dir, const std::string& out_dir,
                          const DenseOptions& options);

}  // namespace casual3d::depth
