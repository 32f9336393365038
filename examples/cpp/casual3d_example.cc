// Reads a 3D photo package (a folder or a .c3d file), prints what each of its
// two layers holds and the size of its mesh, then writes a new package from a
// synthetic panorama and reads it back.
//
//   casual3d_example <package> <new-package-folder>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <casual3d/encoder/package_writer.h>
#include <casual3d/encoder/tile_image_codec.h>
#include <casual3d/format/file_source.h>
#include <casual3d/format/mesh_builder.h>
#include <casual3d/format/package_reader.h>
#include <casual3d/format/two_layer.h>
#include <casual3d/format/version.h>

namespace {

using casual3d::Status;
using casual3d::StatusOr;
using casual3d::TwoLayerPanorama;

// Reads level `level` of the package at `path` (folder or .c3d).
StatusOr<TwoLayerPanorama> ReadLevel(const std::string& path, int level,
                                     casual3d::Manifest* manifest) {
  StatusOr<std::unique_ptr<casual3d::FileSource>> source = casual3d::OpenPackage(path);
  if (!source.ok()) return source.status();
  casual3d::ReadOptions options;
  options.level = level;
  options.num_threads = 4;
  return casual3d::ReadPackage(**source, casual3d::encoder::TileImageDecoders(), options,
                               manifest);
}

// Prints the nodes of each layer: how many, their depth range and mean colour.
void PrintLayers(const TwoLayerPanorama& pano) {
  const char* kNames[casual3d::kNumLayers] = {"front", "back"};
  for (int l = 0; l < casual3d::kNumLayers; ++l) {
    const casual3d::LayerData& layer = pano.layer(l);
    long nodes = 0;
    double near_m = INFINITY, far_m = 0, rgb[3] = {0, 0, 0};
    for (size_t i = 0; i < layer.present.size(); ++i) {
      if (!layer.present[i]) continue;
      ++nodes;
      near_m = std::min<double>(near_m, layer.depth_m[i]);
      far_m = std::max<double>(far_m, layer.depth_m[i]);
      for (int c = 0; c < 3; ++c) rgb[c] += layer.rgb[3 * i + c];
    }
    if (nodes == 0) {
      std::printf("  %s: 0 nodes\n", kNames[l]);
      continue;
    }
    std::printf("  %s: %ld nodes, depth %.3f .. %.3f m, mean colour (%.0f, %.0f, %.0f)\n",
                kNames[l], nodes, near_m, far_m, rgb[0] / nodes, rgb[1] / nodes, rgb[2] / nodes);
  }
}

// Reads every level of `path` and prints it with its mesh.
Status Describe(const std::string& path) {
  casual3d::Manifest manifest;
  StatusOr<TwoLayerPanorama> finest = ReadLevel(path, 0, &manifest);
  if (!finest.ok()) return finest.status();
  std::printf("%s: %dx%d, %zu levels, package format %d.%d, written by %s\n", path.c_str(),
              manifest.width, manifest.height, manifest.levels.size(), manifest.version_major,
              manifest.version_minor, manifest.generator.empty() ? "?" : manifest.generator.c_str());
  for (int level = 0; level < static_cast<int>(manifest.levels.size()); ++level) {
    StatusOr<TwoLayerPanorama> pano = level == 0 ? std::move(finest) : ReadLevel(path, level, nullptr);
    if (!pano.ok()) return pano.status();
    StatusOr<casual3d::Mesh> mesh = casual3d::BuildMesh(*pano);
    if (!mesh.ok()) return mesh.status();
    std::printf("level %d: %dx%d, mesh of %zu vertices and %zu triangles\n", level, pano->width(),
                pano->height(), mesh->num_vertices(), mesh->num_triangles());
    PrintLayers(*pano);
  }
  return Status::Ok();
}

// --- A synthetic 3D photo: a ball in front of the walls of a room -----------

constexpr double kRoomHalfSize[3] = {4.0, 1.5, 4.0};  // Metres from the centre.
constexpr double kBallCentre[3] = {0.0, -0.3, -2.0};  // 2 m straight ahead.
constexpr double kBallRadius_m = 0.6;

struct Hit {
  double depth_m;
  double normal[3];
};

// The room's walls, floor and ceiling seen along unit direction `d`.
Hit HitRoom(const casual3d::Vec3d& d) {
  const double dir[3] = {d.x, d.y, d.z};
  Hit hit{INFINITY, {0, 0, 0}};
  for (int axis = 0; axis < 3; ++axis) {
    if (dir[axis] == 0) continue;
    const double t = kRoomHalfSize[axis] / std::abs(dir[axis]);
    if (t < hit.depth_m) {
      hit = {t, {0, 0, 0}};
      hit.normal[axis] = dir[axis] > 0 ? -1.0 : 1.0;  // Facing the centre.
    }
  }
  return hit;
}

// The ball seen along unit direction `d`, if it is in the way.
bool HitBall(const casual3d::Vec3d& d, Hit* hit) {
  const double b = d.x * kBallCentre[0] + d.y * kBallCentre[1] + d.z * kBallCentre[2];
  const double c = kBallCentre[0] * kBallCentre[0] + kBallCentre[1] * kBallCentre[1] +
                   kBallCentre[2] * kBallCentre[2] - kBallRadius_m * kBallRadius_m;
  const double disc = b * b - c;
  if (disc <= 0 || b - std::sqrt(disc) <= 0) return false;  // Missed, or behind the viewer.
  hit->depth_m = b - std::sqrt(disc);
  const double p[3] = {d.x * hit->depth_m, d.y * hit->depth_m, d.z * hit->depth_m};
  for (int i = 0; i < 3; ++i) hit->normal[i] = (p[i] - kBallCentre[i]) / kBallRadius_m;
  return true;
}

void SetNode(TwoLayerPanorama* pano, int layer, size_t i, const Hit& hit, const uint8_t rgb[3]) {
  casual3d::LayerData& data = pano->layer(layer);
  data.present[i] = 1;
  data.depth_m[i] = static_cast<float>(hit.depth_m);
  for (int c = 0; c < 3; ++c) {
    data.rgb[3 * i + c] = rgb[c];
    data.normal[3 * i + c] = static_cast<float>(hit.normal[c]);
  }
  data.label[i] = static_cast<uint8_t>(layer == casual3d::kFront ? casual3d::NodeLabel::kF
                                                                  : casual3d::NodeLabel::kB);
}

// Links node (layer_a at pixel a) and (layer_b at its neighbour b in direction d).
void Connect(TwoLayerPanorama* pano, size_t a, int layer_a, casual3d::Direction d, size_t b,
             int layer_b) {
  using casual3d::Link;
  uint8_t& from = pano->layer(layer_a).links[a];
  uint8_t& to = pano->layer(layer_b).links[b];
  from = casual3d::SetLink(from, d, layer_b == casual3d::kFront ? Link::kFront : Link::kBack);
  to = casual3d::SetLink(to, casual3d::Opposite(d),
                         layer_a == casual3d::kFront ? Link::kFront : Link::kBack);
}

// The front layer sees the ball where it is in the way and the room elsewhere;
// the back layer holds the room behind the ball. The room's surface is linked
// across the ball's outline (front to back), the ball's outline is a depth edge.
TwoLayerPanorama SyntheticPanorama(int width, int height) {
  TwoLayerPanorama pano(width, height);
  std::vector<uint8_t> on_ball(static_cast<size_t>(width) * height, 0);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const size_t i = pano.index(x, y);
      const casual3d::Vec3d d = casual3d::EquirectPixelToDirection(x + 0.5, y + 0.5, width, height);
      const Hit room = HitRoom(d);
      // Walls in a 0.5 m checkerboard of two greys, tinted by the wall's axis.
      const bool light = (static_cast<int>(std::floor(2 * d.x * room.depth_m)) +
                          static_cast<int>(std::floor(2 * d.y * room.depth_m)) +
                          static_cast<int>(std::floor(2 * d.z * room.depth_m))) & 1;
      const uint8_t grey = light ? 200 : 120;
      const uint8_t wall_rgb[3] = {static_cast<uint8_t>(grey - 40 * std::abs(room.normal[0])),
                                   grey, static_cast<uint8_t>(grey - 40 * std::abs(room.normal[2]))};
      Hit ball;
      if (HitBall(d, &ball)) {
        const uint8_t ball_rgb[3] = {230, 120, 30};
        SetNode(&pano, casual3d::kFront, i, ball, ball_rgb);
        SetNode(&pano, casual3d::kBack, i, room, wall_rgb);
        on_ball[i] = 1;
      } else {
        SetNode(&pano, casual3d::kFront, i, room, wall_rgb);
      }
    }
  }
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (casual3d::Direction d : {casual3d::kRight, casual3d::kDown}) {
        int nx, ny;
        if (!pano.Neighbour(x, y, d, &nx, &ny)) continue;
        const size_t a = pano.index(x, y), b = pano.index(nx, ny);
        if (on_ball[a] == on_ball[b]) {
          Connect(&pano, a, casual3d::kFront, d, b, casual3d::kFront);
          if (on_ball[a]) Connect(&pano, a, casual3d::kBack, d, b, casual3d::kBack);
        } else {
          // The room continues behind the ball's outline.
          Connect(&pano, a, on_ball[a] ? casual3d::kBack : casual3d::kFront, d, b,
                  on_ball[b] ? casual3d::kBack : casual3d::kFront);
        }
      }
    }
  }
  return pano;
}

// Writes the synthetic panorama as a package folder at `dir` and checks that
// reading it back gives the same nodes and links, and depths within the
// package's quantization.
Status WriteSynthetic(const std::string& dir) {
  const TwoLayerPanorama pano = SyntheticPanorama(256, 128);
  if (Status s = pano.Validate(); !s.ok()) return s;
  casual3d::encoder::PackageOptions options;
  options.tile_size = 128;
  options.levels = 2;
  StatusOr<casual3d::encoder::PackageFiles> files = casual3d::encoder::EncodePackage(pano, options);
  if (!files.ok()) return files.status();
  if (Status s = casual3d::encoder::WritePackageFolder(*files, dir); !s.ok()) return s;

  casual3d::Manifest manifest;
  StatusOr<TwoLayerPanorama> back = ReadLevel(dir, 0, &manifest);
  if (!back.ok()) return back.status();
  double worst_depth_error = 0;
  for (int l = 0; l < casual3d::kNumLayers; ++l) {
    const casual3d::LayerData& a = pano.layer(l);
    const casual3d::LayerData& b = back->layer(l);
    if (a.present != b.present || a.links != b.links || a.label != b.label) {
      return casual3d::InternalError(dir + ": the nodes or links read back differ from those written");
    }
    for (size_t i = 0; i < a.present.size(); ++i) {
      if (!a.present[i]) continue;
      worst_depth_error =
          std::max(worst_depth_error, std::abs(b.depth_m[i] / a.depth_m[i] - 1.0));
    }
  }
  const double allowed = manifest.depth.MaxRelativeError();
  if (worst_depth_error > allowed * 1.001) {
    return casual3d::InternalError(dir + ": depth read back off by " +
                                   std::to_string(100 * worst_depth_error) + "%");
  }
  std::printf("wrote %s: read back with the same nodes and links, depth within %.4f%% (bound %.4f%%)\n",
              dir.c_str(), 100 * worst_depth_error, 100 * allowed);
  return Status::Ok();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s <package> <new-package-folder>  (casual3d %s)\n", argv[0],
                 casual3d::kVersion);
    return 2;
  }
  Status s = Describe(argv[1]);
  if (s.ok()) s = WriteSynthetic(argv[2]);
  if (s.ok()) s = Describe(argv[2]);
  if (!s.ok()) {
    std::fprintf(stderr, "casual3d_example: %s\n", s.ToString().c_str());
    return 1;
  }
  return 0;
}
