// `casual3d reconstruct <photos> -o <out>`: the whole pipeline.

#include <cstdio>
#include <stdexcept>
#include <string>

#include "cli/command.h"
#include "cli/described_option.h"
#include "cli/viewer_assets.h"
#include "reconstruct/pipeline/pipeline.h"
#include "reconstruct/util/log.h"

namespace casual3d::cli {

void AddReconstructCommand(CLI::App& app) {
  struct Args {
    std::string input;
    std::string output;
    std::string from = "sparse";
    std::string to = "encode";
    pipeline::PipelineOptions options;
    double working_megapixels = 1.2;
    int pano_width = 0;
    bool no_near_envelope = false;
    bool no_gc_filter = false;
    bool front_only = false;
    bool debug = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "reconstruct",
      "Turn a folder of photos, a video (or a COLMAP workspace) into a web-ready 3D photo: sparse, dense, "
      "panorama (warp, stitch, fuse, normals) and encode stages, resumable");
  cmd->add_option("input", args->input,
                  "Folder of photos (JPEG, PNG, TIFF, HEIC), a video clip (or a folder holding "
                  "one), or a COLMAP workspace")
      ->required();
  cmd->add_option("-o,--output", args->output,
                  "Output folder: web/ (deployable package with index.html), photo.c3d, "
                  "master.exr, preview/, report.json, work/ (stage caches)")
      ->required();
  cmd->add_option("--from", args->from, "First stage to run: sparse, dense, panorama, encode")
      ->capture_default_str();
  cmd->add_option("--to", args->to, "Last stage to run: sparse, dense, panorama, encode")
      ->capture_default_str();
  cmd->add_flag("--force", args->options.force, "Recompute the selected stages even if cached");
  cmd->add_option("--pano-width", args->pano_width,
                  "Panorama width in pixels (height = width / 2), even, 64..16384; 0 = from the "
                  "photos' angular resolution, at most --max-pano-width")
      ->capture_default_str();
  AddDescribedOption(cmd, "--max-pano-width", args->options.panorama, args->options.panorama.max_auto_width);
  cmd->add_option("--working-megapixels", args->working_megapixels,
                  "Photos are downscaled to about this size before matching and depth")
      ->capture_default_str();
  AddDescribedOption(cmd, "--focal-px", args->options.sparse, args->options.sparse.import.focal_px);
  AddSiftOptions(cmd, &args->options.sparse);
  AddPhotoInputOptions(cmd, &args->options.sparse);
  cmd->add_flag("--no-gap-fill", "Leave the front layer's gaps inside the photos' field of view empty")
      ->each([args](const std::string&) { args->options.panorama.fill_front_gaps = false; });
  cmd->add_flag("--no-near-envelope", args->no_near_envelope,
                "Ablation: dense stage without the near envelope prior (Sec. 4.3.2)");
  cmd->add_flag("--no-gc-filter", args->no_gc_filter,
                "Ablation: without the geometric-consistency filter and stitching cost");
  cmd->add_flag("--front-only", args->front_only, "Ablation: front layer only, no back layer");
  cmd->add_flag("--no-seal", "Ablation: leave the quads fusion leaves open (tears seen from the centre)")
      ->each([args](const std::string&) { args->options.panorama.seal_tears = false; });
  cmd->add_flag("--debug", args->debug, "Write colour-mapped PNGs of the dense intermediates");
  cmd->add_option("--holdout-every", args->options.holdout_every,
                  "Register every photo but build the 3D photo without photos 0, N, 2N, ... "
                  "(sorted names; listed in report.json) for `casual3d evaluate`; 0 = none")
      ->capture_default_str();
  cmd->add_option("--quality", args->options.color_quality, "WebP quality of colour tiles, 0..100")
      ->capture_default_str();
  cmd->add_option("--max-package-kb", args->options.max_package_kb,
                  "Fit the web package's tiles and manifest in this many KB (1024 bytes): lossy normals "
                  "first, then colour quality down to 75; fails naming the smallest size reached. "
                  "0 = no budget")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--threads", args->options.num_threads, "Worker threads; 0 = all cores")
      ->capture_default_str();
  cmd->callback([args] {
    pipeline::PipelineOptions options = args->options;
    if (!pipeline::StageFromName(args->from, &options.from)) {
      throw std::invalid_argument("--from " + args->from +
                                  ": not a stage (sparse, dense, panorama, encode)");
    }
    if (!pipeline::StageFromName(args->to, &options.to)) {
      throw std::invalid_argument("--to " + args->to +
                                  ": not a stage (sparse, dense, panorama, encode)");
    }
    options.sparse.import.working_megapixels = args->working_megapixels;
    options.sparse.input_type = sfm::SparseInputType::kAuto;
    options.dense.use_near_envelope = !args->no_near_envelope;
    options.dense.use_gc_filter = !args->no_gc_filter;
    options.dense.debug = args->debug;
    options.panorama.pano_width = args->pano_width;
    options.panorama.back_layer = !args->front_only;
    if (args->no_gc_filter) options.panorama.stitch.lambda_gc = 0.0;
    // The page is titled after the output folder (the capture's name), not
    // its web/ subfolder.
    const std::string title = FolderName(args->output);
    options.finish_web_package = [title](const std::string& web_dir,
                                    const std::vector<std::string>& capture_advice) {
      // As `casual3d encode`: without a built viewer the package is still
      // complete and valid; say how to get the page. The page's info panel
      // shows the capture's advice.
      try {
        WriteViewerPage(web_dir, capture_advice, title);
      } catch (const std::exception& e) {
        util::LogWarning(std::string(e.what()) + "; wrote the package without index.html");
      }
    };
    const pipeline::PipelineReport report =
        pipeline::RunPipeline(args->input, args->output, options);
    for (const pipeline::StageRun& run : report.stages) {
      std::printf("%-9s %s\n", run.stage.c_str(),
                  run.ran ? (std::to_string(run.seconds).substr(0, 6) + " s").c_str()
                          : (run.cached ? "cached" : "skipped"));
    }
    // The capture's description (its warnings were logged as they came).
    if (!report.capture_advice.empty()) std::printf("capture: %s\n", report.capture_advice[0].c_str());
    if (!report.web_dir.empty()) {
      std::printf("wrote the 3D photo to %s (total %.1f s)\nview it with: casual3d view %s\n",
                  report.web_dir.c_str(), report.seconds_total, report.web_dir.c_str());
    }
  });
}

}  // namespace casual3d::cli
