#include "reconstruct/pipeline/panorama_stage.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "encoder/master_file.h"
#include "reconstruct/geometry/colmap_model.h"
#include "reconstruct/io/color_map.h"
#include "reconstruct/io/file_util.h"
#include "reconstruct/pipeline/view_volume.h"
#include "reconstruct/io/image_io.h"
#include "reconstruct/pipeline/panorama_inputs.h"
#include "reconstruct/pipeline/panorama_report.h"
#include "reconstruct/sfm/scene_setup.h"
#include "reconstruct/stitch/smooth_depth.h"
#include "reconstruct/util/log.h"

namespace casual3d::pipeline {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

void WritePreviews(const TwoLayerPanorama& pano, const std::string& dir) {
  io::CreateDirectories(dir);
  const int W = pano.width(), H = pano.height();
  // Previews at most 2048 wide.
  const int step = std::max(1, W / 2048);
  const int pw = W / step, ph = H / step;
  float near = 1e30f;
  for (int l = 0; l < kNumLayers; ++l) {
    const LayerData& layer = pano.layer(l);
    for (size_t i = 0; i < layer.depth_m.size(); ++i)
      if (layer.present[i]) near = std::min(near, layer.depth_m[i]);
  }
  if (!(near < 1e30f)) near = 1.0f;
  for (int l = 0; l < kNumLayers; ++l) {
    const LayerData& layer = pano.layer(l);
    Image8 color(pw, ph, 3, 0), depth(pw, ph, 3, 0);
    for (int y = 0; y < ph; ++y) {
      for (int x = 0; x < pw; ++x) {
        const size_t i = pano.index(x * step, y * step);
        if (!layer.present[i]) continue;
        for (int c = 0; c < 3; ++c) color.at(x, y, c) = layer.rgb[3 * i + c];
        io::DepthRampColor(near / layer.depth_m[i], &depth.at(x, y, 0));
      }
    }
    const std::string name = l == kFront ? "front" : "back";
    io::WritePng(dir + "/" + name + "_color.png", color);
    io::WritePng(dir + "/" + name + "_depth.png", depth);
  }
  Image8 normals(pw, ph, 3, 0), labels(pw, ph, 3, 0);
  const LayerData& front = pano.layer(kFront);
  const LayerData& back = pano.layer(kBack);
  for (int y = 0; y < ph; ++y) {
    for (int x = 0; x < pw; ++x) {
      const size_t i = pano.index(x * step, y * step);
      if (!front.present[i]) continue;
      for (int c = 0; c < 3; ++c) {
        const float n = front.normal[3 * i + c];
        normals.at(x, y, c) = static_cast<uint8_t>(std::lround(127.5f + 127.5f * n));
      }
      // Labels: F grey, B (relabelled front) orange, with a back node: tinted blue.
      const bool b_label = front.label[i] == static_cast<uint8_t>(NodeLabel::kB);
      labels.at(x, y, 0) = b_label ? 230 : 128;
      labels.at(x, y, 1) = b_label ? 140 : 128;
      labels.at(x, y, 2) = back.present[i] ? 255 : 128;
    }
  }
  io::WritePng(dir + "/normals.png", normals);
  io::WritePng(dir + "/labels.png", labels);
}

// The field of view in grey, the front layer's holes in it in red, the rest
// black; at most 2048 wide (a pixel of the preview is red if any pixel it
// stands for is a hole, so that small holes stay visible).
void WriteHolesPreview(const Image8& fov, const Image8& holes, const std::string& path) {
  const int W = fov.width(), H = fov.height();
  const int step = std::max(1, W / 2048);
  Image8 out(W / step, H / step, 3, 0);
  for (int y = 0; y < out.height() * step; ++y) {
    for (int x = 0; x < out.width() * step; ++x) {
      uint8_t* p = &out.at(x / step, y / step, 0);
      if (holes.at(x, y)) {
        p[0] = 230;
        p[1] = 30;
        p[2] = 30;
      } else if (fov.at(x, y) && p[1] == 0) {
        p[0] = p[1] = p[2] = 110;
      }
    }
  }
  io::WritePng(path, out);
}

// The panorama's width: options.pano_width, or when 0 the one the photos'
// angular resolution asks for (AutoPanoramaWidth).
int PanoramaWidth(const geometry::SparseModel& model, const PanoramaStageOptions& options) {
  if (options.pano_width != 0) return options.pano_width;
  std::vector<geometry::Camera> cameras;
  for (const auto& [id, image] : model.images) {
    const auto cam = model.cameras.find(image.camera_id);
    if (cam != model.cameras.end()) cameras.push_back(cam->second);
  }
  const int width = AutoPanoramaWidth(cameras, options.max_auto_width);
  util::LogInfo("panorama: " + std::to_string(width) + "x" + std::to_string(width / 2) +
                " from the photos' angular resolution");
  return width;
}

}  // namespace

int AutoPanoramaWidth(const std::vector<geometry::Camera>& cameras, int max_width) {
  std::vector<double> focal;
  for (const geometry::Camera& c : cameras) {
    const double f = std::sqrt(c.FocalX() * c.FocalY());
    if (std::isfinite(f) && f > 0) focal.push_back(f);
  }
  if (focal.empty()) return std::min(4096, max_width);
  std::nth_element(focal.begin(), focal.begin() + focal.size() / 2, focal.end());
  const double around = 2.0 * kPi * focal[focal.size() / 2];
  const int width = static_cast<int>(std::ceil(around / 1024.0)) * 1024;
  return std::clamp(width, 2048, max_width);
}

PanoramaFrame LoadOrComputeFrame(const std::string& sparse_dir) {
  const fs::path root(sparse_dir);
  if (fs::exists(root / "frame.json"))
    return sfm::ReadPanoramaFrame((root / "frame.json").string());
  if (fs::exists(root / "capture.json")) {
    const std::string path = (root / "capture.json").string();
    try {
      const nlohmann::json j = nlohmann::json::parse(io::ReadFile(path));
      const auto& f = j.at("panorama_frame");
      PanoramaFrame frame;
      for (int k = 0; k < 3; ++k) frame.centre[k] = f.at("centre").at(k).get<double>();
      for (int k = 0; k < 9; ++k) frame.rotation[k] = f.at("rotation").at(k).get<double>();
      return frame;
    } catch (const nlohmann::json::exception& e) {
      throw std::runtime_error(path + ": no valid panorama_frame (" + e.what() + ")");
    }
  }
  const geometry::SparseModel model = geometry::ReadModel((root / "sparse").string());
  return sfm::ComputePanoramaFrame(model, sfm::PanoramaFrameOptions());
}

namespace {

// The photos warped at the panorama's size (`full`) and at the stitch's
// solve size (`coarse`), by index in `photos`, with each photo's centre in
// the panorama frame. Each photo's image and depth map are read, its sky
// given the depth `sky_m`, warped twice and freed, `num_threads` photos at a
// time: the warps, cropped to the photo, are what stays.
void WarpPhotos(const std::vector<PanoramaPhoto>& photos, double sky_m, const PanoramaFrame& frame,
                const PanoramaStageOptions& options, int W, int H, std::vector<warp::WarpedView>* full,
                std::vector<warp::WarpedView>* coarse, std::vector<stitch::ViewGeometry>* geometry) {
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = frame.rotation[3 * r + c];
  const Eigen::Vector3d centre(frame.centre[0], frame.centre[1], frame.centre[2]);
  for (const PanoramaPhoto& p : photos) {
    const Eigen::Vector3d c = R * (p.pose.Center() - centre);
    geometry->push_back({{c.x(), c.y(), c.z()}});
  }
  warp::WarpOptions warp_full = options.warp;
  warp_full.pano_width = W;
  warp_full.pano_height = H;
  warp::WarpOptions warp_coarse = warp_full;
  warp_coarse.pano_width = options.stitch.solve_width;
  warp_coarse.pano_height = options.stitch.solve_height;
  for (const warp::WarpOptions* o : {&warp_full, &warp_coarse})
    if (const Status st = o->Check(); !st.ok()) throw std::invalid_argument("warp options: " + st.message());
  const int n = static_cast<int>(photos.size());
  full->assign(n, {});
  coarse->assign(n, {});
  util::Progress progress("panorama: warping", n);
  ForEachPanoramaPhoto(n, options.num_threads, [&](int i) {
    PanoramaPixels pixels = ReadPanoramaPixels(photos[i]);
    FillSky(sky_m, &pixels.depth);
    const warp::SourceView view{&pixels.rgb, &pixels.depth, photos[i].camera, photos[i].pose};
    (*full)[i] = warp::WarpView(view, frame, warp_full);
    (*coarse)[i] = warp::WarpView(view, frame, warp_coarse);
    progress.Advance();
  });
  progress.Finish();
}

void LogSealed(const fuse::SealStats& seal) {
  util::LogInfo("panorama: sealed " + std::to_string(seal.open_quads_before - seal.open_quads_after) +
                " of " + std::to_string(seal.open_quads_before) + " open quads (" +
                std::to_string(seal.links_made) + " links, " +
                std::to_string(seal.back_nodes_added) + " back nodes); front surfaces: " +
                std::to_string(seal.front_surface_open_quads_before) + " -> " +
                std::to_string(seal.front_surface_open_quads_after) + " open quads; back layer: " +
                std::to_string(seal.back_open_quads_before) + " -> " +
                std::to_string(seal.back_open_quads_after) + " open quads");
}

void LogViewAndCoverage(const ViewHints& hints, bool metric, const PanoramaStageReport& report) {
  util::LogInfo("panorama: opens at yaw " + std::to_string(hints.yaw_deg) + ", pitch " +
                std::to_string(hints.pitch_deg) + ", field of view " + std::to_string(hints.fov_deg) +
                " deg; viewing volume radius " + std::to_string(hints.volume_radius) +
                (metric ? " m" : " (model units)"));
  for (const auto& [what, c] : {std::pair{"field of view", &report.front_fov},
                                std::pair{"footprint", &report.front_footprint}}) {
    util::LogInfo("panorama: front layer covers " + std::to_string(100.0 * c->covered_fraction) +
                  "% of the photos' " + what + "; " + std::to_string(c->num_holes) +
                  " holes, the largest " + std::to_string(100.0 * c->largest_hole_fraction) +
                  "% of it");
  }
}

}  // namespace

TwoLayerPanorama RunPanoramaStage(const std::string& sparse_dir, const std::string& depth_dir,
                                  const std::string& out_dir, const PanoramaStageOptions& options,
                                  PanoramaStageReport* report_out) {
  if (const Status st = options.Check(); !st.ok())
    throw std::invalid_argument("panorama options: " + st.message());
  const auto start = Clock::now();
  PanoramaStageReport report;

  // Load photos, cameras and depth maps.
  auto t = Clock::now();
  const geometry::SparseModel model =
      geometry::ReadModel((fs::path(sparse_dir) / "sparse").string());
  const int W = PanoramaWidth(model, options);
  if (options.stitch.solve_width > W)
    throw std::invalid_argument("panorama options: stitch.solve_width " +
                                std::to_string(options.stitch.solve_width) +
                                " exceeds the panorama width " + std::to_string(W));
  const int H = W / 2;
  report.width = W;
  report.height = H;
  const PanoramaFrame frame = LoadOrComputeFrame(sparse_dir);
  const std::vector<PanoramaPhoto> photos = LoadPanoramaPhotos(model, sparse_dir, depth_dir);
  std::vector<CoverageView> coverage_views;
  for (const PanoramaPhoto& p : photos) coverage_views.push_back({p.camera, p.pose});
  report.num_photos = static_cast<int>(photos.size());
  // Sky (non-finite depth) gets a finite depth beyond everything else.
  report.sky_depth_m = SkyDepth(options.sky_depth_m, photos, options.num_threads);
  report.seconds_load = Seconds(t);

  // Read and warp at the output and at the solve resolution.
  t = Clock::now();
  std::vector<stitch::ViewGeometry> geometry;
  std::vector<warp::WarpedView> full, coarse;
  WarpPhotos(photos, report.sky_depth_m, frame, options, W, H, &full, &coarse, &geometry);
  const Image8 footprint = FootprintMask(full, W, H);
  report.seconds_warp = Seconds(t);

  // Stitch front, then back.
  t = Clock::now();
  stitch::StitchedLayer front, back;
  {
    util::Progress progress("panorama: stitching", options.back_layer ? 2 : 1);
    front = stitch::StitchFront(full, coarse, geometry, W, options.stitch);
    report.seconds_stitch_front = Seconds(t);
    report.seam_blend_front = front.seam_blend;
    progress.Advance();
    if (options.back_layer) {
      t = Clock::now();
      back = stitch::StitchBack(full, coarse, geometry, front, options.stitch);
      report.seconds_stitch_back = Seconds(t);
      report.seam_blend_back = back.seam_blend;
    } else {
      back.rgb = Image8(W, H, 3, 0);
      back.depth_m = ImageF(W, H, 1, 0.0f);
    }
  }
  full.clear();
  coarse.clear();

  // The photos' field of view, from the stitched front layer; its gaps
  // inside the field of view are filled from their rims.
  t = Clock::now();
  double reference_depth = 0.0;
  const Image8 fov = FieldOfViewMask(front.depth_m, frame, coverage_views, 0.0,
                                     options.num_threads, &reference_depth);
  if (options.fill_front_gaps)
    report.front_gaps_filled = FillGapsInside(fov, &front.rgb, &front.depth_m, &front.label);

  // The depth maps' pixel-scale noise, smoothed along each layer's surfaces.
  stitch::SmoothDepthAlongSurfaces(&front.depth_m, options.depth_smooth, options.num_threads);
  stitch::SmoothDepthAlongSurfaces(&back.depth_m, options.depth_smooth, options.num_threads);

  // Fuse and normals.
  fuse::FuseOptions fuse_options = options.fuse;
  if (!options.back_layer) fuse_options.expansion_fraction = 0;
  TwoLayerPanorama pano = fuse::Fuse({&front.rgb, &front.depth_m, &back.rgb, &back.depth_m, frame},
                                     fuse_options, &report.fuse);
  // The stitched layers are in the panorama now; their memory goes to the
  // normals (at 8192x4096, 600 MB).
  front = stitch::StitchedLayer();
  back = stitch::StitchedLayer();
  if (options.seal_tears) {
    report.seal = fuse::SealTears(&pano, options.seal);
    LogSealed(report.seal);
  }
  report.seconds_fuse = Seconds(t);
  t = Clock::now();
  report.normals = normals::ComputeNormals(&pano, options.normals);
  report.seconds_normals = Seconds(t);
  report.front_coverage =
      static_cast<double>(report.fuse.front_nodes) / (static_cast<double>(W) * H);
  Image8 holes;
  report.front_fov = MeasureHoles(pano, kFront, fov, &holes);
  report.front_fov.reference_depth_m = reference_depth;
  report.front_footprint = MeasureHoles(pano, kFront, footprint);
  // Synthetic captures (capture.json) are in metres; COLMAP's models are not.
  const bool metric = fs::exists(fs::path(sparse_dir) / "capture.json");
  // The eye stays where the back layer's growth fills the disocclusions it
  // opens (0.8 of the angle the growth's rings span).
  ViewVolumeOptions view_options = options.view;
  view_options.max_radius_over_near =
      std::max(view_options.min_radius_over_near,
               std::min(view_options.max_radius_over_near, 0.8 * 2.0 * kPi * fuse_options.expansion_fraction));
  pano.view_hints() = ComputeViewHints(pano, fov, coverage_views, frame, metric, view_options);
  LogViewAndCoverage(*pano.view_hints(), metric, report);

  // Write.
  t = Clock::now();
  io::CreateDirectories(out_dir);
  const Status written =
      encoder::WriteMasterFile(pano, (fs::path(out_dir) / "master.exr").string());
  if (!written.ok()) throw std::runtime_error(written.ToString());
  if (options.write_previews) {
    WritePreviews(pano, (fs::path(out_dir) / "preview").string());
    WriteHolesPreview(fov, holes, (fs::path(out_dir) / "preview" / "holes.png").string());
  }
  report.seconds_write = Seconds(t);
  report.seconds_total = Seconds(start);

  io::WriteFileAtomic((fs::path(out_dir) / "panorama.json").string(),
                      PanoramaReportJson(report, options, *pano.view_hints()));
  if (report_out) *report_out = report;
  return pano;
}

}  // namespace casual3d::pipeline
