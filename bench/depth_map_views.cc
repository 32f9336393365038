// What the dense stage's depth maps support, without the panorama: each
// evaluated photo rendered straight from the k photos nearest its camera,
// each drawn as a mesh of its depth map (one vertex per pixel, cut where
// neighbouring depths differ by more than --cut), the nearest surface kept
// and the colours of the photos within 3% of it averaged, weighted by the
// inverse distance of their cameras. The PNGs (RGBA, alpha 0 where no photo
// reaches) are scored by `casual3d evaluate --rendered`; the gap between
// that figure and the 3D photo's own is what the panorama stage loses
// (docs/DECISIONS.md, "Stitch: the nearest surface two photos agree on").
//
//   casual3d evaluate CAPTURE OUT --width 1008 --write-cameras eval.json
//   casual3d evaluate CAPTURE OUT --width W --photos <OUT/work/train/images/*> \
//       --write-cameras sources.json        # W: the depth maps' width
//   depth_map_views eval.json sources.json OUT/work/dense/depth \
//       OUT/work/train/images DIR [--k 8] [--cut 1.05]
//   casual3d evaluate CAPTURE OUT --width 1008 --rendered DIR

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "format/image.h"
#include "format/mesh.h"
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

// The cameras `casual3d evaluate --write-cameras` writes: OpenGL view
// matrices (column-major, -Z forward, +Y up) in the panorama frame, turned
// into the renderer's +Z forward, +Y down pinhole views.
std::map<std::string, NamedView> ReadCameras(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot read the cameras (write them with `casual3d evaluate --write-cameras`)");
  nlohmann::json j;
  in >> j;
  std::map<std::string, NamedView> out;
  for (const auto& c : j.at("cameras")) {
    const auto& m = c.at("view_matrix");
    Eigen::Matrix3d r;
    Eigen::Vector3d t;
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) r(row, col) = m.at(col * 4 + row).get<double>();
      t[row] = m.at(12 + row).get<double>();
    }
    const Eigen::Matrix3d flip = Eigen::Vector3d(1, -1, -1).asDiagonal();
    NamedView v;
    v.view.rotation = flip * r;
    v.view.translation = flip * t;
    v.view.width = c.at("width");
    v.view.height = c.at("height");
    v.view.fx = c.at("fx");
    v.view.fy = c.at("fy");
    v.view.cx = c.at("cx");
    v.view.cy = c.at("cy");
    v.centre = -v.view.rotation.transpose() * v.view.translation;
    out[c.at("name").get<std::string>()] = v;
  }
  if (out.empty()) throw std::runtime_error(path + ": no cameras");
  return out;
}

// A photo's depth map as a mesh in the panorama frame, coloured by the photo.
Mesh DepthMapMesh(const NamedView& source, const ImageF& depth, const Image8& rgb, double cut) {
  const int w = depth.width(), h = depth.height();
  Mesh m;
  m.positions.reserve(3 * size_t(w) * h);
  m.colors.reserve(3 * size_t(w) * h);
  const Eigen::Matrix3d rt = source.view.rotation.transpose();
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const double z = depth.at(x, y) > 0 ? depth.at(x, y) : 1e-6;
      const Eigen::Vector3d cam((x + 0.5 - source.view.cx) / source.view.fx * z,
                                (y + 0.5 - source.view.cy) / source.view.fy * z, z);
      const Eigen::Vector3d p = rt * (cam - source.view.translation);
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

int Run(int argc, char** argv) {
  if (argc < 6) {
    std::fprintf(stderr,
                 "usage: depth_map_views EVAL_CAMERAS SOURCE_CAMERAS DEPTH_DIR IMAGE_DIR OUT_DIR [--k N] [--cut R]\n");
    return 2;
  }
  int k = 8;
  double cut = 1.05;
  for (int a = 6; a < argc; a += 2) {
    const std::string flag = argv[a];
    if (a + 1 >= argc) throw std::runtime_error(flag + ": needs a value");
    if (flag == "--k") k = std::atoi(argv[a + 1]);
    else if (flag == "--cut") cut = std::atof(argv[a + 1]);
    else throw std::runtime_error(flag + ": unknown option (--k N, --cut R)");
  }
  if (k < 1) throw std::runtime_error("--k: give at least 1 photo");
  if (!(cut > 1)) throw std::runtime_error("--cut: give a depth ratio above 1 (e.g. 1.05)");
  const auto evaluated = ReadCameras(argv[1]);
  const auto sources = ReadCameras(argv[2]);
  const std::string depth_dir = argv[3], image_dir = argv[4], out_dir = argv[5];
  fs::create_directories(out_dir);
  casual3d::render::RenderOptions options;
  options.color_source = casual3d::render::ColorSource::kVertexColors;
  options.near_m = 1e-3;
  options.far_m = 1e6;
  for (const auto& [name, target] : evaluated) {
    std::vector<std::pair<double, std::string>> nearest;
    for (const auto& [source_name, source] : sources)
      if (source_name != name) nearest.emplace_back((source.centre - target.centre).norm(), source_name);
    std::sort(nearest.begin(), nearest.end());
    nearest.resize(std::min<size_t>(nearest.size(), k));
    std::vector<RenderResult> renders;
    std::vector<double> weights;
    for (const auto& [distance, source_name] : nearest) {
      const NamedView& source = sources.at(source_name);
      const std::string stem = fs::path(source_name).stem().string();
      const ImageF depth = casual3d::io::ReadExrChannels(depth_dir + "/" + stem + ".exr", {"Z"});
      const Image8 rgb = casual3d::io::ReadImage(image_dir + "/" + source_name);
      if (depth.width() != source.view.width || depth.height() != source.view.height ||
          rgb.width() != depth.width() || rgb.height() != depth.height())
        throw std::runtime_error(source_name + ": the photo, its depth map and its camera differ in size (write the "
                                 "source cameras with --width equal to the depth maps' width)");
      renders.push_back(casual3d::render::RenderMesh(DepthMapMesh(source, depth, rgb, cut),
                                                             casual3d::ImageView<const uint8_t>(), target.view, options));
      weights.push_back(1.0 / (distance + 1e-3));
    }
    const int w = target.view.width, h = target.view.height;
    Image8 out(w, h, 4, 0);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        double nearest_z = HUGE_VAL;
        for (const RenderResult& r : renders)
          if (r.mask.at(x, y)) nearest_z = std::min<double>(nearest_z, r.depth.at(x, y));
        double sum[3] = {0, 0, 0}, weight = 0;
        for (size_t i = 0; i < renders.size(); ++i) {
          if (!renders[i].mask.at(x, y) || renders[i].depth.at(x, y) > 1.03 * nearest_z) continue;
          for (int c = 0; c < 3; ++c) sum[c] += weights[i] * renders[i].color.at(x, y, c);
          weight += weights[i];
        }
        if (!(weight > 0)) continue;
        for (int c = 0; c < 3; ++c) out.at(x, y, c) = static_cast<uint8_t>(std::lround(sum[c] / weight));
        out.at(x, y, 3) = 255;
      }
    }
    const std::string path = out_dir + "/" + fs::path(name).stem().string() + ".png";
    casual3d::io::WritePng(path, out);
    std::printf("%s: from %zu photos -> %s\n", name.c_str(), renders.size(), path.c_str());
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
