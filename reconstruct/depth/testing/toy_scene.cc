#include "reconstruct/depth/testing/toy_scene.h"

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>

#include "reconstruct/geometry/colmap_model.h"
#include "reconstruct/io/exr_io.h"
#include "reconstruct/io/file_util.h"
#include "reconstruct/io/image_io.h"

namespace casual3d::depth::testing {
namespace {

float Hash(int x, int y, unsigned seed) {
  uint32_t h = static_cast<uint32_t>(x) * 374761393u + static_cast<uint32_t>(y) * 668265263u + seed * 2246822519u;
  h = (h ^ (h >> 13)) * 1274126177u;
  h ^= h >> 16;
  return (h & 0xffffff) / static_cast<float>(0xffffff);
}

float ValueNoise(double x, double y, unsigned seed) {
  const double fx = std::floor(x), fy = std::floor(y);
  const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
  double tx = x - fx, ty = y - fy;
  tx = tx * tx * (3 - 2 * tx);
  ty = ty * ty * (3 - 2 * ty);
  const double a = Hash(ix, iy, seed), b = Hash(ix + 1, iy, seed), c = Hash(ix, iy + 1, seed),
               d = Hash(ix + 1, iy + 1, seed);
  return static_cast<float>((a + (b - a) * tx) + ((c + (d - c) * tx) - (a + (b - a) * tx)) * ty);
}

void Texture(const ToyRect& r, double x, double y, float* rgb) {
  if (r.cells_per_m <= 0) {
    for (int k = 0; k < 3; ++k) rgb[k] = r.color[k];
    return;
  }
  const double s = r.cells_per_m;
  const float n = 0.55f * ValueNoise(x * s, y * s, r.seed) + 0.3f * ValueNoise(x * s * 2.7, y * s * 2.7, r.seed + 7) +
                  0.15f * ValueNoise(x * s * 0.3, y * s * 0.3, r.seed + 13);
  // Each surface has its own palette (hue from its seed), as real objects do.
  const float h0 = Hash(1, 2, r.seed), h1 = Hash(3, 4, r.seed), h2 = Hash(5, 6, r.seed);
  const float m = 0.6f + 0.4f * ValueNoise(x * s * 0.5, y * s * 0.5, r.seed + 3);
  rgb[0] = 0.1f + (0.3f + 0.5f * h0) * n;
  rgb[1] = 0.1f + (0.3f + 0.5f * h1) * n * m;
  rgb[2] = 0.1f + (0.3f + 0.5f * h2) * (1.0f - n);
}

// Nearest hit along the ray C + s * dir (dir.z > 0); returns Z or +inf.
double Cast(const ToyScene& scene, const Eigen::Vector3d& c, const Eigen::Vector3d& dir, float* rgb) {
  double best = std::numeric_limits<double>::infinity();
  for (const ToyRect& r : scene.rects) {
    const double s = (r.z - c.z()) / dir.z();
    if (s <= 0 || r.z >= best) continue;
    const double x = c.x() + s * dir.x(), y = c.y() + s * dir.y();
    if (x < r.x0 || x > r.x1 || y < r.y0 || y > r.y1) continue;
    best = r.z;
    if (rgb) Texture(r, x, y, rgb);
  }
  if (rgb && !std::isfinite(best)) {
    // Smooth, textureless sky.
    const float t = static_cast<float>(0.5 + 0.5 * dir.y() / dir.norm());
    rgb[0] = 0.55f + 0.2f * t;
    rgb[1] = 0.7f + 0.15f * t;
    rgb[2] = 0.95f;
  }
  return best;
}

}  // namespace

ToyScene ToyScene::Default() {
  ToyScene s;
  s.rects.push_back({6.0, -20, 20, -0.9, 20, 6.0, 11});   // Wall, open to the sky above y = -0.9.
  s.rects.push_back({2.0, -0.55, 0.25, -0.35, 0.45, 22.0, 23});  // Board.
  s.rects.push_back({1.2, 0.32, 0.37, -3, 3, 40.0, 37});     // Pole (thin).
  return s;
}

PinholeCamera ToyCamera(const Eigen::Vector3d& c, int w, int h, double f) {
  PinholeCamera cam;
  cam.width = w;
  cam.height = h;
  cam.fx = cam.fy = f;
  cam.cx = w / 2.0;
  cam.cy = h / 2.0;
  cam.R = Eigen::Matrix3d::Identity();
  cam.t = -c;
  return cam;
}

ToyShot Render(const ToyScene& scene, const PinholeCamera& cam, double gain, double offset) {
  ToyShot shot;
  shot.color = ImageF(cam.width, cam.height, 3);
  shot.depth = ImageF(cam.width, cam.height, 1);
  const Eigen::Vector3d c = cam.Center();
  const Eigen::Matrix3d rt = cam.R.transpose();
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      float acc[3] = {0, 0, 0};
      for (int sy = 0; sy < 2; ++sy)
        for (int sx = 0; sx < 2; ++sx) {
          const Eigen::Vector3d d_cam((x + 0.25 + 0.5 * sx - cam.cx) / cam.fx,
                                      (y + 0.25 + 0.5 * sy - cam.cy) / cam.fy, 1.0);
          float rgb[3] = {0, 0, 0};
          Cast(scene, c, rt * d_cam, rgb);
          for (int k = 0; k < 3; ++k) acc[k] += 0.25f * rgb[k];
        }
      for (int k = 0; k < 3; ++k)
        shot.color.at(x, y, k) =
            static_cast<float>(std::min(1.0, std::max(0.0, gain * acc[k] + offset)));
      const Eigen::Vector3d d_cam((x + 0.5 - cam.cx) / cam.fx, (y + 0.5 - cam.cy) / cam.fy, 1.0);
      const double z = Cast(scene, c, rt * d_cam, nullptr);
      // Depth along the optical axis: rays have unit camera-frame Z.
      shot.depth.at(x, y) = static_cast<float>(std::isfinite(z) ? (z - c.z()) : z);
    }
  return shot;
}

DenseView MakeView(const ToyScene& scene, const PinholeCamera& camera, DepthRange range,
                   double gain, double offset, ImageF* depth) {
  ToyShot shot = Render(scene, camera, gain, offset);
  DenseView v;
  v.name = "toy";
  v.camera = camera;
  v.range = range;
  v.full_width = camera.width;
  v.full_height = camera.height;
  v.gray = ImageF(camera.width, camera.height, 1);
  for (size_t i = 0; i < v.gray.size(); ++i) {
    const float* c = shot.color.data() + 3 * i;
    v.gray.data()[i] = 0.299f * c[0] + 0.587f * c[1] + 0.114f * c[2];
  }
  v.color = std::move(shot.color);
  if (depth) *depth = std::move(shot.depth);
  return v;
}

void WriteToyWorkspace(const std::string& dir, const ToyScene& scene, int rows, int cols,
                       double spacing, int w, int h, double f) {
  namespace fs = std::filesystem;
  io::CreateDirectories((fs::path(dir) / "images").string());
  io::CreateDirectories((fs::path(dir) / "sparse").string());
  io::CreateDirectories((fs::path(dir) / "gt").string());
  geometry::SparseModel model;
  geometry::Camera cam;
  cam.camera_id = 1;
  cam.model = geometry::CameraModelId::kPinhole;
  cam.width = w;
  cam.height = h;
  cam.params = {f, f, w / 2.0, h / 2.0};
  model.cameras[1] = cam;
  std::vector<PinholeCamera> cams;
  std::vector<ImageF> depths;
  int id = 1;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c, ++id) {
      const Eigen::Vector3d centre((c - (cols - 1) / 2.0) * spacing, (r - (rows - 1) / 2.0) * spacing, 0.0);
      const PinholeCamera pc = ToyCamera(centre, w, h, f);
      // Mild exposure differences between photos.
      const ToyShot shot = Render(scene, pc, 1.0 + 0.04 * ((id % 3) - 1), 0.01 * ((id % 2) ? 1 : -1));
      char name[32];
      std::snprintf(name, sizeof(name), "%04d", id);
      Image8 rgb(w, h, 3);
      for (size_t i = 0; i < rgb.size(); ++i)
        rgb.data()[i] = static_cast<uint8_t>(std::lround(255.0f * shot.color.data()[i]));
      io::WritePng((fs::path(dir) / "images" / (std::string(name) + ".png")).string(),
                   static_cast<const Image8&>(rgb).view());
      io::WriteExr((fs::path(dir) / "gt" / (std::string(name) + ".exr")).string(),
                   static_cast<const ImageF&>(shot.depth).view(), {"Z"});
      geometry::ModelImage im;
      im.image_id = id;
      im.camera_id = 1;
      im.name = std::string(name) + ".png";
      im.pose.rotation = Eigen::Quaterniond::Identity();
      im.pose.translation = pc.t;
      model.images[id] = im;
      cams.push_back(pc);
      depths.push_back(shot.depth);
    }
  // Sparse points: a grid of surface points per photo, tracked in every photo
  // that sees them unoccluded.
  uint64_t pid = 1;
  for (size_t i = 0; i < cams.size(); ++i) {
    for (int y = 4; y < h; y += 12)
      for (int x = 4; x < w; x += 12) {
        const float d = depths[i].at(x, y);
        if (!std::isfinite(d)) continue;
        geometry::Point3D p;
        p.point3d_id = pid;
        p.xyz = cams[i].Unproject(x, y, d);
        for (size_t j = 0; j < cams.size(); ++j) {
          const Eigen::Vector3d pc = cams[j].R * p.xyz + cams[j].t;
          const double u = cams[j].fx * pc.x() / pc.z() + cams[j].cx;
          const double v = cams[j].fy * pc.y() / pc.z() + cams[j].cy;
          if (u < 0 || v < 0 || u >= w || v >= h) continue;
          const float dj = depths[j].at(static_cast<int>(u), static_cast<int>(v));
          if (!(std::abs(dj - pc.z()) < 0.01 * pc.z())) continue;
          geometry::ModelImage& im = model.images[static_cast<int>(j) + 1];
          geometry::Observation2D ob;
          ob.xy = Eigen::Vector2d(u, v);
          ob.point3d_id = pid;
          p.track.push_back({im.image_id, static_cast<int>(im.points2d.size())});
          im.points2d.push_back(ob);
        }
        if (p.track.size() >= 2) model.points[pid] = p;
        else
          for (auto& te : p.track) model.images[te.image_id].points2d.pop_back();
        ++pid;
      }
  }
  geometry::WriteModelText(model, (fs::path(dir) / "sparse").string());
}

}  // namespace casual3d::depth::testing
