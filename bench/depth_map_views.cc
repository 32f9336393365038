// What the dense stage's depth maps support, without the panorama: each
// evaluated photo rendered straight from the k photos nearest its camera,
// each drawn as a mesh of its depth map (one vertex per pixel, cut where
// neighbouring depths differ by more than --cut), the nearest surface kept
// and the colours of the photos within 3% of it averaged, weighted by the
// inverse distance of their cameras (--weights uniform: equally; with --k
// at least the number of source photos, one colour per point whatever the
// eye, as a 3D photo has). The PNGs (RGBA, alpha 0 where no photo
// reaches) are scored by `casual3d evaluate --rendered`; the gap between
// that figure and the 3D photo's own is what the panorama stage loses
// (docs/DECISIONS.md, "Stitch: the nearest surface two photos agree on").
// With --surface MASTER.exr the 3D photo's own mesh is drawn instead and
// each of its pixels coloured from the same photos where their depth maps
// see that point (within 3%): the gap to the 3D photo's own figure is its
// colour's, the gap to the depth maps' figure its surface's. Sky (depth
// not finite) is left undrawn: compare captures without sky, such as fern.
//
//   casual3d evaluate CAPTURE OUT --width 1008 --write-cameras eval.json
//   casual3d evaluate CAPTURE OUT --width W --photos <OUT/work/train/images/*> \
//       --write-cameras sources.json        # W: the depth maps' width
//   depth_map_views eval.json sources.json OUT/work/dense/depth \
//       OUT/work/train/images DIR [--k 8] [--cut 1.05] [--surface OUT/master.exr]
//       [--weights nearest|uniform]
//   casual3d evaluate CAPTURE OUT --width 1008 --rendered DIR

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "encoder/master_file.h"
#include "format/color_atlas.h"
#include "format/image.h"
#include "format/mesh.h"
#include "format/mesh_builder.h"
#include "reconstruct/depth/workspace.h"
#include "reconstruct/eval/external_renders.h"
#include "reconstruct/io/exr_io.h"
#include "reconstruct/io/image_io.h"
#include "reconstruct/render/mesh_renderer.h"

namespace {

using casual3d::Image8;
using casual3d::ImageF;
using casual3d::Mesh;
using casual3d::render::PinholeView;
using casual3d::render::RenderResult;
namespace fs = std::filesystem;

struct NamedView {
  PinholeView view;
  Eigen::Vector3d centre;
};

// The views of a cameras file of `casual3d evaluate --write-cameras` by name,
// with their camera centres.
std::map<std::string, NamedView> ReadCameras(const std::string& path) {
  std::map<std::string, NamedView> out;
  for (casual3d::eval::NamedView& nv : casual3d::eval::ReadRephotoCameras(path))
    out[nv.name] = {nv.view, -nv.view.rotation.transpose() * nv.view.translation};
  return out;
}

// Pixel (x, y) of `view` at camera-frame depth z, in the panorama frame.
Eigen::Vector3d Unproject(const PinholeView& view, double x, double y, double z) {
  const Eigen::Vector3d cam((x - view.cx) / view.fx * z, (y - view.cy) / view.fy * z, z);
  return view.rotation.transpose() * (cam - view.translation);
}

// A photo's depth map as a mesh in the panorama frame, coloured by the photo.
Mesh DepthMapMesh(const NamedView& source, const ImageF& depth, const Image8& rgb, double cut) {
  const int w = depth.width(), h = depth.height();
  Mesh m;
  m.positions.reserve(3 * size_t(w) * h);
  m.colors.reserve(3 * size_t(w) * h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const double z = depth.at(x, y) > 0 ? depth.at(x, y) : 1e-6;
      const Eigen::Vector3d p = Unproject(source.view, x + 0.5, y + 0.5, z);
      for (int c = 0; c < 3; ++c) {
        m.positions.push_back(static_cast<float>(p[c]));
        m.colors.push_back(rgb.at(x, y, c));
      }
    }
  }
  m.normals.assign(m.positions.size(), 0.0f);
  m.uvs.assign(2 * size_t(w) * h, 0.0f);
  const float* d = depth.data();
  auto joined = [&](int a, int b) {
    return d[a] > 0 && d[b] > 0 && std::max(d[a], d[b]) < cut * std::min(d[a], d[b]);
  };
  for (int y = 0; y + 1 < h; ++y) {
    for (int x = 0; x + 1 < w; ++x) {
      const uint32_t i00 = y * w + x, i10 = i00 + 1, i01 = i00 + w, i11 = i01 + 1;
      if (joined(i00, i10) && joined(i00, i01) && joined(i10, i01)) m.indices.insert(m.indices.end(), {i00, i01, i10});
      if (joined(i10, i11) && joined(i01, i11) && joined(i10, i01)) m.indices.insert(m.indices.end(), {i10, i01, i11});
    }
  }
  return m;
}

// The whole of `text` as a number, or an error naming `flag`.
double ParseNumber(const std::string& flag, const char* text) {
  char* end = nullptr;
  const double value = std::strtod(text, &end);
  if (end == text || *end != '\0' || !std::isfinite(value))
    throw std::runtime_error(flag + ": '" + text + "' is not a number");
  return value;
}

// A source photo with its depth map, checked against its camera.
struct Source {
  const NamedView* camera;
  ImageF depth;
  Image8 rgb;
  double weight;
};

Source LoadSource(const std::string& name, const NamedView& camera, const std::string& depth_dir,
                  const std::string& image_dir, double weight) {
  Source s{&camera, casual3d::io::ReadExrChannels(depth_dir + "/" + casual3d::depth::OutputStem(name) + ".exr", {"Z"}),
           casual3d::io::ReadImage(image_dir + "/" + name), weight};
  if (s.depth.width() != camera.view.width || s.depth.height() != camera.view.height ||
      s.rgb.width() != s.depth.width() || s.rgb.height() != s.depth.height())
    throw std::runtime_error(name + ": the photo, its depth map and its camera differ in size (write the "
                             "source cameras with --width equal to the depth maps' width)");
  return s;
}

// The colour the sources give the point `p` (panorama frame): the weighted
// mean of the bilinear colours of those whose depth map sees it within 3%;
// false if none does.
bool ColourFromSources(const std::vector<Source>& sources, const Eigen::Vector3d& p, uint8_t rgb[3]) {
  double sum[3] = {0, 0, 0}, weight = 0;
  for (const Source& s : sources) {
    const PinholeView& v = s.camera->view;
    const Eigen::Vector3d q = v.rotation * p + v.translation;
    if (!(q.z() > 0)) continue;
    const double u = v.fx * q.x() / q.z() + v.cx - 0.5, w = v.fy * q.y() / q.z() + v.cy - 0.5;
    const int ui = static_cast<int>(std::lround(u)), wi = static_cast<int>(std::lround(w));
    if (ui < 0 || wi < 0 || ui >= v.width || wi >= v.height) continue;
    const double d = s.depth.at(ui, wi);
    if (!(d > 0) || std::abs(d - q.z()) > 0.03 * q.z()) continue;
    const int u0 = std::clamp(static_cast<int>(std::floor(u)), 0, v.width - 2);
    const int w0 = std::clamp(static_cast<int>(std::floor(w)), 0, v.height - 2);
    const double fu = std::clamp(u - u0, 0.0, 1.0), fw = std::clamp(w - w0, 0.0, 1.0);
    for (int c = 0; c < 3; ++c)
      sum[c] += s.weight * ((1 - fu) * (1 - fw) * s.rgb.at(u0, w0, c) + fu * (1 - fw) * s.rgb.at(u0 + 1, w0, c) +
                            (1 - fu) * fw * s.rgb.at(u0, w0 + 1, c) + fu * fw * s.rgb.at(u0 + 1, w0 + 1, c));
    weight += s.weight;
  }
  if (!(weight > 0)) return false;
  for (int c = 0; c < 3; ++c) rgb[c] = static_cast<uint8_t>(std::lround(sum[c] / weight));
  return true;
}

int Run(int argc, char** argv) {
  if (argc < 6) {
    std::fprintf(stderr,
                 "usage: depth_map_views EVAL_CAMERAS SOURCE_CAMERAS DEPTH_DIR IMAGE_DIR OUT_DIR [--k N] [--cut R] "
                 "[--surface MASTER.exr] [--weights nearest|uniform]\n");
    return 2;
  }
  double k = 8;
  double cut = 1.05;
  std::string surface;
  bool uniform = false;
  for (int a = 6; a < argc; a += 2) {
    const std::string flag = argv[a];
    if (a + 1 >= argc) throw std::runtime_error(flag + ": needs a value");
    if (flag == "--k") k = ParseNumber(flag, argv[a + 1]);
    else if (flag == "--cut") cut = ParseNumber(flag, argv[a + 1]);
    else if (flag == "--surface") surface = argv[a + 1];
    else if (flag == "--weights") {
      const std::string value = argv[a + 1];
      if (value != "nearest" && value != "uniform") throw std::runtime_error("--weights: give nearest or uniform");
      uniform = value == "uniform";
    } else throw std::runtime_error(flag + ": unknown option (--k N, --cut R, --surface MASTER.exr, --weights W)");
  }
  if (!(k >= 1 && k == std::floor(k))) throw std::runtime_error("--k: give a whole number of photos, at least 1");
  if (!(cut > 1)) throw std::runtime_error("--cut: give a depth ratio above 1 (e.g. 1.05)");
  const auto evaluated = ReadCameras(argv[1]);
  const auto sources = ReadCameras(argv[2]);
  const std::string depth_dir = argv[3], image_dir = argv[4], out_dir = argv[5];
  fs::create_directories(out_dir);
  Mesh surface_mesh;
  Image8 surface_atlas;
  if (!surface.empty()) {
    auto pano = casual3d::encoder::ReadMasterFile(surface);
    if (!pano.ok()) throw std::runtime_error(surface + ": " + pano.status().message());
    auto mesh = casual3d::BuildMesh(*pano);
    if (!mesh.ok()) throw std::runtime_error(surface + ": " + mesh.status().message());
    surface_mesh = std::move(*mesh);
    surface_atlas = casual3d::BuildColorAtlas(*pano);
  }
  casual3d::render::RenderOptions options;
  options.color_source = casual3d::render::ColorSource::kVertexColors;
  options.near_m = 1e-3;
  options.far_m = 1e6;
  for (const auto& [name, target] : evaluated) {
    std::vector<std::pair<double, std::string>> nearest;
    for (const auto& [source_name, source] : sources)
      if (source_name != name) nearest.emplace_back((source.centre - target.centre).norm(), source_name);
    if (nearest.empty()) throw std::runtime_error(name + ": no other photo among the source cameras");
    std::sort(nearest.begin(), nearest.end());
    nearest.resize(std::min<size_t>(nearest.size(), static_cast<size_t>(k)));
    std::vector<Source> loaded;
    for (const auto& [distance, source_name] : nearest)
      loaded.push_back(LoadSource(source_name, sources.at(source_name), depth_dir, image_dir,
                                  uniform ? 1.0 : 1.0 / (distance + 1e-3)));
    const int w = target.view.width, h = target.view.height;
    Image8 out(w, h, 4, 0);
    if (!surface.empty()) {
      // The 3D photo's surface, coloured from the sources where they see it.
      const RenderResult r = casual3d::render::RenderMesh(surface_mesh, std::as_const(surface_atlas).view(),
                                                          target.view, {});
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          if (!r.mask.at(x, y)) continue;
          out.at(x, y, 3) = 255;
          uint8_t rgb[3];
          const bool seen = ColourFromSources(loaded, Unproject(target.view, x + 0.5, y + 0.5, r.depth.at(x, y)), rgb);
          for (int c = 0; c < 3; ++c) out.at(x, y, c) = seen ? rgb[c] : r.color.at(x, y, c);
        }
      }
    } else {
      std::vector<RenderResult> renders;
      for (const Source& s : loaded)
        renders.push_back(casual3d::render::RenderMesh(DepthMapMesh(*s.camera, s.depth, s.rgb, cut),
                                                       casual3d::ImageView<const uint8_t>(), target.view, options));
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          double nearest_z = HUGE_VAL;
          for (const RenderResult& r : renders)
            if (r.mask.at(x, y)) nearest_z = std::min<double>(nearest_z, r.depth.at(x, y));
          double sum[3] = {0, 0, 0}, weight = 0;
          for (size_t i = 0; i < renders.size(); ++i) {
            if (!renders[i].mask.at(x, y) || renders[i].depth.at(x, y) > 1.03 * nearest_z) continue;
            for (int c = 0; c < 3; ++c) sum[c] += loaded[i].weight * renders[i].color.at(x, y, c);
            weight += loaded[i].weight;
          }
          if (!(weight > 0)) continue;
          for (int c = 0; c < 3; ++c) out.at(x, y, c) = static_cast<uint8_t>(std::lround(sum[c] / weight));
          out.at(x, y, 3) = 255;
        }
      }
    }
    const std::string path = (fs::path(out_dir) / casual3d::eval::ExternalRenderName(name)).string();
    casual3d::io::WritePng(path, out);
    std::printf("%s: from %zu photos -> %s\n", name.c_str(), loaded.size(), path.c_str());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return Run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "depth_map_views: error: %s\n", e.what());
    return 1;
  }
}
