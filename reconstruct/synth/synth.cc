#include "reconstruct/synth/synth.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "encoder/master_file.h"
#include "reconstruct/geometry/colmap_model.h"
#include "reconstruct/io/exr_io.h"
#include "reconstruct/io/file_util.h"
#include "reconstruct/io/image_io.h"
#include "reconstruct/io/jpeg_exif.h"
#include "reconstruct/synth/clip.h"
#include "reconstruct/synth/default_scene.h"
#include "reconstruct/synth/ground_truth_panorama.h"
#include "reconstruct/synth/ground_truth_two_layer.h"
#include "reconstruct/synth/procedural_texture.h"
#include "reconstruct/synth/render_photo.h"
#include "reconstruct/synth/sparse_points.h"
#include "reconstruct/util/log.h"

namespace casual3d::synth {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

std::string PhotoName(int i) {
  char buf[16];
  std::snprintf(buf, sizeof(buf), "%04d", i);
  return buf;
}

void UpdateRange(const ImageF& image, int channel, double* lo, double* hi) {
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) {
      const float v = image.at(x, y, channel);
      if (std::isfinite(v) && v > 0) {
        *lo = std::min(*lo, static_cast<double>(v));
        *hi = std::max(*hi, static_cast<double>(v));
      }
    }
}

}  // namespace

RigOptions SynthOptions::ResolvedRig() const {
  RigOptions r = RigOptions::Defaults(rig);
  if (width > 0) r.width = width;
  r.height = height > 0 ? height : (width > 0 ? width * 3 / 4 : r.height);
  if (num_photos > 0) r.num_photos = num_photos;
  r.seed = seed;
  return r;
}

Status SynthOptions::Check() const {
  CASUAL3D_RETURN_IF_ERROR(util::CheckFields(*this));
  // The clip's path interpolates orientations about their mean (clip.h):
  // the sphere rig's turn all around has no such mean.
  if (video_frames > 0 && rig == RigKind::kSphere)
    return InvalidArgument(
        "video_frames " + std::to_string(video_frames) +
        ": a video clip follows the partial or walk-around rig, not the sphere rig");
  return ResolvedRig().Check();
}

namespace {

// The photos of a capture, as rendered.
struct RenderedPhotos {
  std::vector<Scene> scenes;  // Per photo (the moving object displaced).
  std::vector<std::string> names;
  std::vector<double> exposures;
  std::vector<Eigen::Vector3d> offsets;  // Of the moving object.
  double depth_lo = std::numeric_limits<double>::infinity(), depth_hi = 0;
};

// Renders the photos into DIR/images (JPEG with a phone's EXIF) and their
// depth maps into DIR/depth.
RenderedPhotos RenderPhotos(const SynthOptions& options, const RigOptions& rig_options, const Rig& rig,
                            const Scene& scene, const std::string& dir) {
  const int n = rig_options.num_photos;
  RenderOptions render;
  render.edge_samples = options.edge_samples;
  render.num_threads = options.num_threads;
  RenderedPhotos out;
  util::Progress progress("synth: rendering photos", n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d offset =
        options.moving_object ? Eigen::Vector3d(options.moving_step_m * i, 0, 0)
                              : Eigen::Vector3d::Zero();
    out.scenes.push_back(scene.Displaced(offset));
    out.offsets.push_back(offset);
    const PhotoRender r = RenderPhoto(out.scenes.back(), rig.camera, rig.poses[i], render);
    DevelopOptions develop;
    const double u = HashToUnit(Hash(options.seed, 0xE4905E, i));
    develop.exposure = std::exp2(options.exposure_jitter_stops * (2.0 * u - 1.0));
    develop.noise_sigma = options.noise_sigma;
    develop.seed = Hash(options.seed, 0x401, i);
    out.exposures.push_back(develop.exposure);
    const Image8 photo = Develop(r.radiance, develop);
    out.names.push_back(PhotoName(i) + ".jpg");
    // EXIF as a phone writes it (5.6 mm wide sensor), so that the sparse
    // stage finds the focal length as it would for real photos.
    io::ExifFields exif;
    exif.make = "casual3d";
    exif.model = std::string("synthetic ") + RigKindName(rig_options.kind);
    exif.focal_plane_px_per_mm = rig.camera.width / 5.6;
    exif.focal_mm = rig.camera.FocalX() / exif.focal_plane_px_per_mm;
    io::WriteFileAtomic(dir + "/images/" + out.names.back(),
                        io::InsertExif(io::EncodeJpeg(photo.view(), {options.jpeg_quality}), exif));
    io::WriteExr(dir + "/depth/" + PhotoName(i) + ".exr", r.depth_m.view(), {"Z"});
    UpdateRange(r.depth_m, 0, &out.depth_lo, &out.depth_hi);
    progress.Advance();
  }
  return out;
}

// Writes the ground-truth sparse model (COLMAP text and binary) into
// DIR/sparse; fills the summary's point count and mean track length.
void WriteGroundTruthSparse(const SynthOptions& options, const Rig& rig, const RenderedPhotos& photos,
                            const std::string& dir, CaptureSummary* summary) {
  SparsePointOptions sparse;
  sparse.step_px = options.sparse_step_px;
  sparse.seed = options.seed;
  sparse.num_threads = options.num_threads;
  const geometry::SparseModel model = MakeGroundTruthModel(photos.scenes, rig, photos.names, sparse);
  geometry::WriteModelText(model, dir + "/sparse");
  geometry::WriteModelBinary(model, dir + "/sparse");
  summary->num_points = model.points.size();
  size_t observations = 0;
  for (const auto& [id, p] : model.points) observations += p.track.size();
  summary->mean_track_length =
      model.points.empty() ? 0.0 : static_cast<double>(observations) / model.points.size();
}

// Writes DIR/ground_truth/panorama.exr (depths as float, colours and
// normals as half floats: enough for 8-bit colour and normals to ~1e-3) and,
// with write_master, master.exr. Returns the panorama's front depth range.
void WriteGroundTruthPanorama(const SynthOptions& options, const Scene& scene, const PanoramaFrame& frame,
                              const TwoLayerOptions& two_layer_options, const std::string& dir,
                              double* pano_lo, double* pano_hi, CaptureSummary* summary) {
  const int pano_w = options.panorama_width, pano_h = options.panorama_width / 2;
  const GroundTruthPanorama gt = RenderGroundTruthPanorama(scene, frame, pano_w, pano_h, options.num_threads);
  const auto& channel_names = PanoramaChannelNames();
  io::ExrWriteOptions exr;
  exr.num_threads = options.num_threads;
  for (int c = 0; c < kNumPanoramaChannels; ++c) {
    exr.channel_types.push_back(c == kFrontZ || c == kBackZ ? io::ExrPixelType::kFloat
                                                            : io::ExrPixelType::kHalf);
  }
  io::WriteExr(dir + "/ground_truth/panorama.exr", gt.pixels.view(),
               std::vector<std::string>(channel_names.begin(), channel_names.end()), exr);
  UpdateRange(gt.pixels, kFrontZ, pano_lo, pano_hi);
  if (options.write_master) {
    const TwoLayerPanorama two_layer = GroundTruthToTwoLayer(gt, two_layer_options);
    const Status status = encoder::WriteMasterFile(two_layer, dir + "/ground_truth/master.exr");
    if (!status.ok()) throw std::runtime_error(status.ToString());
    summary->wrote_master = true;
  }
}

// capture.json: everything a later stage needs to know (no timings, so that
// the bytes are reproducible).
nlohmann::ordered_json CaptureJson(const SynthOptions& options, const RigOptions& rig_options, const Rig& rig,
                                   const PanoramaFrame& frame, const RenderedPhotos& photos,
                                   const TwoLayerOptions& two_layer_options, double pano_lo, double pano_hi,
                                   const CaptureSummary& summary, const ClipSummary* clip) {
  const int n = rig_options.num_photos;
  const int pano_w = options.panorama_width, pano_h = options.panorama_width / 2;
  nlohmann::ordered_json j;
  j["format"] = "casual3d-capture";
  j["version"] = "1.0";
  j["generator"] = "casual3d synth";
  j["scene"] = {{"name", "default"},
                {"depth_min_m", summary.depth_min_m},
                {"depth_max_m", summary.depth_max_m},
                {"panorama_depth_min_m", pano_lo},
                {"panorama_depth_max_m", pano_hi},
                {"sky_depth", "inf"},
                {"up", {0, 1, 0}},
                {"ground_plane_y_m", 0.0}};
  j["rig"] = RigKindName(rig_options.kind);
  j["seed"] = options.seed;
  j["options"] = {{"width", rig_options.width},
                  {"height", rig_options.height},
                  {"photos", n},
                  {"fov_x_deg", rig_options.fov_x_deg},
                  {"radius_m", rig_options.radius_m},
                  {"noise_sigma", options.noise_sigma},
                  {"exposure_jitter_stops", options.exposure_jitter_stops},
                  {"moving_object", options.moving_object},
                  {"moving_step_m", options.moving_step_m},
                  {"panorama_width", pano_w},
                  {"panorama_height", pano_h},
                  {"jpeg_quality", options.jpeg_quality},
                  {"edge_samples", options.edge_samples},
                  {"sparse_step_px", options.sparse_step_px}};
  j["camera"] = {{"model", "PINHOLE"},
                 {"width", rig.camera.width},
                 {"height", rig.camera.height},
                 {"params", rig.camera.params}};
  j["panorama_frame"] = {{"centre", {frame.centre[0], frame.centre[1], frame.centre[2]}},
                         {"rotation", std::vector<double>(frame.rotation, frame.rotation + 9)}};
  j["ground_truth"] = {{"panorama", "ground_truth/panorama.exr"},
                       {"master", options.write_master ? "ground_truth/master.exr" : ""},
                       {"two_layer_sky_depth_m",
                        std::max(two_layer_options.sky_depth_m, 2.0 * pano_hi)},
                       {"tau_dratio", two_layer_options.tau_dratio},
                       {"link_ratio", two_layer_options.link_ratio}};
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d c = rig.poses[i].Center();
    const Eigen::Vector3d& offset = photos.offsets[i];
    list.push_back({{"name", photos.names[i]},
                    {"image_id", i + 1},
                    {"depth", "depth/" + PhotoName(i) + ".exr"},
                    {"centre", {c.x(), c.y(), c.z()}},
                    {"exposure", photos.exposures[i]},
                    {"moving_object_offset_m", {offset.x(), offset.y(), offset.z()}}});
  }
  j["photos"] = list;
  j["sparse_points"] = summary.num_points;
  if (clip != nullptr) {
    nlohmann::ordered_json nearest = nlohmann::ordered_json::array();
    for (const NearestFrame& f : clip->nearest)
      nearest.push_back({{"photo", f.photo},
                         {"frame", f.frame},
                         {"distance_m", f.distance_m},
                         {"angle_deg", f.angle_deg}});
    j["video"] = {{"frames", clip->num_frames},
                  {"frame_names", "video/frame_NNNNNN.jpg"},
                  {"sparse", "video/sparse"},
                  {"nearest_frame", nearest}};
  }
  return j;
}

}  // namespace

CaptureSummary GenerateCapture(const SynthOptions& options, const std::string& dir) {
  if (const Status st = options.Check(); !st.ok()) throw std::invalid_argument(st.message());
  const Clock::time_point start = Clock::now();
  const RigOptions rig_options = options.ResolvedRig();
  const Eigen::Vector3d centre = DefaultRigCentre();
  const Rig rig = MakeRig(rig_options, centre);
  const Scene scene = BuildDefaultScene(options.seed);

  io::CreateDirectories(dir);
  for (const char* sub : {"images", "depth", "sparse", "ground_truth"}) {
    io::CreateDirectories(dir + "/" + sub);
  }

  CaptureSummary summary;
  summary.num_photos = rig_options.num_photos;
  summary.width = rig.camera.width;
  summary.height = rig.camera.height;

  const Clock::time_point photos_start = Clock::now();
  const RenderedPhotos photos = RenderPhotos(options, rig_options, rig, scene, dir);
  summary.seconds_photos = Seconds(photos_start);
  WriteGroundTruthSparse(options, rig, photos, dir, &summary);

  ClipSummary clip;
  if (options.video_frames > 0) {
    ClipOptions clip_options;
    clip_options.num_frames = options.video_frames;
    clip_options.seed = options.seed;
    clip_options.noise_sigma = options.noise_sigma;
    clip_options.exposure_jitter_stops = options.exposure_jitter_stops;
    clip_options.moving_object = options.moving_object;
    clip_options.moving_step_m = options.moving_step_m;
    clip_options.jpeg_quality = options.jpeg_quality;
    clip_options.edge_samples = options.edge_samples;
    clip_options.num_threads = options.num_threads;
    clip = WriteClip(clip_options, rig_options, centre, scene, rig, photos.names, dir);
    summary.video_frames = clip.num_frames;
    summary.seconds_video = clip.seconds;
    summary.video_min_distance_m = std::numeric_limits<double>::infinity();
    for (const NearestFrame& f : clip.nearest) {
      summary.video_max_distance_m = std::max(summary.video_max_distance_m, f.distance_m);
      summary.video_min_distance_m = std::min(summary.video_min_distance_m, f.distance_m);
    }
  }

  // Ground-truth panorama from the rig centre (panorama frame = world axes).
  const Clock::time_point pano_start = Clock::now();
  PanoramaFrame frame;
  for (int k = 0; k < 3; ++k) frame.centre[k] = centre[k];
  double pano_lo = std::numeric_limits<double>::infinity(), pano_hi = 0;
  const TwoLayerOptions two_layer_options;
  WriteGroundTruthPanorama(options, photos.scenes.front(), frame, two_layer_options, dir, &pano_lo, &pano_hi,
                           &summary);
  summary.seconds_panorama = Seconds(pano_start);
  summary.panorama_width = options.panorama_width;
  summary.panorama_height = options.panorama_width / 2;
  summary.depth_min_m = std::min(photos.depth_lo, pano_lo);
  summary.depth_max_m = std::max(photos.depth_hi, pano_hi);

  const nlohmann::ordered_json j = CaptureJson(options, rig_options, rig, frame, photos, two_layer_options,
                                               pano_lo, pano_hi, summary,
                                               options.video_frames > 0 ? &clip : nullptr);
  io::WriteFileAtomic(dir + "/capture.json", j.dump(2) + "\n");
  summary.seconds_total = Seconds(start);
  return summary;
}

}  // namespace casual3d::synth
