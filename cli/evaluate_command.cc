// `casual3d evaluate <capture> <3d-photo> [more 3d photos] [-o report.html]
// [--json out.json] [--width 900] [--photos names...] [--holdout-every N]
// [--labels names...] [--reference NAME:PSNR:SSIM] [--no-viewer-views] [--no-backdrop]
// [--viewer-width 640] [--viewer-height 400] [--viewer-images DIR] [--rephoto-images DIR]
// [--write-cameras cameras.json] [--rendered DIR] [--reference-poses SPARSE_DIR]`:
// virtual rephotography (paper Sec. 6.3) of one or more 3D photos of the same
// capture and what a viewer sees of each (tears, stretched fill), with a
// self-contained HTML report and a JSON summary. --write-cameras and
// --rendered score another renderer's images of the same 3D photo
// (reconstruct/eval/external_renders.h).

#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli/command.h"
#include "cli/described_option.h"
#include "reconstruct/eval/evaluate.h"
#include "reconstruct/eval/external_renders.h"
#include "reconstruct/eval/report.h"
#include "reconstruct/eval/viewer_views_report.h"
#include "reconstruct/io/file_util.h"
#include "reconstruct/io/image_io.h"

namespace casual3d::cli {

namespace {

struct EvaluateArgs {
  std::string capture;
  std::vector<std::string> photo3d;
  std::string html = "report.html";
  std::string json;
  eval::EvaluateOptions options;
  eval::ReportOptions report;
  std::vector<std::string> labels;
  std::vector<std::string> references;
  bool no_viewer_views = false;
  bool no_backdrop = false;
  std::string viewer_images;
  std::string rephoto_images;
  std::string write_cameras;
};

// The flags of `casual3d evaluate`, bound to `args`.
void AddEvaluateFlags(CLI::App* cmd, const std::shared_ptr<EvaluateArgs>& args) {
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
  AddDescribedOption(cmd, "--width", args->options, args->options.width);
  cmd->add_option("--photos", args->options.photos,
                  "Photos to evaluate, by file name or index in the sorted model (the "
                  "reference's with --reference-poses; default: the 3D photo's held-out photos, "
                  "else all)");
  AddDescribedOption(cmd, "--holdout-every", args->options, args->options.holdout_every);
  AddDescribedOption(cmd, "--shift", args->options, args->options.metrics.shift_radius_px);
  AddDescribedOption(cmd, "--threads", args->options, args->options.num_threads);
  cmd->add_option("--labels", args->labels,
                  "Names of the 3D photos in the report, one per 3D photo (default: their paths)");
  cmd->add_option("--reference", args->references,
                  "Published result on the same protocol shown in the report, NAME:PSNR_DB:SSIM "
                  "(repeatable; e.g. LLFF:23.22:0.753)");
  AddDescribedOption(cmd, "--title", args->report, args->report.title);
  cmd->add_flag("--no-backdrop", args->no_backdrop,
                 "Viewer views: the mesh alone, without the backdrop the viewer draws behind "
                 "it (format/backdrop.h); the photos are always rendered without it");
  AddDescribedOption(cmd, "--sheet-stretch", args->options, args->options.viewer.sheet_stretch);
  cmd->add_flag("--no-viewer-views", args->no_viewer_views,
                "Skip the viewer-side measure (tears and stretched fill seen from 17 eyes over "
                "the viewing volume)");
  AddDescribedOption(cmd, "--viewer-width", args->options, args->options.viewer.width);
  AddDescribedOption(cmd, "--viewer-height", args->options, args->options.viewer.height);
  AddDescribedOption(cmd, "--stretch-factor", args->options, args->options.viewer.stretch_factor);
  cmd->add_flag("--derive-view-hints", args->options.viewer.derive_hints,
                "Viewer views: derive the view hints from the panorama even when the 3D photo "
                "carries its own");
  cmd->add_option("--viewer-images", args->viewer_images,
                  "Also write each viewer view's heatmap and their grid as PNG files to this "
                  "folder (prefixed with the 3D photo's number)");
  cmd->add_option("--rephoto-images", args->rephoto_images,
                  "Also write each evaluated photo and its rephotograph, at the evaluated size, "
                  "as PNG files to this folder (<3D photo number>_<photo stem>_photo.png and "
                  "_render.png)");
  cmd->add_option("--write-cameras", args->write_cameras,
                  "Also write the evaluated photos' cameras as JSON (OpenGL view and projection "
                  "matrices in the panorama frame, which is glTF's) for rendering them elsewhere; "
                  "one 3D photo only");
  AddDescribedOption(cmd, "--rendered", args->options, args->options.rendered_dir);
  AddDescribedOption(cmd, "--reference-poses", args->options, args->options.reference_poses);
}

// The checks of the arguments and what follows from them (the references,
// the ablation flags), and the image folders made, before the (long)
// evaluation.
void PrepareEvaluateArgs(EvaluateArgs* args) {
  args->options.viewer_views = !args->no_viewer_views;
  args->options.backdrop = !args->no_backdrop;
  if (const Status st = args->options.Check(); !st.ok())
    throw std::invalid_argument("evaluate: " + st.message());
  if (!args->labels.empty() && args->labels.size() != args->photo3d.size())
    throw std::invalid_argument("--labels: " + std::to_string(args->labels.size()) +
                                " names for " + std::to_string(args->photo3d.size()) +
                                " 3D photos (give one per 3D photo)");
  for (const std::string& r : args->references) {
    const size_t a = r.find(':'), b = r.find(':', a == std::string::npos ? a : a + 1);
    eval::ReferenceResult ref;
    try {
      if (a == std::string::npos || b == std::string::npos) throw std::invalid_argument(r);
      ref.label = r.substr(0, a);
      size_t used = 0;
      ref.psnr_db = std::stod(r.substr(a + 1, b - a - 1), &used);
      if (used != b - a - 1) throw std::invalid_argument(r);
      ref.ssim = std::stod(r.substr(b + 1), &used);
      if (used != r.size() - b - 1) throw std::invalid_argument(r);
    } catch (const std::exception&) {
      throw std::invalid_argument("--reference " + r + ": expected NAME:PSNR_DB:SSIM");
    }
    args->report.references.push_back(ref);
  }
  if (const Status st = args->report.Check(); !st.ok())
    throw std::invalid_argument("evaluate: --" + st.message());
  if (!args->write_cameras.empty() && args->photo3d.size() != 1)
    throw std::invalid_argument("--write-cameras: give exactly one 3D photo (got " +
                                std::to_string(args->photo3d.size()) + ")");
  const std::filesystem::path html(args->html);
  if (!html.parent_path().empty() && !std::filesystem::is_directory(html.parent_path()))
    throw std::runtime_error(args->html + ": the folder " + html.parent_path().string() +
                             " does not exist (create it or choose another -o)");
  // Image folders are made before the (long) evaluation, so that a wrong
  // path fails at once.
  for (const auto& [flag, dir] : {std::pair{"--viewer-images", &args->viewer_images},
                                  std::pair{"--rephoto-images", &args->rephoto_images}}) {
    try {
      if (!dir->empty()) io::CreateDirectories(*dir);
    } catch (const std::exception& e) {
      throw std::runtime_error(std::string(flag) + " " + e.what() + " (choose another folder)");
    }
  }
}

// Prints the figures of 3D photo number k and writes its images where asked.
void ReportEvaluation(size_t k, const eval::PhotoModelEvaluation& e, const EvaluateArgs& args) {
  std::printf(
      "%s: %zu photos, error %.4f, completeness %.3f, PSNR %.2f dB, SSIM %.3f (whole frame "
      "%.2f dB, %.3f)",
      e.label.c_str(), e.photos.size(), e.mean_error, e.mean_completeness, e.mean_psnr_db,
      e.mean_ssim, e.mean_psnr_filled_db, e.mean_ssim_filled);
  if (e.has_depth)
    std::printf(", depth median rel. error %.4f, within 3%% %.3f", e.mean_depth_median_rel,
                e.mean_depth_within);
  std::printf("\n");
  if (e.viewer) {
    std::printf("  %s\n", eval::ViewerViewsSummary(*e.viewer).c_str());
    if (!args.viewer_images.empty()) {
      eval::WriteViewerHeatmaps(*e.viewer, args.viewer_images, std::to_string(k) + "_");
      std::printf("  viewer heatmaps: %s/%zu_viewer_*.png\n", args.viewer_images.c_str(), k);
    }
  }
  if (!args.rephoto_images.empty()) {
    for (const eval::PhotoEvaluation& q : e.photos) {
      const std::string stem = (std::filesystem::path(args.rephoto_images) /
                                (std::to_string(k) + "_" +
                                 std::filesystem::path(q.name).stem().string()))
                                   .string();
      io::WritePng(stem + "_photo.png", q.photo);
      io::WritePng(stem + "_render.png", q.render);
    }
    std::printf("  rephotographs: %s/%zu_*_render.png\n", args.rephoto_images.c_str(), k);
  }
  for (const eval::PhotoEvaluation& q : e.photos)
    std::printf(
        "  %-24s %dx%d error %.4f completeness %.3f PSNR %6.2f SSIM %.3f whole frame %6.2f "
        "%.3f%s\n",
        q.name.c_str(), q.metrics.width, q.metrics.height, q.metrics.error,
        q.metrics.completeness, q.metrics.psnr_db, q.metrics.ssim, q.metrics.psnr_filled_db,
        q.metrics.ssim_filled, q.held_out ? " (held out)" : "");
}

// --write-cameras: the evaluated photos' cameras of the one 3D photo.
void WriteCameras(const std::vector<eval::PhotoModelEvaluation>& evals, const EvaluateArgs& args) {
  if (args.write_cameras.empty()) return;
  std::vector<eval::NamedView> views;
  for (const eval::PhotoEvaluation& q : evals.front().photos) {
    if (q.has_distortion)
      throw std::runtime_error("--write-cameras: photo " + q.name +
                               " has lens distortion, which the cameras file cannot carry "
                               "(evaluate the 3D photo's undistorted workspace)");
    views.push_back({q.name, q.view});
  }
  io::WriteFileAtomic(args.write_cameras,
                      eval::RephotoCamerasJson(views, evals.front().near_m, evals.front().far_m));
  std::printf("cameras: %s\n", args.write_cameras.c_str());
}

void RunEvaluate(EvaluateArgs* args) {
  PrepareEvaluateArgs(args);
  std::vector<eval::PhotoModelEvaluation> evals;
  for (size_t k = 0; k < args->photo3d.size(); ++k) {
    evals.push_back(eval::EvaluatePhoto3d(args->capture, args->photo3d[k], args->options));
    if (!args->labels.empty()) evals.back().label = args->labels[k];
    ReportEvaluation(k, evals.back(), *args);
  }
  WriteCameras(evals, *args);
  io::WriteFileAtomic(args->html, eval::RenderHtmlReport(args->capture, evals, args->report));
  std::printf("report: %s\n", args->html.c_str());
  if (!args->json.empty()) {
    io::WriteFileAtomic(args->json, eval::RenderJsonReport(args->capture, evals, args->options));
    std::printf("json: %s\n", args->json.c_str());
  }
}

}  // namespace

void AddEvaluateCommand(CLI::App& app) {
  auto args = std::make_shared<EvaluateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "evaluate",
      "Virtual rephotography: render 3D photos from the photos' poses and compare them with the "
      "photos (error, completeness, PSNR, SSIM; depth error on synthetic captures)");
  AddEvaluateFlags(cmd, args);
  cmd->callback([args] { RunEvaluate(args.get()); });
}

}  // namespace casual3d::cli
