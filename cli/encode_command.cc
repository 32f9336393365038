// `casual3d encode <master.exr> -o <package> [--quality Q] [--tile-size N]
// [--levels N] [--omit-level-width W] [--depth-bits B] [--normal-bits B] [--lossy-normals]
// [--normal-mean-error DEG] [--normal-p99-error DEG] [--single-file out.c3d]
// [--max-kb N [--min-quality Q]] [--capture SPARSE_DIR] [--title T]`: turns a master file into a web package
// (spec/package.md), optionally also as one .c3d file.

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "cli/command.h"
#include "cli/described_option.h"
#include "cli/encode_options.h"
#include "cli/viewer_assets.h"
#include "encoder/master_file.h"
#include "encoder/package_fit.h"
#include "encoder/package_writer.h"
#include "reconstruct/pipeline/capture_shape.h"
#include "reconstruct/util/log.h"

namespace casual3d::cli {
namespace {

void RunEncode(const EncodeCommandOptions& o) {
  if (o.output.empty() && o.single_file.empty())
    throw std::runtime_error("encode: give an output folder with -o (and/or --single-file)");
  Status check = o.Check();
  if (!check.ok()) throw std::runtime_error("encode: " + check.message());
  // The capture's advice for the page's info panel, as reconstruct gives it;
  // measured before anything is written so that a wrong folder leaves nothing.
  std::vector<std::string> advice;
  if (!o.capture.empty()) {
    try {
      advice = pipeline::MeasureWorkspaceCaptureShape(o.capture).advice;
    } catch (const std::exception& e) {
      throw std::runtime_error("encode: --capture " + o.capture + ": " + e.what() +
                               " (give the sparse stage output, e.g. <output>/work/sparse)");
    }
  }
  const auto start = std::chrono::steady_clock::now();
  StatusOr<TwoLayerPanorama> pano = encoder::ReadMasterFile(o.master);
  if (!pano.ok()) throw std::runtime_error(pano.status().message());
  const auto read = std::chrono::steady_clock::now();
  encoder::PackageFitOptions fit;
  fit.max_bytes = static_cast<uint64_t>(o.max_kb) * 1024;
  fit.min_color_quality = o.min_quality;
  StatusOr<encoder::PackageFit> fitted = encoder::EncodePackageWithin(*pano, o.package, fit);
  if (!fitted.ok())
    throw std::runtime_error(o.master + ": " + fitted.status().message() +
                             (o.max_kb > 0 ? " (--max-kb, --min-quality)" : ""));
  const encoder::PackageFiles& files = fitted->files;
  const encoder::PackageStats& stats = fitted->stats;
  const auto encoded = std::chrono::steady_clock::now();
  if (o.max_kb > 0) {
    const encoder::PackageOptions& used = fitted->options;
    const bool changed = used.lossy_normals != o.package.lossy_normals ||
                         used.color_quality != o.package.color_quality;
    util::LogInfo(std::string("--max-kb ") + std::to_string(o.max_kb) + ": " +
                  (changed ? "fitted with " : "fits with the given settings, ") +
                  (used.lossy_normals ? "lossy normals" : "lossless normals") + ", colour quality " +
                  std::to_string(static_cast<int>(std::lround(used.color_quality))) + " (" +
                  std::to_string(fitted->encodings) + (fitted->encodings == 1 ? " encoding)" : " encodings)"));
  }
  if (!o.output.empty()) {
    Status s = encoder::WritePackageFolder(files, o.output);
    if (!s.ok()) throw std::runtime_error(s.message());
    if (o.viewer) {
      try {
        WriteViewerPage(o.output, advice, o.title);
      } catch (const std::exception& e) {
        util::LogWarning(std::string("package written without index.html: ") + e.what());
      }
    }
  }
  if (!o.single_file.empty()) {
    Status s = encoder::WritePackageSingleFile(files, o.single_file);
    if (!s.ok()) throw std::runtime_error(s.message());
  }
  auto seconds = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
  std::string levels;
  for (size_t l = 0; l < stats.level_bytes.size(); ++l)
    levels += (l ? ", " : "") + std::to_string(stats.level_bytes[l] / 1024) + " KB";
  util::LogInfo("encoded " + std::to_string(pano->width()) + "x" + std::to_string(pano->height()) +
                " in " + util::FormatDuration(seconds(read, encoded)) + " (read " +
                util::FormatDuration(seconds(start, read)) + "): " +
                std::to_string(stats.num_files) + " files, " +
                std::to_string(stats.total_bytes / 1024) + " KB; levels " + levels);
}

}  // namespace

void AddEncodeCommand(CLI::App& app) {
  auto options = std::make_shared<EncodeCommandOptions>();
  CLI::App* cmd = app.add_subcommand("encode", "Encode a master file (.exr) as a web package");
  cmd->add_option("master", options->master, "Master file (two-layer panorama, OpenEXR)")
      ->required();
  cmd->add_option("-o,--output", options->output, "Output package folder");
  cmd->add_option("--single-file", options->single_file, "Also write the package as one .c3d file");
  AddDescribedOption(cmd, "--quality", *options, options->package.color_quality);
  AddDescribedOption(cmd, "--tile-size", *options, options->package.tile_size);
  AddDescribedOption(cmd, "--levels", *options, options->package.levels);
  AddDescribedOption(cmd, "--omit-level-width", *options, options->package.omit_level_width);
  AddDescribedOption(cmd, "--depth-bits", *options, options->package.depth_bits);
  AddDescribedOption(cmd, "--normal-bits", *options, options->package.normal_bits);
  cmd->add_flag("--lossy-normals", options->package.lossy_normals,
                "Store normals as lossy images within --normal-mean-error and --normal-p99-error "
                "(package version 1.2, which readers before it refuse) instead of lossless codes "
                "of --normal-bits");
  AddDescribedOption(cmd, "--normal-mean-error", *options, options->package.normal_mean_error_deg);
  AddDescribedOption(cmd, "--normal-p99-error", *options, options->package.normal_p99_error_deg);
  AddDescribedOption(cmd, "--max-kb", *options, options->max_kb);
  AddDescribedOption(cmd, "--min-quality", *options, options->min_quality)->needs("--max-kb");
  AddDescribedOption(cmd, "--threads", *options, options->package.num_threads);
  cmd->add_flag("!--no-viewer", options->viewer, "Do not add index.html and the viewer");
  cmd->add_option("--title", options->title,
                  "Title of the viewer page (default: the output folder's name)");
  cmd->add_option("--capture", options->capture,
                  "Sparse stage output (reconstruct's <output>/work/sparse) whose capture advice "
                  "the viewer page's info panel shows, as reconstruct's page does");
  cmd->callback([options] { RunEncode(*options); });
}

}  // namespace casual3d::cli
