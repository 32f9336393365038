#include "reconstruct/eval/evaluate.h"

#include <algorithm>
#include <cstdio>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <utility>

#include "base/parallel_for.h"
#include "encoder/gltf_export.h"
#include "encoder/master_file.h"
#include "encoder/tile_image_codec.h"
#include "format/backdrop.h"
#include "format/file_source.h"
#include "format/mesh_builder.h"
#include "format/package_reader.h"
#include "reconstruct/eval/external_renders.h"
#include "reconstruct/geometry/colmap_model.h"
#include "reconstruct/io/cv_bridge.h"
#include "reconstruct/io/exr_io.h"
#include "reconstruct/io/file_util.h"
#include "reconstruct/io/image_io.h"
#include "reconstruct/render/photo_renderer.h"
#include "reconstruct/util/log.h"

namespace casual3d::eval {

namespace fs = std::filesystem;

std::vector<int> SelectPhotos(const std::vector<std::string>& names,
                              const std::vector<std::string>& requested, int every,
                              const std::vector<std::string>& holdout) {
  std::vector<int> out;
  auto index_of = [&](const std::string& name) {
    const auto it = std::find(names.begin(), names.end(), name);
    return it == names.end() ? -1 : static_cast<int>(it - names.begin());
  };
  if (!requested.empty()) {
    for (const std::string& r : requested) {
      int index = index_of(r);
      if (index < 0) {
        // Not a name: a decimal index?
        const bool numeric = !r.empty() && std::all_of(r.begin(), r.end(),
                                                       [](char c) { return c >= '0' && c <= '9'; });
        if (!numeric || r.size() > 9)
          throw std::runtime_error(
              "photo '" + r + "': not a registered photo of the 3D photo's model (" +
              std::to_string(names.size()) + " photos; give a name or an index)");
        index = std::stoi(r);
        if (index >= static_cast<int>(names.size()))
          throw std::runtime_error("photo index " + r + " is out of range: the model has " +
                                   std::to_string(names.size()) + " photos (indices 0 to " +
                                   std::to_string(int(names.size()) - 1) + ")");
      }
      out.push_back(index);
    }
  } else if (every > 0) {
    for (int i = 0; i < static_cast<int>(names.size()); i += every) out.push_back(i);
  } else {
    for (const std::string& h : holdout)
      if (const int i = index_of(h); i >= 0) out.push_back(i);
    if (out.empty())
      for (int i = 0; i < static_cast<int>(names.size()); ++i) out.push_back(i);
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

namespace {

double SecondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// The 3D photo's panorama and where its other files are.
struct LoadedPhoto3d {
  TwoLayerPanorama pano;
  fs::path root;  // Output folder (report.json, work/, photo.c3d), may not exist.
  std::string source;
  uint64_t package_bytes = 0;
};

TwoLayerPanorama ReadPackageOrThrow(const std::string& path, int num_threads) {
  auto source = OpenPackage(path);
  if (!source.ok()) throw std::runtime_error(source.status().message());
  ReadOptions read;
  read.num_threads = num_threads;
  auto pano = ReadPackage(**source, encoder::TileImageDecoders(), read);
  if (!pano.ok()) throw std::runtime_error(path + ": " + pano.status().message());
  return std::move(*pano);
}

TwoLayerPanorama ReadMasterOrThrow(const fs::path& path) {
  auto pano = encoder::ReadMasterFile(path.string());
  if (!pano.ok()) throw std::runtime_error(path.string() + ": " + pano.status().message());
  return std::move(*pano);
}

LoadedPhoto3d LoadPhoto3d(const std::string& path, int num_threads) {
  LoadedPhoto3d out;
  const fs::path p(path);
  std::error_code ec;
  if (!fs::exists(p, ec))
    throw std::runtime_error(path +
                             ": no such 3D photo (give the output folder of `casual3d "
                             "reconstruct`, a master .exr, a package folder or a .c3d file)");
  if (fs::is_directory(p) && fs::exists(p / "master.exr")) {
    out.root = p;
    out.source = (p / "master.exr").string();
    out.pano = ReadMasterOrThrow(p / "master.exr");
  } else if (fs::is_directory(p) && fs::exists(p / "manifest.json")) {
    out.root = p.parent_path();
    out.source = path;
    out.pano = ReadPackageOrThrow(path, num_threads);
  } else if (fs::is_regular_file(p) && p.extension() == ".exr") {
    out.root = p.parent_path();
    out.source = path;
    out.pano = ReadMasterOrThrow(p);
  } else if (fs::is_regular_file(p)) {
    out.root = p.parent_path();
    out.source = path;
    out.pano = ReadPackageOrThrow(path, num_threads);
    out.package_bytes = fs::file_size(p, ec);
  } else {
    throw std::runtime_error(path + ": not a 3D photo (no master.exr or manifest.json inside)");
  }
  if (out.package_bytes == 0 && fs::exists(out.root / "photo.c3d", ec))
    out.package_bytes = fs::file_size(out.root / "photo.c3d", ec);
  return out;
}

// Reads the held-out names and the timings per stage that the 3D photo's
// output folder records (report.json of reconstruct, or panorama.json of the
// panorama stage).
void ReadReports(const fs::path& root, PhotoModelEvaluation* eval) {
  const auto parse = [](const fs::path& file) -> nlohmann::json {
    try {
      return nlohmann::json::parse(io::ReadFile(file.string()));
    } catch (const nlohmann::json::exception& e) {
      throw std::runtime_error(file.string() + ": not valid JSON (" + e.what() + ")");
    }
  };
  std::error_code ec;
  if (fs::exists(root / "report.json", ec)) {
    const nlohmann::json j = parse(root / "report.json");
    if (j.contains("holdout") && j["holdout"].is_array())
      for (const auto& n : j["holdout"])
        if (n.is_string()) eval->holdout.push_back(n.get<std::string>());
    if (j.contains("stages") && j["stages"].is_array())
      for (const auto& s : j["stages"])
        if (s.contains("stage") && s.contains("seconds") && s["seconds"].is_number())
          eval->stage_seconds.emplace_back(s["stage"].get<std::string>(),
                                           s["seconds"].get<double>());
  }
  if (eval->stage_seconds.empty() && fs::exists(root / "panorama.json", ec)) {
    const nlohmann::json j = parse(root / "panorama.json");
    if (j.contains("seconds") && j["seconds"].is_object())
      for (const auto& [k, v] : j["seconds"].items())
        if (v.is_number()) eval->stage_seconds.emplace_back("panorama/" + k, v.get<double>());
  }
}

// The workspace (folder with sparse/ and images/) giving the poses.
fs::path FindSparseWorkspace(const fs::path& root, const fs::path& capture) {
  for (const fs::path& ws : {root / "work" / "sparse", capture}) {
    for (const fs::path& model : {ws / "sparse", ws / "sparse" / "0"}) {
      if (HoldsColmapModel(model.string())) return model;
    }
  }
  throw std::runtime_error(
      "no camera poses: neither " + (root / "work" / "sparse" / "sparse").string() + " nor " +
      (capture / "sparse").string() +
      " holds a COLMAP model (evaluate the output folder of `casual3d reconstruct`, or a capture "
      "folder with sparse/)");
}

fs::path FindReferencePhoto(const fs::path& model_dir, const fs::path& capture,
                            const std::string& name) {
  std::error_code ec;
  for (const fs::path& p :
       {model_dir.parent_path() / "images" / name, capture / "images" / name, capture / name})
    if (fs::is_regular_file(p, ec)) return p;
  throw std::runtime_error("photo " + name + ": not found in " +
                           (model_dir.parent_path() / "images").string() + ", " +
                           (capture / "images").string() + " or " + capture.string());
}

// Scale from the 3D photo's model units to the capture's ground-truth units:
// the ratio of the spreads (RMS distance from their mean) of the camera
// centres of the photos both models hold. 1 when the 3D photo uses the
// capture's own model, or when fewer than two photos are shared. A fresh
// structure-from-motion model has an arbitrary scale, so its depths are only
// comparable with the ground truth after this.
double ModelToCaptureScale(const geometry::SparseModel& model, const fs::path& model_dir,
                           const fs::path& capture) {
  std::error_code ec;
  fs::path truth_dir;
  for (const fs::path& d : {capture / "sparse", capture / "sparse" / "0"})
    if (HoldsColmapModel(d.string())) truth_dir = d;
  if (truth_dir.empty() || fs::equivalent(truth_dir, model_dir, ec)) return 1.0;
  const geometry::SparseModel truth = geometry::ReadModel(truth_dir.string());
  std::map<std::string, Eigen::Vector3d> truth_centres;
  for (const auto& [id, image] : truth.images) truth_centres[image.name] = image.pose.Center();
  std::vector<Eigen::Vector3d> a, b;
  for (const auto& [id, image] : model.images) {
    const auto it = truth_centres.find(image.name);
    if (it == truth_centres.end()) continue;
    a.push_back(image.pose.Center());
    b.push_back(it->second);
  }
  if (a.size() < 2) return 1.0;
  const auto spread = [](const std::vector<Eigen::Vector3d>& v) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& c : v) mean += c / static_cast<double>(v.size());
    double sum = 0;
    for (const auto& c : v) sum += (c - mean).squaredNorm();
    return std::sqrt(sum / v.size());
  };
  const double sa = spread(a), sb = spread(b);
  return sa > 0 && sb > 0 ? sb / sa : 1.0;
}

DepthComparison CompareDepth(const ImageF& truth, const render::RenderResult& r, double tolerance,
                             double scale) {
  DepthComparison d;
  const int w = r.depth.width(), h = r.depth.height();
  std::vector<float> rel, ratio;
  rel.reserve(static_cast<size_t>(w) * h);
  ratio.reserve(static_cast<size_t>(w) * h);
  int64_t within = 0;
  for (int y = 0; y < h; ++y) {
    const int ty = std::min(truth.height() - 1, int((y + 0.5) * truth.height() / h));
    for (int x = 0; x < w; ++x) {
      if (!r.mask.at(x, y)) continue;
      const int tx = std::min(truth.width() - 1, int((x + 0.5) * truth.width() / w));
      const float t = truth.at(tx, ty);
      if (!std::isfinite(t) || t <= 0) continue;
      const float z = static_cast<float>(scale * r.depth.at(x, y));
      const float e = std::abs(z - t) / t;
      rel.push_back(e);
      ratio.push_back(z / t);
      within += e <= tolerance;
    }
  }
  d.available = true;
  d.pixels = static_cast<int64_t>(rel.size());
  if (rel.empty()) return d;
  std::nth_element(rel.begin(), rel.begin() + rel.size() / 2, rel.end());
  d.median_relative_error = rel[rel.size() / 2];
  std::nth_element(ratio.begin(), ratio.begin() + ratio.size() / 2, ratio.end());
  d.median_ratio = ratio[ratio.size() / 2];
  d.within_tolerance = double(within) / rel.size();
  return d;
}

}  // namespace

namespace {

// spec/mesh.md's mesh of the 3D photo, its atlas and, for the viewer views
// with options.backdrop, the backdrop the viewer draws behind it.
struct EvaluationMesh {
  Mesh mesh;
  Mesh backdrop;
  Image8 atlas;
};

EvaluationMesh BuildEvaluationMesh(const LoadedPhoto3d& photo3d, const std::string& photo3d_path,
                                   size_t num_selected, const EvaluateOptions& options,
                                   PhotoModelEvaluation* eval) {
  const auto mesh_start = std::chrono::steady_clock::now();
  EvaluationMesh m;
  auto built = BuildMesh(photo3d.pano);
  if (!built.ok()) throw std::runtime_error(photo3d.source + ": " + built.status().message());
  m.mesh = std::move(*built);
  m.atlas = encoder::BuildColorAtlas(photo3d.pano);
  eval->mesh_triangles = m.mesh.indices.size() / 3;
  if (options.backdrop && options.viewer_views) {
    auto built_backdrop = BuildBackdrop(photo3d.pano);
    if (!built_backdrop.ok())
      throw std::runtime_error(photo3d.source + ": backdrop: " + built_backdrop.status().message());
    m.backdrop = std::move(*built_backdrop);
    eval->backdrop_triangles = m.backdrop.num_triangles();
  }
  util::LogInfo("evaluate: " + photo3d_path + ": mesh of " +
                std::to_string(eval->mesh_triangles) + " triangles (and " +
                std::to_string(eval->backdrop_triangles) + " of the backdrop) in " +
                std::to_string(SecondsSince(mesh_start)) + " s; " +
                std::to_string(num_selected) + " photos");
  return m;
}

// What a viewer sees (viewer_views.h), with the backdrop appended to the
// mesh for it; the mesh alone again afterwards, for the rephotographs.
void EvaluateViewerSide(const LoadedPhoto3d& photo3d, const std::string& photo3d_path,
                        const EvaluateOptions& options, EvaluationMesh* m, PhotoModelEvaluation* eval) {
  const auto viewer_start = std::chrono::steady_clock::now();
  ViewerViewsOptions viewer = options.viewer;
  viewer.num_threads = options.num_threads;
  viewer.keep_images = viewer.keep_images && options.keep_images;
  Mesh& mesh = m->mesh;
  // Array sizes of the mesh alone (colours may be absent).
  const size_t sizes[5] = {mesh.positions.size(), mesh.normals.size(), mesh.uvs.size(),
                           mesh.colors.size(), mesh.indices.size()};
  if (options.backdrop) {
    viewer.vertex_colors_from_triangle = eval->mesh_triangles;
    AppendMesh(m->backdrop, &mesh);
  }
  eval->viewer = EvaluateViewerViews(photo3d.pano, mesh, std::as_const(m->atlas).view(),
                                     photo3d.pano.view_hints(), viewer);
  mesh.positions.resize(sizes[0]);
  mesh.normals.resize(sizes[1]);
  mesh.uvs.resize(sizes[2]);
  mesh.colors.resize(sizes[3]);
  mesh.indices.resize(sizes[4]);
  m->backdrop = Mesh();
  util::LogInfo("evaluate: " + photo3d_path + ": 17 viewer views in " +
                std::to_string(SecondsSince(viewer_start)) + " s");
}

// The model the photos' poses come from, its photo names sorted, and each
// name's image.
struct PosedPhotos {
  fs::path model_dir;
  geometry::SparseModel model;
  std::vector<std::string> names;
  std::map<std::string, const geometry::ModelImage*> by_name;
};

// Fills the names and the by-name index of posed->model.
void IndexPosedPhotos(PosedPhotos* posed) {
  posed->names.clear();
  posed->by_name.clear();
  for (const auto& [id, image] : posed->model.images) {
    posed->names.push_back(image.name);
    posed->by_name[image.name] = &image;
  }
  std::sort(posed->names.begin(), posed->names.end());
  if (posed->names.empty())
    throw std::runtime_error(posed->model_dir.string() + ": the model has no registered photos");
}

void ReadPosedPhotos(const fs::path& model_dir, PosedPhotos* posed) {
  posed->model_dir = model_dir;
  try {
    posed->model = geometry::ReadModel(model_dir.string());
  } catch (const std::exception& e) {
    throw std::runtime_error(model_dir.string() + ": " + e.what());
  }
  IndexPosedPhotos(posed);
}

// With options.reference_poses: the reference's photos, posed in the 3D
// photo's world by aligning `own` (the 3D photo's model) to the reference over
// the photos both hold other than the evaluated ones; `selected` receives
// the evaluated photos' indices among the reference's names.
PosedPhotos PosedFromReference(const PosedPhotos& own, const EvaluateOptions& options,
                               PhotoModelEvaluation* eval, std::vector<int>* selected) {
  PosedPhotos ref;
  ReadPosedPhotos(FindReferenceModel(options.reference_poses), &ref);
  *selected = SelectPhotos(ref.names, options.photos, options.holdout_every, eval->holdout);
  std::set<std::string> evaluated;
  for (const int i : *selected) evaluated.insert(ref.names[i]);
  ReferenceAlignment alignment;
  ref.model = PosesFromReference(own.model, ref.model, evaluated, own.model_dir.string(),
                                 ref.model_dir.string(), &alignment);
  IndexPosedPhotos(&ref);
  char line[320];
  std::snprintf(line, sizeof(line),
                "evaluate: poses from %s, aligned to %s by %d common photos: scale %.4g, "
                "residuals %.3f deg and %.4g (reference units) on average",
                ref.model_dir.c_str(), own.model_dir.c_str(), alignment.num_common,
                alignment.model_to_reference.scale, alignment.mean_rotation_error_deg,
                alignment.mean_centre_error);
  util::LogInfo(line);
  eval->reference_alignment = alignment;
  eval->poses_from = ref.model_dir.string() + " (aligned to " + own.model_dir.string() + " by " +
                     std::to_string(alignment.num_common) + " photos)";
  return ref;
}

// The photo `index` of `posed` at the evaluated width, as the capture holds
// it, and its camera scaled alike.
Image8 ReferencePhoto(const PosedPhotos& posed, const fs::path& capture, const std::string& name,
                      const EvaluateOptions& options, geometry::Camera* camera) {
  const geometry::ModelImage& image = *posed.by_name.at(name);
  const auto cam_it = posed.model.cameras.find(image.camera_id);
  if (cam_it == posed.model.cameras.end())
    throw std::runtime_error(posed.model_dir.string() + ": photo " + name +
                             " refers to a missing camera");
  const geometry::Camera& full = cam_it->second;
  const fs::path photo_path = FindReferencePhoto(posed.model_dir, capture, name);
  const Image8 photo_full = io::ReadImage(photo_path.string());
  if (photo_full.width() != full.width || photo_full.height() != full.height)
    throw std::runtime_error(photo_path.string() + ": " + std::to_string(photo_full.width()) +
                             "x" + std::to_string(photo_full.height()) +
                             " pixels but its camera is " + std::to_string(full.width) + "x" +
                             std::to_string(full.height) +
                             " (compare with the photos the 3D photo was reconstructed from)");
  const double scale = options.width > 0 ? double(options.width) / full.width : 1.0;
  *camera = scale == 1.0 ? full : full.Scaled(scale);
  Image8 photo(camera->width, camera->height, 3);
  if (scale == 1.0) {
    photo = photo_full;
  } else {
    cv::Mat dst = io::ToMat(photo);
    cv::resize(io::ToMat(photo_full), dst, dst.size(), 0, 0,
               scale < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
  }
  return photo;
}

// The means over the evaluated photos (depth over those with ground truth).
void AddMeans(PhotoModelEvaluation* eval) {
  const double n = static_cast<double>(eval->photos.size());
  int depth_n = 0;
  for (const PhotoEvaluation& pe : eval->photos) {
    eval->mean_error += pe.metrics.error / n;
    eval->mean_completeness += pe.metrics.completeness / n;
    eval->mean_psnr_db += pe.metrics.psnr_db / n;
    eval->mean_ssim += pe.metrics.ssim / n;
    eval->mean_psnr_filled_db += pe.metrics.psnr_filled_db / n;
    eval->mean_ssim_filled += pe.metrics.ssim_filled / n;
    if (pe.depth.available && pe.depth.pixels > 0) {
      ++depth_n;
      eval->mean_depth_median_rel += pe.depth.median_relative_error;
      eval->mean_depth_within += pe.depth.within_tolerance;
    }
  }
  if (depth_n > 0) {
    eval->has_depth = true;
    eval->mean_depth_median_rel /= depth_n;
    eval->mean_depth_within /= depth_n;
  }
}

}  // namespace

PhotoModelEvaluation EvaluatePhoto3d(const std::string& capture_dir,
                                     const std::string& photo3d_path,
                                     const EvaluateOptions& options) {
  if (const Status st = options.Check(); !st.ok())
    throw std::invalid_argument("evaluate: " + st.message());
  const fs::path capture(capture_dir);
  std::error_code ec;
  if (!fs::is_directory(capture, ec))
    throw std::runtime_error(capture_dir +
                             ": not a folder (give the capture's photo or capture folder)");

  if (!options.rendered_dir.empty() && !fs::is_directory(options.rendered_dir, ec))
    throw std::runtime_error(options.rendered_dir +
                             ": not a folder (give the folder holding the renderings made "
                             "elsewhere, one PNG per photo)");

  PhotoModelEvaluation eval;
  eval.label = photo3d_path;
  const int threads = base::ResolveThreads(options.num_threads);
  LoadedPhoto3d photo3d = LoadPhoto3d(photo3d_path, threads);
  eval.source = photo3d.source;
  eval.package_bytes = photo3d.package_bytes;
  eval.pano_width = photo3d.pano.width();
  eval.pano_height = photo3d.pano.height();
  ReadReports(photo3d.root, &eval);

  PosedPhotos posed;
  ReadPosedPhotos(FindSparseWorkspace(photo3d.root, capture), &posed);
  eval.poses_from = posed.model_dir.string();
  std::vector<int> selected;
  if (options.reference_poses.empty()) {
    selected = SelectPhotos(posed.names, options.photos, options.holdout_every, eval.holdout);
  } else {
    posed = PosedFromReference(posed, options, &eval, &selected);
    IndexPosedPhotos(&posed);  // Pointers into this copy's model.
  }
  double depth_scale = 1.0;
  if (fs::is_directory(capture / "depth", ec)) {
    // The reference is in the capture's units: the alignment's scale takes
    // the 3D photo's units there.
    depth_scale = eval.reference_alignment ? eval.reference_alignment->model_to_reference.scale
                                           : ModelToCaptureScale(posed.model, posed.model_dir, capture);
    eval.depth_scale = depth_scale;
  }

  // The mesh and its atlas, unless every rendering comes from elsewhere.
  const bool render_here = options.rendered_dir.empty();
  EvaluationMesh m;
  if (render_here) m = BuildEvaluationMesh(photo3d, photo3d_path, selected.size(), options, &eval);
  if (options.viewer_views && render_here) EvaluateViewerSide(photo3d, photo3d_path, options, &m, &eval);

  render::RenderOptions render_options;
  render_options.num_threads = options.num_threads;
  // The far plane beyond the farthest node, as the viewer sets it: the
  // model's units are arbitrary (COLMAP's), so a fixed far plane could clip.
  double near_m = 0.0, far_m = 0.0;
  if (photo3d.pano.NodeDepthRange(&near_m, &far_m))
    render_options.far_m = std::max(render_options.far_m, 1.5 * far_m);
  eval.near_m = render_options.near_m;
  eval.far_m = render_options.far_m;
  util::Progress progress("rephotography", static_cast<int64_t>(selected.size()));
  eval.error_histogram.assign(options.metrics.histogram_bins, 0);
  for (const int index : selected) {
    const std::string& name = posed.names[index];
    const geometry::ModelImage& image = *posed.by_name.at(name);
    geometry::Camera camera;
    Image8 photo = ReferencePhoto(posed, capture, name, options, &camera);
    PhotoEvaluation pe;
    pe.name = name;
    pe.index = index;
    pe.held_out = std::find(eval.holdout.begin(), eval.holdout.end(), name) != eval.holdout.end();
    pe.view = render::ViewFromPhoto(camera, image.pose, photo3d.pano.frame());
    pe.has_distortion = camera.HasDistortion();
    const auto t = std::chrono::steady_clock::now();
    render::RenderResult r;
    if (render_here) {
      r = render::RenderPhotoView(m.mesh, std::as_const(m.atlas).view(), photo3d.pano.frame(), camera,
                                  image.pose, render_options);
    } else {
      if (pe.has_distortion)
        throw std::runtime_error("photo " + name + ": its camera has lens distortion, which " +
                                 "renderings made elsewhere leave out (evaluate against the "
                                 "undistorted workspace: the 3D photo's work/sparse)");
      ExternalRender ext =
          ReadExternalRender(options.rendered_dir, name, camera.width, camera.height);
      r.color = std::move(ext.color);
      r.mask = std::move(ext.mask);
    }
    pe.seconds_render = SecondsSince(t);
    ImageF error_map;
    pe.metrics = ComputeRephotoMetrics(std::as_const(photo).view(), std::as_const(r.color).view(),
                                       std::as_const(r.mask).view(), options.metrics,
                                       options.keep_images ? &error_map : nullptr);
    const fs::path truth = capture / "depth" / (fs::path(name).stem().string() + ".exr");
    if (render_here && fs::is_regular_file(truth, ec))
      pe.depth = CompareDepth(io::ReadExrChannels(truth.string(), {"Z"}), r,
                              options.depth_tolerance, depth_scale);
    if (options.keep_images) {
      pe.photo = std::move(photo);
      pe.render = std::move(r.color);
      pe.error_map = std::move(error_map);
    }
    for (size_t b = 0; b < eval.error_histogram.size(); ++b)
      eval.error_histogram[b] += pe.metrics.error_histogram[b];
    eval.total_pixels += int64_t{pe.metrics.width} * pe.metrics.height;
    eval.photos.push_back(std::move(pe));
    progress.Advance();
  }
  progress.Finish();
  AddMeans(&eval);
  return eval;
}

}  // namespace casual3d::eval
