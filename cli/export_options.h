#pragma once

// The options of `casual3d export` (cli/export_command.cc), described once
// (reconstruct/util/options_fields.h) for the flags' help and range checks.
//
// MeshSimplifyOptions (format/, standard library only) and
// encoder::GltfExportOptions (encoder/, below reconstruct/util) keep their
// own Check(); the fields the flags set are described here within their
// ranges (cli/command_options_test.cc holds them to it).

#include <string>

#include "encoder/gltf_export.h"
#include "format/mesh_simplify.h"
#include "format/status.h"
#include "reconstruct/util/options_fields.h"

namespace casual3d::cli {

struct ExportOptions {
  std::string input;         // Package folder, single-file package or master file.
  std::string glb;           // Output .glb path.
  int level = 0;             // Package level of detail (0 = full resolution).
  bool no_simplify = false;  // true: the full mesh of BuildMesh.
  MeshSimplifyOptions simplify_options;
  std::string texture = "jpeg";  // "jpeg" or "png".
  encoder::GltfExportOptions gltf;
  bool lit = false;  // Use a lit (PBR) material instead of KHR_materials_unlit.
  bool no_normals = false;
  int num_threads = 0;  // Tile decoding threads; 0 = all cores.

  template <typename Self, typename Visitor>
  static void DescribeFields(Self& o, Visitor& v) {
    using R = util::Rule;
    v.Field("level", o.level, R::Closed(0, 64),
            "Package level of detail to read (0 = full resolution)");
    v.Field("simplify_options.max_triangles", o.simplify_options.max_triangles,
            R::Closed(0, 2147483648.0),
            "Triangle budget of the simplified mesh (0: only --max-error limits it)");
    // Library: (0, 0.5]; from 1e-6 on here, a bound that keeps the mesh finite.
    v.Field("simplify_options.max_relative_error", o.simplify_options.max_relative_error,
            R::Closed(1e-6, 0.5),
            "Largest relative depth error of the simplification (0.01 = 1%); from a "
            "package, beyond one step of its depth code");
    v.Field("texture", o.texture, R::OneOf({"jpeg", "png"}), "Texture format");
    v.Field("gltf.jpeg_quality", o.gltf.jpeg_quality, R::Closed(1, 100), "JPEG quality");
    v.Field("gltf.max_texture_size", o.gltf.max_texture_size, R::Closed(16, 16384),
            "Longest texture side in pixels; larger atlases are shrunk");
    v.Field("gltf.draco_position_bits", o.gltf.draco_position_bits, R::Closed(0, 30),
            "Draco position quantization bits; 0 = enough for 0.1% of the nearest vertex's "
            "distance over the mesh's extent");
    v.Field("gltf.draco_normal_bits", o.gltf.draco_normal_bits, R::Closed(1, 30),
            "Draco normal quantization bits");
    v.Field("gltf.draco_texcoord_bits", o.gltf.draco_texcoord_bits, R::Closed(1, 30),
            "Draco texture coordinate quantization bits");
    v.Field("gltf.draco_compression_level", o.gltf.draco_compression_level, R::Closed(0, 10),
            "Draco compression level, 0 (fast) .. 10 (small)");
    v.Field("num_threads", o.num_threads, R::Closed(0, 256),
            "Tile decoding threads (0 = all cores)", util::Keyed::kNo);
  }
  // The described ranges, then the glTF and simplification options' own checks.
  Status Check() const {
    CASUAL3D_RETURN_IF_ERROR(util::CheckFields(*this));
    CASUAL3D_RETURN_IF_ERROR(gltf.Check());
    return simplify_options.Check();
  }
};

}  // namespace casual3d::cli
