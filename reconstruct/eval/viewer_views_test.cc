#include "reconstruct/eval/viewer_views.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <set>
#include <utility>

#include "format/backdrop.h"
#include "format/color_atlas.h"
#include "format/mesh_builder.h"
#include "format/testing/test_panoramas.h"
#include "reconstruct/eval/captured_field.h"
#include "reconstruct/eval/viewer_views_report.h"
#include "reconstruct/render/derived_view_hints.h"

namespace casual3d::eval {
namespace {

// Clears every link of node (x, y, front) and the links pointing at it.
void CutLinks(TwoLayerPanorama* pano, int x, int y) {
  for (int d = 0; d < kNumDirections; ++d) {
    int nx, ny;
    if (!pano->Neighbour(x, y, Direction(d), &nx, &ny)) continue;
    uint8_t& links = pano->layer(kFront).links[pano->index(nx, ny)];
    links = SetLink(links, Opposite(Direction(d)), Link::kNone);
  }
  pano->layer(kFront).links[pano->index(x, y)] = 0;
}

// Removes the front node at (x, y) (and the links to it).
void RemoveFrontNode(TwoLayerPanorama* pano, int x, int y) {
  CutLinks(pano, x, y);
  LayerData& f = pano->layer(kFront);
  const size_t i = pano->index(x, y);
  f.present[i] = 0;
  f.depth_m[i] = 0;
  f.label[i] = 0;
  for (int c = 0; c < 3; ++c) f.rgb[3 * i + c] = 0, f.normal[3 * i + c] = 0;
}

struct MeshAndAtlas {
  Mesh mesh;
  Image8 atlas;
};

MeshAndAtlas Build(const TwoLayerPanorama& pano) {
  const StatusOr<Mesh> mesh = BuildMesh(pano);
  EXPECT_TRUE(mesh.ok()) << mesh.status().ToString();
  return {mesh.ok() ? *mesh : Mesh(), BuildColorAtlas(pano)};
}

ViewHints Ahead(double volume_radius) {
  ViewHints h;
  h.yaw_deg = 0;
  h.pitch_deg = 0;
  h.fov_deg = 60;
  h.volume_radius = volume_radius;
  return h;
}

ViewerViewsOptions SmallViews() {
  ViewerViewsOptions o;
  o.width = 320;
  o.height = 200;
  return o;
}

TEST(ViewerViewsTest, CamerasLieOnTheBallAndLookAtTheContent) {
  ViewHints h;
  h.yaw_deg = 30;
  h.pitch_deg = -10;
  h.fov_deg = 50;
  h.volume_radius = 0.25;
  const std::vector<render::GlCamera> cams = ViewerCameras(h);
  ASSERT_EQ(cams.size(), 17u);
  EXPECT_EQ(ViewerCameraNames().size(), 17u);
  std::set<std::vector<long>> distinct;
  int level = 0, above = 0, below = 0;
  for (size_t k = 0; k < cams.size(); ++k) {
    const render::GlCamera& c = cams[k];
    const double r = std::hypot(c.position[0], c.position[1], c.position[2]);
    EXPECT_NEAR(r, k == 0 ? 0.0 : 0.25, 1e-12) << k;
    EXPECT_EQ(c.yaw_deg, 30);
    EXPECT_EQ(c.pitch_deg, -10);
    EXPECT_EQ(c.fov_y_deg, 50);
    const double lat = std::asin(c.position[1] / std::max(r, 1e-30)) * 180 / kPi;
    if (k > 0) {
      level += std::abs(lat) < 1e-9;
      above += std::abs(lat - 45) < 1e-9;
      below += std::abs(lat + 45) < 1e-9;
    }
    distinct.insert({std::lround(c.position[0] * 1e6), std::lround(c.position[1] * 1e6),
                     std::lround(c.position[2] * 1e6)});
  }
  EXPECT_EQ(level, 8);
  EXPECT_EQ(above, 4);
  EXPECT_EQ(below, 4);
  EXPECT_EQ(distinct.size(), 17u);
  // The first boundary eye is straight ahead along the viewing direction (yaw
  // 30 in the horizontal plane), the third 90 degrees to its right.
  const Vec3d ahead = LonLatToDirection(30 * kPi / 180, 0);
  EXPECT_NEAR(cams[1].position[0], 0.25 * ahead.x, 1e-12);
  EXPECT_NEAR(cams[1].position[2], 0.25 * ahead.z, 1e-12);
  const Vec3d right = LonLatToDirection(120 * kPi / 180, 0);
  EXPECT_NEAR(cams[3].position[0], 0.25 * right.x, 1e-12);
  EXPECT_NEAR(cams[3].position[2], 0.25 * right.z, 1e-12);
}

// Content only in longitudes [150, 220] (across the seam), latitudes [-30, 30].
TwoLayerPanorama SeamPanorama() {
  TwoLayerPanorama pano = testing::MakeSpherePanorama(360, 180, 3.0f);
  for (int y = 0; y < 180; ++y)
    for (int x = 0; x < 360; ++x)
      if (!((x >= 330 || x < 40) && y >= 60 && y < 120)) RemoveFrontNode(&pano, x, y);
  EXPECT_TRUE(pano.Validate().ok()) << pano.Validate().ToString();
  return pano;
}

TEST(DeriveViewHintsTest, ContentAcrossTheSeamGivesAWrappedExtent) {
  const TwoLayerPanorama pano = SeamPanorama();
  const ViewHints h = render::DeriveViewHints(pano);
  EXPECT_TRUE(h.Validate().ok()) << h.Validate().ToString();
  EXPECT_NEAR(h.yaw_deg, -175, 1e-9);
  EXPECT_NEAR(h.content_yaw_min_deg, -210, 1e-9);
  EXPECT_NEAR(h.content_yaw_max_deg, -140, 1e-9);
  EXPECT_NEAR(h.content_pitch_min_deg, -30, 1e-9);
  EXPECT_NEAR(h.content_pitch_max_deg, 30, 1e-9);
  EXPECT_NEAR(h.pitch_deg, 0, 1e-9);
  // The widest 4:3 view inside 70 x 60 degrees: 2 atan(tan(35) / (4/3)).
  EXPECT_NEAR(h.fov_deg, 2 * std::atan(std::tan(35 * kPi / 180) * 0.75) * 180 / kPi, 1e-9);
  EXPECT_NEAR(h.volume_radius, render::kDerivedVolumeFraction * 3.0, 1e-6);  // Front depth 3.
  EXPECT_FALSE(h.metric);

  const CapturedField field(pano, h);
  EXPECT_TRUE(field.Contains(LonLatToDirection(-175 * kPi / 180, 0)));
  EXPECT_TRUE(field.Contains(LonLatToDirection(179.9 * kPi / 180, 0.2)));
  EXPECT_TRUE(field.Contains(LonLatToDirection(152 * kPi / 180, -0.2)));
  EXPECT_FALSE(field.Contains(LonLatToDirection(0, 0)));
  EXPECT_FALSE(field.Contains(LonLatToDirection(-130 * kPi / 180, 0)));
  EXPECT_FALSE(field.Contains(LonLatToDirection(-175 * kPi / 180, 40 * kPi / 180)));

  // A whole sphere: the whole circle, looking ahead.
  const ViewHints full = render::DeriveViewHints(testing::MakeSpherePanorama(64, 32, 2.0f));
  EXPECT_EQ(full.content_yaw_min_deg, -180);
  EXPECT_EQ(full.content_yaw_max_deg, 180);
  EXPECT_EQ(full.yaw_deg, 0);
  EXPECT_EQ(full.fov_deg, 120);
}

TEST(CapturedFieldTest, NarrowHolesCountNotchesOfTheOutlineDoNot) {
  // Content over columns 171..340 and rows 86..169 of a 512 x 256 panorama
  // (one pixel a cell); a 3 x 3 hole inside it and a notch 3 rows high,
  // 6 columns deep, cut into its right edge. Closing radius 2 degrees = 3 cells.
  TwoLayerPanorama pano(512, 256);
  LayerData& f = pano.layer(kFront);
  for (int y = 86; y < 170; ++y)
    for (int x = 171; x < 341; ++x) {
      const bool hole = x >= 250 && x < 253 && y >= 120 && y < 123;
      const bool notch = x >= 335 && y >= 130 && y < 133;
      if (hole || notch) continue;
      f.present[pano.index(x, y)] = 1;
      f.depth_m[pano.index(x, y)] = 2.0f;
    }
  ViewHints h = Ahead(0.1);
  h.content_yaw_min_deg = -60;
  h.content_yaw_max_deg = 60;
  h.content_pitch_min_deg = -30;
  h.content_pitch_max_deg = 30;
  const CapturedField field(pano, h, 2.0);
  const auto pixel = [&](double x, double y) { return EquirectPixelToDirection(x, y, 512, 256); };
  EXPECT_TRUE(field.Contains(pixel(251.5, 121.5)));   // The hole: captured.
  EXPECT_FALSE(field.Contains(pixel(338.5, 131.5)));  // The notch: not.
  EXPECT_TRUE(field.Contains(pixel(330.5, 131.5)));   // Content beside it.
  EXPECT_FALSE(field.Contains(pixel(345.5, 131.5)));  // Beyond the outline.
}

TEST(ViewerViewsTest, HoleInsideTheContentTearsTheCentreView) {
  const int w = 256, h = 128;
  TwoLayerPanorama pano = testing::MakeSpherePanorama(w, h, 2.0f);
  // Cut every link of the nodes in columns [124, 134), rows [58, 66): the
  // nodes stay (the content mask is whole) but no triangle touches them.
  const auto cut = [](int x, int y) { return x >= 124 && x < 134 && y >= 58 && y < 66; };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (cut(x, y)) CutLinks(&pano, x, y);
  ASSERT_TRUE(pano.Validate().ok());
  const MeshAndAtlas m = Build(pano);
  const ViewerViewsOptions options = SmallViews();
  const ViewerViewsEvaluation e =
      EvaluateViewerViews(pano, m.mesh, m.atlas.view(), Ahead(0.2), options);
  EXPECT_FALSE(e.hints_derived);
  ASSERT_EQ(e.views.size(), 17u);
  const ViewerViewResult& centre = e.views[0];
  EXPECT_EQ(centre.captured_pixels, options.width * options.height);

  // Expected: the pixels whose direction falls in a pixel quad with two or
  // more cut corners (no triangle), plus half of those with one (one corner
  // triangle of two remains), the latter also the tolerance.
  const render::PinholeView view = render::ViewFromGlCamera(e.views[0].camera, 320, 200);
  double expected = 0, half = 0;
  for (int j = 0; j < 200; ++j)
    for (int i = 0; i < 320; ++i) {
      const Eigen::Vector3d d =
          view.rotation.transpose() *
          Eigen::Vector3d((i + 0.5 - view.cx) / view.fx, (j + 0.5 - view.cy) / view.fy, 1.0);
      double u, v;
      DirectionToEquirectPixel({d.x(), d.y(), d.z()}, w, h, &u, &v);
      const int qx = int(std::floor(u - 0.5)), qy = int(std::floor(v - 0.5));
      const int corners = cut(qx, qy) + cut(qx + 1, qy) + cut(qx, qy + 1) + cut(qx + 1, qy + 1);
      if (corners >= 2) expected += 1;
      if (corners == 1) half += 1;
    }
  expected += half / 2;
  ASSERT_GT(expected, 1000);
  const double total = options.width * options.height;
  EXPECT_NEAR(centre.tear_pixels, expected, half / 2 + 0.01 * expected);
  EXPECT_NEAR(e.centre_tears, expected / total, (half / 2 + 0.01 * expected) / total);
  EXPECT_GT(e.boundary_tears_mean, 0.5 * e.centre_tears);
  EXPECT_EQ(e.centre_stretched, 0.0);

  // The hole filled: no tear from anywhere in the viewing volume.
  testing::LinkByDepthRatio(&pano, 0.75f);
  const MeshAndAtlas filled = Build(pano);
  const ViewerViewsEvaluation f =
      EvaluateViewerViews(pano, filled.mesh, filled.atlas.view(), Ahead(0.2), options);
  EXPECT_EQ(f.centre_tears, 0.0);
  EXPECT_EQ(f.boundary_tears_max, 0.0);
  EXPECT_EQ(f.boundary_stretched_max, 0.0);
}

// The same hole with the backdrop drawn behind the mesh (format/backdrop.h),
// as the viewer draws it: no tear from anywhere in the volume, and the hole
// shows the backdrop's colour (the sphere's), not the background.
TEST(ViewerViewsTest, TheBackdropClosesAHoleFromEverywhere) {
  const int w = 256, h = 128;
  TwoLayerPanorama pano = testing::MakeSpherePanorama(w, h, 2.0f);
  for (int y = 58; y < 66; ++y)
    for (int x = 124; x < 134; ++x) CutLinks(&pano, x, y);
  MeshAndAtlas m = Build(pano);
  const size_t mesh_triangles = m.mesh.num_triangles();
  ViewerViewsOptions options = SmallViews();
  const ViewerViewsEvaluation torn = EvaluateViewerViews(pano, m.mesh, std::as_const(m.atlas).view(), Ahead(0.2), options);
  ASSERT_GT(torn.centre_tears, 0.01);
  const StatusOr<Mesh> backdrop = BuildBackdrop(pano);
  ASSERT_TRUE(backdrop.ok());
  AppendMesh(*backdrop, &m.mesh);
  options.vertex_colors_from_triangle = mesh_triangles;
  const ViewerViewsEvaluation e = EvaluateViewerViews(pano, m.mesh, std::as_const(m.atlas).view(), Ahead(0.2), options);
  EXPECT_EQ(e.centre_tears, 0.0);
  EXPECT_EQ(e.boundary_tears_max, 0.0);
  EXPECT_EQ(e.boundary_stretched_max, 0.0);
  // The centre pixel looks into the hole: drawn in the backdrop's colour.
  const Image8& centre = e.views[0].render;
  const uint8_t* p = &centre.at(160, 100, 0);
  const uint8_t* c = &backdrop->colors[0];
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(p[k], c[k], 2) << k;
}

TEST(ViewerViewsTest, BlackBeyondTheCapturedContentIsNotATear) {
  const TwoLayerPanorama pano = SeamPanorama();
  const MeshAndAtlas m = Build(pano);
  ViewHints h = render::DeriveViewHints(pano);
  h.yaw_deg = -140;  // Looking at the content's edge: half the view is empty.
  const ViewerViewsEvaluation e =
      EvaluateViewerViews(pano, m.mesh, m.atlas.view(), h, SmallViews());
  const ViewerViewResult& centre = e.views[0];
  EXPECT_GT(centre.captured_pixels, 0.3 * 320 * 200);
  EXPECT_LT(centre.captured_pixels, 0.6 * 320 * 200);
  EXPECT_EQ(centre.tear_pixels, 0);
  // Seen from the ball's surface the content's edge moves by a few pixels
  // against the directions measured from the eye: a thin band at most.
  EXPECT_LT(e.boundary_tears_max, 0.01);
}

TEST(ViewerViewsTest, LinkedDepthStepGivesStretchedFill) {
  const int w = 256, h = 128;
  TwoLayerPanorama pano = testing::MakeSpherePanorama(w, h, 8.0f);
  const ViewerViewsOptions options = SmallViews();
  {
    const MeshAndAtlas m = Build(pano);
    const ViewerViewsEvaluation smooth =
        EvaluateViewerViews(pano, m.mesh, m.atlas.view(), Ahead(0.4), options);
    EXPECT_EQ(smooth.centre_stretched, 0.0);
    EXPECT_EQ(smooth.boundary_stretched_max, 0.0);
    EXPECT_EQ(smooth.boundary_tears_max, 0.0);
  }
  // A square plateau at 0.8 m ahead, linked to the sphere at 8 m around it:
  // a skirt of triangles bridging the depth step, which the eye sees
  // stretched as soon as it leaves the centre.
  for (int y = 56; y < 72; ++y)
    for (int x = 120; x < 136; ++x) pano.layer(kFront).depth_m[pano.index(x, y)] = 0.8f;
  testing::LinkByDepthRatio(&pano, 0.0f);
  ASSERT_TRUE(pano.Validate().ok());
  const MeshAndAtlas m = Build(pano);
  const ViewerViewsEvaluation e =
      EvaluateViewerViews(pano, m.mesh, m.atlas.view(), Ahead(0.4), options);
  EXPECT_EQ(e.centre_stretched, 0.0);
  EXPECT_EQ(e.centre_tears, 0.0);
  EXPECT_GT(e.boundary_stretched_max, 0.005);
  EXPECT_GT(e.boundary_stretched_mean, 0.001);
  // The stretched pixels of the view from the right lie around the plateau
  // and the heatmap paints them orange.
  const ViewerViewResult& right = e.views[3];
  EXPECT_GT(right.stretched_pixels, 100);
  const Image8 heat = ViewerHeatmap(right);
  int64_t orange = 0;
  for (int y = 0; y < heat.height(); ++y)
    for (int x = 0; x < heat.width(); ++x)
      orange += heat.at(x, y, 0) == 255 && heat.at(x, y, 1) == 150 && heat.at(x, y, 2) == 0;
  EXPECT_EQ(orange, right.stretched_pixels);
}

TEST(ViewerViewsReportTest, GridHtmlAndJsonCarryEveryView) {
  std::set<std::pair<int, int>> cells;
  for (int k = 0; k < 17; ++k) {
    int column, row;
    ViewerGridCell(k, &column, &row);
    EXPECT_TRUE(column >= 0 && column < 8 && row >= 0 && row < 3) << k;
    cells.insert({column, row});
  }
  EXPECT_EQ(cells.size(), 17u);  // No two views share a cell.

  TwoLayerPanorama pano = testing::MakeSpherePanorama(128, 64, 2.0f);
  for (int y = 28; y < 34; ++y)
    for (int x = 60; x < 66; ++x) CutLinks(&pano, x, y);
  const MeshAndAtlas m = Build(pano);
  ViewerViewsOptions options;
  options.width = 64;
  options.height = 48;
  const ViewerViewsEvaluation e =
      EvaluateViewerViews(pano, m.mesh, m.atlas.view(), Ahead(0.2), options);
  ASSERT_GT(e.views[0].tear_pixels, 0);
  // A thumbnail keeps a single tear visible: reduced 4 times, the red pixels
  // still cover every tear.
  const Image8 thumb = ViewerHeatmapThumbnail(e.views[0], 4);
  EXPECT_EQ(thumb.width(), 16);
  int64_t red = 0;
  for (int y = 0; y < thumb.height(); ++y)
    for (int x = 0; x < thumb.width(); ++x)
      red += thumb.at(x, y, 0) == 255 && thumb.at(x, y, 1) == 0 && thumb.at(x, y, 2) == 0;
  EXPECT_GE(red * 16, e.views[0].tear_pixels);
  const Image8 grid = ViewerHeatmapGrid(e, 4);
  EXPECT_EQ(grid.width(), 8 * 17 + 1);
  EXPECT_EQ(grid.height(), 3 * 13 + 1);

  const std::string html = ViewerViewsHtml(e, 32);
  for (const std::string& name : ViewerCameraNames())
    EXPECT_NE(html.find(">" + name + "<"), std::string::npos) << name;
  const std::string json = ViewerViewsJson(e);
  EXPECT_NE(json.find("\"centre_tears\""), std::string::npos);
  EXPECT_NE(json.find("\"below az 315\""), std::string::npos);
  EXPECT_NE(ViewerViewsSummary(e).find("tears centre"), std::string::npos);
}

}  // namespace
}  // namespace casual3d::eval
