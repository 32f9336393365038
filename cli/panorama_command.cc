// `casual3d panorama <workspace> -o <out> [--depth <dense-out>]`: warp, stitch,
// fuse and normals (Sec. 4.4 and 5) into a master file, from a workspace of
// undistorted photos with their depth maps.

#include <cstdio>
#include <string>

#include "cli/command.h"
#include "cli/described_option.h"
#include "reconstruct/io/image_io.h"
#include "reconstruct/pipeline/ground_truth_eval.h"
#include "reconstruct/pipeline/panorama_stage.h"

namespace casual3d::cli {

void AddPanoramaCommand(CLI::App& app) {
  struct Args {
    std::string workspace;
    std::string depth_dir;
    std::string output;
    pipeline::PanoramaStageOptions options;
    std::string ground_truth;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "panorama",
      "Warp, stitch and fuse the photos' depth maps into a two-layer panorama with normals "
      "(master.exr and previews)");
  cmd->add_option("workspace", args->workspace,
                  "Workspace with images/ and sparse/ (sparse stage output or a synthetic capture)")
      ->required();
  cmd->add_option("--depth", args->depth_dir,
                  "Folder holding depth/<photo>.exr (dense stage output); default: the workspace "
                  "itself (ground-truth depth of a synthetic capture)");
  cmd->add_option("-o,--output", args->output, "Output folder")->required();
  AddDescribedOption(cmd, "--pano-width", args->options, args->options.pano_width);
  AddDescribedOption(cmd, "--max-pano-width", args->options, args->options.max_auto_width);
  AddDescribedOption(cmd, "--solve-width", args->options, args->options.stitch.solve_width);
  AddDescribedOption(cmd, "--blend-depth-tolerance", args->options, args->options.stitch.blend_depth_tolerance);
  AddDescribedOption(cmd, "--front-support", args->options, args->options.stitch.front_support);
  AddDescribedOption(cmd, "--seam-blend-length", args->options, args->options.stitch.seam_blend_length);
  AddDescribedOption(cmd, "--depth-smooth-radius", args->options, args->options.depth_smooth.radius);
  AddDescribedOption(cmd, "--depth-smooth-iterations", args->options, args->options.depth_smooth.iterations);
  cmd->add_flag("--no-gap-fill", "Leave the front layer's gaps inside the photos' field of view empty")
      ->each([args](const std::string&) { args->options.fill_front_gaps = false; });
  cmd->add_flag("--front-only", "Front layer only (no back layer)")
      ->each([args](const std::string&) { args->options.back_layer = false; });
  AddDescribedOption(cmd, "--min-edge-depth-ratio", args->options, args->options.warp.min_edge_depth_ratio);
  cmd->add_flag("--no-seal", "Leave the quads fusion leaves open (tears seen from the centre)")
      ->each([args](const std::string&) { args->options.seal_tears = false; });
  cmd->add_flag("--no-gc", "Stitch without the geometric-consistency cost")
      ->each([args](const std::string&) { args->options.stitch.lambda_gc = 0.0; });
  AddDescribedOption(cmd, "--sky-depth", args->options, args->options.sky_depth_m);
  cmd->add_option("--ground-truth", args->ground_truth,
                  "A synthetic capture's ground_truth/panorama.exr (same size) to compare with");
  AddDescribedOption(cmd, "--threads", args->options, args->options.num_threads);
  cmd->callback([args] {
    pipeline::PanoramaStageOptions options = args->options;
    options.stitch.solve_height = options.stitch.solve_width / 2;
    const std::string depth_dir = args->depth_dir.empty() ? args->workspace : args->depth_dir;
    pipeline::PanoramaStageReport r;
    const TwoLayerPanorama pano =
        pipeline::RunPanoramaStage(args->workspace, depth_dir, args->output, options, &r);
    std::printf(
        "panorama: %d photos -> %dx%d, front coverage %.3f, back nodes %ld (+%ld hallucinated), "
        "sky nodes %ld\n"
        "seconds: load %.2f, warp %.2f, stitch front %.2f, back %.2f, fuse %.2f, normals %.2f, "
        "write %.2f, total %.2f\n",
        r.num_photos, r.width, r.height, r.front_coverage,
        r.fuse.back_nodes_in - r.fuse.back_nodes_redundant, r.fuse.back_nodes_hallucinated,
        r.normals.sky_nodes, r.seconds_load, r.seconds_warp, r.seconds_stitch_front,
        r.seconds_stitch_back, r.seconds_fuse, r.seconds_normals, r.seconds_write,
        r.seconds_total);
    if (!args->ground_truth.empty()) {
      Image8 map;
      const pipeline::GroundTruthComparison c =
          pipeline::CompareWithGroundTruthFile(pano, args->ground_truth, &map);
      io::WritePng(args->output + "/preview/ground_truth_comparison.png", map);
      std::printf(
          "ground truth: front within 3%%: %.4f of %ld covered pixels (coverage %.4f); back node "
          "behind %.4f of %ld second-surface pixels near depth edges; front links across depth "
          "edges: %ld of %ld (%.5f)\n",
          c.FrontAccuracy(), c.front_covered, c.FrontCoverage(), c.BackNearEdges(),
          c.back_edge_pixels, c.edge_pairs_linked, c.edge_pairs, c.LinksAcrossEdges());
    }
  });
}

}  // namespace casual3d::cli
