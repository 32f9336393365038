#include "reconstruct/synth/default_scene.h"

#include <utility>
#include <vector>

namespace casual3d::synth {
namespace {

using Eigen::Vector3d;

enum MaterialId : int {
  kGround = 0,
  kStone,
  kRedPaint,
  kRodPaint,
  kBark,
  kPlainWall,
  kBricks,
  kLeaves,
  kFacade,
  kWood,
  kBluePaint,
  kFacadeLight,
  kGreyBricks,
  kNumMaterials
};

Material Noise(Vector3d a, Vector3d b, double frequency) {
  Material m;
  m.kind = TextureKind::kNoise;
  m.color_a = a;
  m.color_b = b;
  m.frequency = frequency;
  return m;
}

std::vector<Material> Materials(uint64_t seed) {
  std::vector<Material> m(kNumMaterials);
  m[kGround] = Noise({0.10, 0.13, 0.05}, {0.36, 0.31, 0.20}, 1.2);
  m[kStone] = Noise({0.22, 0.22, 0.21}, {0.62, 0.60, 0.56}, 6.0);
  m[kRedPaint] = Noise({0.45, 0.06, 0.04}, {0.85, 0.40, 0.12}, 10.0);
  m[kRodPaint] = Noise({0.75, 0.62, 0.12}, {0.95, 0.92, 0.80}, 30.0);
  m[kBark] = Noise({0.10, 0.07, 0.04}, {0.38, 0.27, 0.16}, 5.0);
  m[kPlainWall].kind = TextureKind::kFlat;
  m[kPlainWall].color_a = {0.62, 0.60, 0.57};
  m[kBricks].kind = TextureKind::kBricks;
  m[kBricks].color_a = {0.42, 0.14, 0.07};
  m[kBricks].color_b = {0.70, 0.36, 0.20};
  m[kBricks].cell_m = 0.25;
  m[kLeaves].kind = TextureKind::kLeaves;
  m[kLeaves].color_a = {0.04, 0.12, 0.02};
  m[kLeaves].color_b = {0.22, 0.45, 0.08};
  m[kLeaves].frequency = 4.0;
  m[kFacade].kind = TextureKind::kWindows;
  m[kFacade].color_a = {0.55, 0.50, 0.42};
  m[kFacade].color_b = {0.07, 0.09, 0.13};
  m[kFacade].frequency = 2.0;
  m[kFacade].cell_m = 1.6;
  m[kWood] = Noise({0.28, 0.16, 0.07}, {0.58, 0.40, 0.22}, 8.0);
  m[kBluePaint] = Noise({0.04, 0.12, 0.45}, {0.30, 0.52, 0.88}, 12.0);
  m[kFacadeLight].kind = TextureKind::kWindows;
  m[kFacadeLight].color_a = {0.72, 0.70, 0.64};
  m[kFacadeLight].color_b = {0.10, 0.12, 0.10};
  m[kFacadeLight].frequency = 2.5;
  m[kFacadeLight].cell_m = 1.4;
  m[kGreyBricks].kind = TextureKind::kBricks;
  m[kGreyBricks].color_a = {0.30, 0.27, 0.25};
  m[kGreyBricks].color_b = {0.58, 0.53, 0.47};
  m[kGreyBricks].cell_m = 0.3;
  for (int i = 0; i < kNumMaterials; ++i) m[i].seed = Hash(seed, 0x5C3E, i);
  return m;
}

void AddTree(std::vector<Primitive>* out, double x, double z, double height) {
  out->push_back(MakeCylinder({x, -0.02, z}, {x, 0.62 * height, z}, 0.035 * height, kBark));
  out->push_back(MakeSphere({x, 0.68 * height, z}, 0.28 * height, kLeaves));
  out->push_back(MakeSphere({x + 0.09 * height, 0.86 * height, z + 0.05 * height},
                            0.2 * height, kLeaves));
}

}  // namespace

Scene BuildDefaultScene(uint64_t seed) {
  std::vector<Primitive> p;
  // Ground: a 45 m disc, 1 m thick, top at y = 0.
  p.push_back(MakeCylinder({0, -1.0, 0}, {0, 0.0, 0}, 45.0, kGround));
  p.back().is_ground = true;

  // --- Near objects in the forward view (0.6-2 m from the rig centre). ---
  // Stone pedestal with a ball on top (depth edges against the far scene).
  p.push_back(MakeBox({0.32, 0.45, -1.25}, {0.25, 0.46, 0.2}, 10.0, kStone));
  p.push_back(MakeSphere({0.32, 1.06, -1.25}, 0.15, kRedPaint));
  // A small cube on an 8 mm stand, about 0.75 m away.
  p.push_back(MakeBox({-0.12, 1.25, -0.72}, {0.06, 0.06, 0.06}, 30.0, kWood));
  p.push_back(MakeCylinder({-0.12, -0.01, -0.72}, {-0.12, 1.19, -0.72}, 0.004, kRodPaint));
  // A cluster of thin rods (5-9 mm radius) and a slanted rod.
  const double rods[6][4] = {{-0.72, -1.05, 0.005, 2.2}, {-0.62, -1.22, 0.007, 1.9},
                             {-0.55, -1.02, 0.006, 2.05}, {-0.46, -1.38, 0.009, 1.7},
                             {-0.38, -1.15, 0.005, 2.3}, {-0.85, -1.3, 0.008, 1.85}};
  for (const auto& r : rods) p.push_back(MakeCylinder({r[0], -0.01, r[1]}, {r[0], r[3], r[1]}, r[2], kRodPaint));
  p.push_back(MakeCylinder({-1.0, -0.01, -1.65}, {-0.15, 2.1, -1.3}, 0.01, kBark));
  // A post 1.9 m ahead on the right.
  p.push_back(MakeCylinder({0.78, -0.01, -1.9}, {0.78, 2.4, -1.9}, 0.07, kBark));

  // --- Near objects in the other directions (for the full-sphere rig). ---
  p.push_back(MakeBox({0.0, 0.22, 1.45}, {0.8, 0.23, 0.22}, 0.0, kWood));     // Bench behind.
  p.push_back(MakeBox({1.35, 0.29, 0.2}, {0.3, 0.3, 0.3}, 25.0, kWood));      // Crate right.
  p.push_back(MakeSphere({-1.05, 0.15, 1.0}, 0.36, kStone));                  // Rock left-behind.
  p.push_back(MakeCylinder({-1.3, -0.01, 0.25}, {-1.3, 2.0, 0.25}, 0.006, kRodPaint));
  p.push_back(MakeCylinder({-1.25, -0.01, 0.45}, {-1.25, 1.7, 0.45}, 0.008, kRodPaint));
  p.push_back(MakeCylinder({1.0, -0.01, 1.2}, {1.0, 2.2, 1.2}, 0.05, kBark));

  // --- The large textureless wall (forward left, 6 m away, 7 m x 4 m). ---
  p.push_back(MakeBox({-5.5, 2.0, -6.2}, {3.5, 2.01, 0.15}, 0.0, kPlainWall));

  // --- Far geometry (5-30 m). ---
  p.push_back(MakeBox({8.0, 3.5, -13.0}, {5.0, 3.51, 2.5}, -15.0, kBricks));  // Brick building.
  p.push_back(MakeBox({-2.0, 8.0, -28.0}, {6.0, 8.01, 3.0}, 0.0, kFacade));
  p.push_back(MakeBox({-6.0, 5.0, 22.0}, {6.0, 5.01, 3.0}, 5.0, kFacadeLight));
  p.push_back(MakeBox({20.0, 4.0, 3.0}, {3.0, 4.01, 7.0}, 10.0, kFacade));
  p.push_back(MakeBox({-18.0, 3.0, 6.0}, {2.5, 3.01, 6.0}, -8.0, kGreyBricks));
  p.push_back(MakeBox({12.0, 6.0, 18.0}, {4.0, 6.01, 4.0}, 30.0, kFacadeLight));
  p.push_back(MakeBox({-16.0, 4.5, -16.0}, {4.0, 4.51, 4.0}, 40.0, kGreyBricks));
  AddTree(&p, 2.2, -7.6, 6.0);
  AddTree(&p, -3.8, -13.5, 7.5);
  AddTree(&p, -10.0, 12.0, 7.0);
  AddTree(&p, 9.0, 9.0, 6.5);
  AddTree(&p, -13.0, -4.0, 8.0);
  AddTree(&p, 15.0, -6.0, 6.0);
  AddTree(&p, 2.5, 11.0, 5.5);
  p.push_back(MakeSphere({3.0, -0.3, -5.0}, 0.8, kStone));
  p.push_back(MakeSphere({-2.0, -0.5, 7.0}, 1.0, kStone));
  p.push_back(MakeSphere({6.0, -0.2, 4.0}, 0.6, kStone));
  // A fence on the right: posts every 0.5 m (a repeated structure) and a rail.
  for (int i = 0; i <= 12; ++i) {
    const double z = -3.0 + 0.5 * i;
    p.push_back(MakeCylinder({3.6, -0.01, z}, {3.6, 1.2, z}, 0.035, kWood));
  }
  p.push_back(MakeBox({3.6, 1.05, 0.0}, {0.03, 0.05, 3.1}, 0.0, kWood));

  // --- The moving object: a blue ball 1.7 m ahead. ---
  Primitive ball = MakeSphere({-0.3, 1.5, -1.7}, 0.1, kBluePaint);
  ball.is_moving = true;
  p.push_back(ball);

  return Scene(std::move(p), Materials(seed));
}

}  // namespace casual3d::synth
