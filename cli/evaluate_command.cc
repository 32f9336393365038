// `casual3d evaluate <capture> <3d-photo> [more 3d photos] [-o report.html]
// [--json out.json] [--width 900] [--photos names...] [--holdout-every N]`:
// virtual rephotography (paper Sec. 6.3) of one or more 3D photos of the same
// capture, with a self-contained HTML report and a JSON summary.

#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli/command.h"
#include "reconstruct/eval/evaluate.h"
#include "reconstruct/eval/report.h"
#include "reconstruct/io/file_util.h"

namespace casual3d::cli {

void AddEvaluateCommand(CLI::App& app) {
  struct Args {
    std::string capture;
    std::vector<std::string> photo3d;
    std::string html = "report.html";
    std::string json;
    eval::EvaluateOptions options;
    eval::ReportOptions report;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "evaluate",
      "Virtual rephotography: render 3D photos from the photos' poses and compare them with the "
      "photos (error, completeness, PSNR, SSIM; depth error on synthetic captures)");
  cmd->add_option("capture", args->capture,
                  "The capture: photo folder, capture folder or COLMAP workspace")
      ->required();
  cmd->add_option(
         "photo3d", args->photo3d,
         "3D photos to evaluate (reconstruct output folder, master .exr, package folder or "
         ".c3d); several are compared side by side (ablations)")
      ->required();
  cmd->add_option("-o,--output", args->html, "HTML report to write (one self-contained file)")
      ->capture_default_str();
  cmd->add_option("--json", args->json, "Also write the figures as JSON to this file");
  cmd->add_option("--width", args->options.width,
                  "Width of the rephotographs in pixels (the camera is scaled); 0 = photo size")
      ->capture_default_str();
  cmd->add_option("--photos", args->options.photos,
                  "Photos to evaluate, by file name or index in the sorted model (default: the "
                  "3D photo's held-out photos, else all)");
  cmd->add_option("--holdout-every", args->options.holdout_every,
                  "Evaluate photos 0, N, 2N, ... (LLFF protocol: 8) when --photos is not given")
      ->capture_default_str();
  cmd->add_option("--shift", args->options.metrics.shift_radius_px,
                  "Half-size of the shiftable window, pixels")
      ->capture_default_str();
  cmd->add_option("--threads", args->options.num_threads, "Worker threads; 0 = all cores")
      ->capture_default_str();
  cmd->callback([args] {
    if (const std::string why = args->options.Check(); !why.empty())
      throw std::invalid_argument("evaluate: --" + why);
    const std::filesystem::path html(args->html);
    if (!html.parent_path().empty() && !std::filesystem::is_directory(html.parent_path()))
      throw std::runtime_error(args->html + ": the folder " + html.parent_path().string() +
                               " does not exist (create it or choose another -o)");
    std::vector<eval::PhotoModelEvaluation> evals;
    for (const std::string& p : args->photo3d) {
      evals.push_back(eval::EvaluatePhoto3d(args->capture, p, args->options));
      const eval::PhotoModelEvaluation& e = evals.back();
      std::printf("%s: %zu photos, error %.4f, completeness %.3f, PSNR %.2f dB, SSIM %.3f",
                  p.c_str(), e.photos.size(), e.mean_error, e.mean_completeness, e.mean_psnr_db,
                  e.mean_ssim);
      if (e.has_depth)
        std::printf(", depth median rel. error %.4f, within 3%% %.3f", e.mean_depth_median_rel,
                    e.mean_depth_within);
      std::printf("\n");
      for (const eval::PhotoEvaluation& q : e.photos)
        std::printf("  %-24s error %.4f completeness %.3f PSNR %6.2f SSIM %.3f%s\n", q.name.c_str(),
                    q.metrics.error, q.metrics.completeness, q.metrics.psnr_db, q.metrics.ssim,
                    q.held_out ? " (held out)" : "");
    }
    io::WriteFileAtomic(args->html, eval::RenderHtmlReport(args->capture, evals, args->report));
    std::printf("report: %s\n", args->html.c_str());
    if (!args->json.empty()) {
      io::WriteFileAtomic(args->json, eval::RenderJsonReport(args->capture, evals, args->options));
      std::printf("json: %s\n", args->json.c_str());
    }
  });
}

}  // namespace casual3d::cli
