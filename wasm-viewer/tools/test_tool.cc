// viewer_test_tool: native helpers of the viewer's browser test and benchmark.
//
//   viewer_test_tool package <room|room-nosphere|room-partial|sphere|test> <width> <height>
//                            <out_dir> [tile_size] [levels] [lossy-normals]
//     Writes a web package of a procedural two-layer panorama (encoder/), at
//     PackageOptions' defaults or, with "lossy-normals", DeliveryPackageOptions()
//     with lossy normals (package version 1.2).
//     room-partial: the room with nodes only at longitudes [-75, 45] and
//     latitudes [-40, 50] degrees, like a capture of part of the sphere.
//     room-sheets: the room without a back layer, its sphere's outline linked
//     to the wall behind (links down to a depth ratio of 0.2): sheets across a
//     depth step, as the sealing makes where three surfaces meet.
//   viewer_test_tool render [--viewer] <package_dir> <level> <width> <height> <out_prefix>
//                           <yaw,pitch,fov,x,y,z>...
//     Reads the package natively (encoder/tile_image_codec.h), builds the mesh of `level` and
//     renders it with the native software renderer (reconstruct/render/) from
//     each WebGL-style camera (degrees, metres): <out_prefix>_<i>.ppm (binary
//     RGB, for comparisons) and <out_prefix>_<i>.png (for looking at).
//     --viewer: as the viewer draws by default, with the backdrop
//     (format/backdrop.h) and the sheets it leaves out (format/sheet_stretch.h).
//   viewer_test_tool single-file <package_dir> <out.c3d>
//     Writes the package folder's files (manifest.json first, then the files
//     in the manifest's order) as a single-file container (spec/package.md 8).
//   viewer_test_tool mesh <package_dir> <level> <out_base>
//     Reads the package natively and writes <out_base>.pano and <out_base>.mesh
//     (src/panorama_blob.h): the decoded panorama and its native mesh.

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "encoder/package_writer.h"
#include "encoder/tile_image_codec.h"
#include "format/backdrop.h"
#include "format/color_atlas.h"
#include "format/file_source.h"
#include "format/mesh_builder.h"
#include "format/package_reader.h"
#include "format/package_test_scene.h"
#include "format/sheet_stretch.h"
#include "format/testing/test_panoramas.h"
#include "reconstruct/render/mesh_renderer.h"
#include "wasm-viewer/src/panorama_blob.h"

namespace {

int Fail(const std::string& message) {
  std::fprintf(stderr, "viewer_test_tool: error: %s\n", message.c_str());
  return 1;
}

// Removes every node whose pixel centre lies outside the longitudes
// [lon0, lon1] or latitudes [lat0, lat1] (degrees), and the links to them.
void KeepLonLatBox(double lon0, double lon1, double lat0, double lat1,
                   casual3d::TwoLayerPanorama* pano) {
  const int w = pano->width(), h = pano->height();
  for (int y = 0; y < h; ++y) {
    const double lat = 90.0 - (y + 0.5) / h * 180.0;
    for (int x = 0; x < w; ++x) {
      const double lon = ((x + 0.5) / w - 0.5) * 360.0;
      if (lon >= lon0 && lon <= lon1 && lat >= lat0 && lat <= lat1) continue;
      const size_t i = pano->index(x, y);
      for (int l = 0; l < 2; ++l) {
        casual3d::LayerData& d = pano->layer(l);
        d.present[i] = 0;
        d.rgb[3 * i] = d.rgb[3 * i + 1] = d.rgb[3 * i + 2] = 0;
        d.depth_m[i] = 0;
        d.normal[3 * i] = d.normal[3 * i + 1] = d.normal[3 * i + 2] = 0;
        d.label[i] = 0;
        d.links[i] = 0;
      }
    }
  }
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int l = 0; l < 2; ++l) {
        uint8_t& links = pano->layer(l).links[pano->index(x, y)];
        for (int d = 0; d < 4; ++d) {
          const auto dir = static_cast<casual3d::Direction>(d);
          const casual3d::Link link = casual3d::GetLink(links, dir);
          if (link == casual3d::Link::kNone) continue;
          int nx, ny;
          const int nl = link == casual3d::Link::kFront ? 0 : 1;
          if (!pano->Neighbour(x, y, dir, &nx, &ny) || !pano->present(nl, nx, ny)) {
            links = casual3d::SetLink(links, dir, casual3d::Link::kNone);
          }
        }
      }
    }
  }
}

bool MakePanorama(const std::string& kind, int w, int h, casual3d::TwoLayerPanorama* pano) {
  namespace t = casual3d::testing;
  if (kind == "room-partial") {
    *pano = t::MakeRoomPanorama(w, h);
    KeepLonLatBox(-75, 45, -40, 50, pano);
  } else if (kind == "room") {
    *pano = t::MakeRoomPanorama(w, h);
  } else if (kind == "room-sheets") {
    t::RoomOptions options;
    options.with_back_layer = false;
    *pano = t::MakeRoomPanorama(w, h, options);
    t::LinkByDepthRatio(pano, 0.2f);
  } else if (kind == "room-nosphere") {
    t::RoomOptions options;
    options.with_sphere = false;
    *pano = t::MakeRoomPanorama(w, h, options);
  } else if (kind == "sphere") {
    *pano = t::MakeSpherePanorama(w, h, 3.0f);
  } else if (kind == "test") {
    *pano = t::MakePackageTestPanorama(w, h);
  } else {
    return false;
  }
  return true;
}

int Package(int argc, char** argv) {
  if (argc < 6)
    return Fail(
        "usage: viewer_test_tool package <kind> <width> <height> <out_dir> [tile_size] [levels] "
        "[lossy-normals]");
  casual3d::TwoLayerPanorama pano;
  if (!MakePanorama(argv[2], std::atoi(argv[3]), std::atoi(argv[4]), &pano)) {
    return Fail(std::string("unknown panorama kind '") + argv[2] + "'");
  }
  casual3d::encoder::PackageOptions options;
  if (argc > 8) {
    if (std::string(argv[8]) != "lossy-normals")
      return Fail(std::string("unknown package settings '") + argv[8] +
                  "' (expected lossy-normals)");
    options = casual3d::encoder::DeliveryPackageOptions();
    options.lossy_normals = true;
  }
  if (argc > 6) options.tile_size = std::atoi(argv[6]);
  if (argc > 7) options.levels = std::atoi(argv[7]);
  options.generator = "viewer_test_tool";
  casual3d::encoder::PackageStats stats;
  auto files = casual3d::encoder::EncodePackage(pano, options, &stats);
  if (!files.ok()) return Fail(files.status().ToString());
  const casual3d::Status s = casual3d::encoder::WritePackageFolder(*files, argv[5]);
  if (!s.ok()) return Fail(s.ToString());
  std::printf("{\"total_bytes\": %llu, \"manifest_bytes\": %llu, \"level_bytes\": [",
              static_cast<unsigned long long>(stats.total_bytes),
              static_cast<unsigned long long>(stats.manifest_bytes));
  for (size_t i = 0; i < stats.level_bytes.size(); ++i) {
    std::printf("%s%llu", i ? ", " : "", static_cast<unsigned long long>(stats.level_bytes[i]));
  }
  std::printf("]}\n");
  return 0;
}

bool WriteFile(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  return static_cast<bool>(out);
}

int DumpMesh(int argc, char** argv) {
  if (argc != 5) return Fail("usage: viewer_test_tool mesh <package_dir> <level> <out_base>");
  casual3d::ReadOptions read;
  read.level = std::atoi(argv[3]);
  casual3d::FolderFileSource source(argv[2]);
  auto pano = casual3d::ReadPackage(source, casual3d::encoder::TileImageDecoders(), read);
  if (!pano.ok()) return Fail(std::string(argv[2]) + ": " + pano.status().ToString());
  auto mesh = casual3d::BuildMesh(*pano);
  if (!mesh.ok()) return Fail(mesh.status().ToString());
  const std::string base = argv[4];
  if (!WriteFile(base + ".pano", casual3d::viewer::SerializePanorama(*pano)) ||
      !WriteFile(base + ".mesh", casual3d::viewer::SerializeMesh(*mesh))) {
    return Fail(base + ": cannot write the blobs");
  }
  std::printf("{\"vertices\": %zu, \"triangles\": %zu}\n", mesh->num_vertices(),
              mesh->num_triangles());
  return 0;
}

int Render(int argc, char** argv) {
  // --viewer: drawn as the viewer draws by default (backdrop, sheets left out).
  const bool as_viewer = argc > 2 && std::string(argv[2]) == "--viewer";
  if (as_viewer) {
    for (int i = 2; i + 1 < argc; ++i) argv[i] = argv[i + 1];
    --argc;
  }
  if (argc < 8) {
    return Fail(
        "usage: viewer_test_tool render [--viewer] <package_dir> <level> <width> <height> "
        "<out_prefix> <yaw,pitch,fov,x,y,z>...");
  }
  casual3d::ReadOptions read;
  read.level = std::atoi(argv[3]);
  const int width = std::atoi(argv[4]), height = std::atoi(argv[5]);
  const std::string prefix = argv[6];
  casual3d::FolderFileSource source(argv[2]);
  auto pano = casual3d::ReadPackage(source, casual3d::encoder::TileImageDecoders(), read);
  if (!pano.ok()) return Fail(std::string(argv[2]) + ": " + pano.status().ToString());
  auto mesh = casual3d::BuildMesh(*pano);
  if (!mesh.ok()) return Fail(mesh.status().ToString());
  // The colour atlas the viewer uploads (format/color_atlas.h).
  const casual3d::Image8 atlas = casual3d::BuildColorAtlas(*pano, 3);
  casual3d::render::RenderOptions options;
  if (as_viewer) {
    auto backdrop = casual3d::BuildBackdrop(*pano);
    if (!backdrop.ok()) return Fail(backdrop.status().ToString());
    options.vertex_colors_from_triangle = mesh->num_triangles();
    options.sheet_stretch = casual3d::kDefaultSheetStretch;
    casual3d::AppendMesh(*backdrop, &*mesh);
  }
  for (int i = 7; i < argc; ++i) {
    casual3d::render::GlCamera camera;
    char comma;
    std::istringstream in(argv[i]);
    in >> camera.yaw_deg >> comma >> camera.pitch_deg >> comma >> camera.fov_y_deg >> comma >>
        camera.position[0] >> comma >> camera.position[1] >> comma >> camera.position[2];
    if (!in) return Fail(std::string("camera '") + argv[i] + "': expected yaw,pitch,fov,x,y,z");
    const casual3d::render::PinholeView view =
        casual3d::render::ViewFromGlCamera(camera, width, height);
    const casual3d::render::RenderResult result = casual3d::render::RenderMesh(
        *mesh, atlas.view(), view, options);
    const std::string base = prefix + "_" + std::to_string(i - 7);
    std::ofstream ppm(base + ".ppm", std::ios::binary);
    ppm << "P6\n" << width << " " << height << "\n255\n";
    ppm.write(reinterpret_cast<const char*>(result.color.data()),
              static_cast<std::streamsize>(result.color.size()));
    if (!ppm) return Fail(base + ".ppm: cannot write");
    cv::Mat rgb(height, width, CV_8UC3, const_cast<uint8_t*>(result.color.data()));
    cv::Mat bgr;
    cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
    if (!cv::imwrite(base + ".png", bgr)) return Fail(base + ".png: cannot write");
  }
  std::printf("{\"vertices\": %zu, \"triangles\": %zu}\n", mesh->num_vertices(),
              mesh->num_triangles());
  return 0;
}

}  // namespace

int SingleFile(int argc, char** argv) {
  if (argc != 4) return Fail("usage: viewer_test_tool single-file <package_dir> <out.c3d>");
  casual3d::FolderFileSource source(argv[2]);
  auto manifest_bytes = source.Read(casual3d::kManifestFileName, 16u << 20);
  if (!manifest_bytes.ok()) return Fail(manifest_bytes.status().ToString());
  auto reader = casual3d::PackageReader::Create(
      std::string_view(reinterpret_cast<const char*>(manifest_bytes->data()), manifest_bytes->size()));
  if (!reader.ok()) return Fail(reader.status().ToString());
  casual3d::encoder::PackageFiles files;
  files.emplace_back(casual3d::kManifestFileName, std::move(manifest_bytes).value());
  for (const casual3d::FileEntry& f : reader->manifest().files) {
    auto bytes = source.Read(f.path, f.bytes);
    if (!bytes.ok()) return Fail(bytes.status().ToString());
    files.emplace_back(f.path, std::move(bytes).value());
  }
  const casual3d::Status s = casual3d::encoder::WritePackageSingleFile(files, argv[3]);
  return s.ok() ? 0 : Fail(s.ToString());
}

int main(int argc, char** argv) {
  try {
    if (argc >= 2 && std::string(argv[1]) == "package") return Package(argc, argv);
    if (argc >= 2 && std::string(argv[1]) == "render") return Render(argc, argv);
    if (argc >= 2 && std::string(argv[1]) == "mesh") return DumpMesh(argc, argv);
    if (argc >= 2 && std::string(argv[1]) == "single-file") return SingleFile(argc, argv);
  } catch (const std::exception& e) {
    return Fail(e.what());
  }
  return Fail("usage: viewer_test_tool <package|render|mesh|single-file> ...");
}
