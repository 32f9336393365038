// viewer_mesh_dump: writes a procedural two-layer panorama and the mesh the
// NATIVE format library builds from it, as panorama and mesh blobs
// (src/panorama_blob.h). The Node test (test/mesh_equivalence.test.mjs) builds
// the mesh from the same panorama blob with the wasm library and compares.
//
//   viewer_mesh_dump <room|room-nosphere|sphere|test> <width> <height> <out_dir>
//
// Writes <out_dir>/<name>_<w>x<h>.pano, .mesh (BuildMesh) and .smesh
// (BuildSimplifiedMesh with a budget of a quarter of the full mesh's triangles
// and the default error bound; the budget is printed) and .bmesh (BuildBackdrop
// with its default cell).

#include <cstdio>
#include <cstdlib>
#include <string>

#include "base/atomic_file.h"
#include "format/backdrop.h"
#include "format/mesh_builder.h"
#include "format/mesh_simplify.h"
#include "format/package_test_scene.h"
#include "format/testing/test_panoramas.h"
#include "wasm-viewer/src/panorama_blob.h"

namespace {

int Fail(const std::string& message) {
  std::fprintf(stderr, "viewer_mesh_dump: error: %s\n", message.c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) {
    return Fail(
        "usage: viewer_mesh_dump <room|room-nosphere|sphere|test> <width> <height> <out_dir>");
  }
  const std::string kind = argv[1];
  const int width = std::atoi(argv[2]), height = std::atoi(argv[3]);
  const std::string out_dir = argv[4];
  if (width < 2 || height < 2 || width > 16384 || height > 8192) {
    return Fail("width and height must be in 2..16384 and 2..8192");
  }
  casual3d::TwoLayerPanorama pano;
  if (kind == "room") {
    pano = casual3d::testing::MakeRoomPanorama(width, height);
  } else if (kind == "room-nosphere") {
    casual3d::testing::RoomOptions options;
    options.with_sphere = false;
    pano = casual3d::testing::MakeRoomPanorama(width, height, options);
  } else if (kind == "sphere") {
    pano = casual3d::testing::MakeSpherePanorama(width, height, 3.0f);
  } else if (kind == "test") {
    pano = casual3d::testing::MakePackageTestPanorama(width, height);
  } else {
    return Fail("unknown panorama kind '" + kind + "' (room, room-nosphere, sphere or test)");
  }
  const casual3d::Status valid = pano.Validate();
  if (!valid.ok()) return Fail(kind + ": " + valid.ToString());
  auto mesh = casual3d::BuildMesh(pano);
  if (!mesh.ok()) return Fail(kind + ": " + mesh.status().ToString());
  casual3d::MeshSimplifyOptions simplify;
  simplify.max_triangles = static_cast<int64_t>(mesh->num_triangles() / 4);
  auto simplified = casual3d::BuildSimplifiedMesh(pano, simplify);
  if (!simplified.ok()) return Fail(kind + ": " + simplified.status().ToString());
  auto backdrop = casual3d::BuildBackdrop(pano);
  if (!backdrop.ok()) return Fail(kind + ": " + backdrop.status().ToString());
  const std::string base =
      out_dir + "/" + kind + "_" + std::to_string(width) + "x" + std::to_string(height);
  using casual3d::base::WriteFileAtomic;
  casual3d::Status written = WriteFileAtomic(base + ".pano", casual3d::viewer::SerializePanorama(pano));
  if (written.ok()) written = WriteFileAtomic(base + ".mesh", casual3d::viewer::SerializeMesh(*mesh));
  if (written.ok())
    written = WriteFileAtomic(base + ".smesh", casual3d::viewer::SerializeMesh(simplified->mesh));
  if (written.ok())
    written = WriteFileAtomic(base + ".bmesh", casual3d::viewer::SerializeMesh(*backdrop));
  if (!written.ok()) return Fail(written.message() + " (does the folder exist?)");
  std::printf(
      "{\"vertices\": %zu, \"triangles\": %zu, \"budget\": %lld, \"simplified_triangles\": %zu}\n",
      mesh->num_vertices(), mesh->num_triangles(), static_cast<long long>(simplify.max_triangles),
      simplified->mesh.num_triangles());
  return 0;
}
