#pragma once

// glTF 2.0 export of a 3D photo: the (simplified) triangle mesh of format/mesh.h
// with its colour atlas as one binary glTF file (GLB), optionally with the mesh
// compressed by Draco (KHR_draco_mesh_compression), for use in any glTF tool or
// web viewer.
//
// What the file holds:
// - One scene, one node, one mesh with one triangle primitive: POSITION (metres),
//   NORMAL (optional), TEXCOORD_0 and indices (unsigned short when every index
//   fits, else unsigned int).
// - Axes: glTF is right-handed with +Y up, exactly the panorama frame of
//   format/equirect.h (+X right, +Y up, -Z forward), so positions and normals
//   are written unchanged, without any axis flip; the node has no transform.
//   The viewpoint of the 3D photo is the origin.
// - Winding: Mesh triangles are counter-clockwise seen from the centre, which is
//   glTF's front face for a viewer at the origin.
// - Texture: the colour atlas (front layer above back layer, see Mesh::uvs) as
//   PNG or JPEG inside the GLB's binary chunk. glTF puts texture coordinate
//   (0, 0) at the first pixel of the image's first row, as Mesh::uvs does, so
//   the coordinates are written unchanged too. Sampler: linear filtering with
//   mipmaps; wrapS REPEAT, because the seam copies of column-0 nodes (format/
//   mesh.h) have u = 1 + 0.5 / width, which must wrap onto column 0 as the
//   panorama does; wrapT CLAMP_TO_EDGE (rows do not wrap).
// - Material: by default KHR_materials_unlit with the atlas as base colour. The
//   colours of a 3D photo are photographs with the scene's lighting already in
//   them; shading them again under a renderer's lights would darken or tint
//   them. Viewers without the extension fall back to the metallic-roughness
//   material (metallic 0, roughness 1), which still shows the texture.
// - Normals: glTF requires unit-length normals, but a Mesh marks unlit nodes
//   (sky) with the normal (0, 0, 0). Such vertices are exported with a normal
//   pointing from the vertex to the centre (-position / |position|), the normal
//   of a surface seen face-on from the viewpoint; other normals are
//   renormalized. Normals can also be left out altogether.
//
// All functions return a Status instead of throwing; output files are written
// atomically (a temporary file in the same folder renamed over the target).

#include <cstdint>
#include <string>
#include <vector>

#include "format/image.h"
#include "format/mesh.h"
#include "format/status.h"
#include "format/two_layer.h"

namespace casual3d::encoder {

enum class TextureFormat {
  kPng,   // Lossless, larger.
  kJpeg,  // Lossy (jpeg_quality), several times smaller for photographs.
};

struct GltfExportOptions {
  // How the colour atlas is stored in the file.
  TextureFormat texture_format = TextureFormat::kJpeg;
  // JPEG quality, 1..100 (libjpeg scale); used with kJpeg only.
  int jpeg_quality = 90;
  // Longest side of the stored texture in pixels, 16..16384. A larger atlas is
  // shrunk (area average, aspect ratio kept, height kept even so the front and
  // back halves stay apart). 8192 is what current desktop GPUs accept; use 4096
  // for phones.
  int max_texture_size = 8192;

  // Write the NORMAL attribute (see the header comment for unlit vertices).
  bool normals = true;
  // Use KHR_materials_unlit (see the header comment).
  bool unlit = true;
  // Render both sides of each triangle. A 3D photo is seen from near its centre,
  // so back faces are normally hidden; turn on for tools that orbit the mesh.
  bool double_sided = false;

  // Compress the mesh with Draco (KHR_draco_mesh_compression, required by the
  // file then). The texture is stored as without Draco.
  bool draco = false;
  // Draco quantization bits, 1..30 each. Positions: 0 = automatic
  // (DracoPositionBits): a 3D photo spans from near objects to the sky, and
  // a uniform grid over its bounding box must still place the nearest
  // vertices within 0.1% of their distance (14 bits over a box 1000 times
  // the nearest distance would move them by 12%). Normals: 10 bits
  // (octahedral, under 0.2 degrees). Texture coordinates: 14 bits over their
  // range, enough for a quarter-texel precision on an 4096-texel-wide atlas.
  int draco_position_bits = 0;
  int draco_normal_bits = 10;
  int draco_texcoord_bits = 14;
  // Draco compression level, 0..10 (Draco's encoding speed is 10 - level).
  // Higher levels try costlier predictors, which do not always give a
  // smaller mesh (docs/DECISIONS.md, "GLB export: Draco compression level").
  int draco_compression_level = 6;

  // Returns InvalidArgument naming the first field out of range.
  Status Check() const;
};

// Position bits for Draco such that the quantization step over the
// positions' bounding box (its largest side / 2^bits) is at most
// `relative_step` times the smallest non-zero distance of a vertex from the
// origin (the 3D photo's centre); within [14, 30].
int DracoPositionBits(const std::vector<float>& positions, double relative_step = 1e-3);

// Facts about a written GLB, for logs and tests.
struct GltfExportStats {
  size_t num_vertices = 0;   // As stored (after Draco's decoding, if any).
  size_t num_triangles = 0;  // As stored.
  int texture_width = 0;     // Stored texture size in pixels.
  int texture_height = 0;
  size_t texture_bytes = 0;  // Encoded PNG/JPEG size.
  int draco_position_bits = 0;  // As used (0 without Draco).
  size_t mesh_bytes = 0;     // Vertex and index data (or the Draco bitstream).
  size_t file_bytes = 0;     // The whole GLB.
};

// The colour atlas that Mesh::uvs address (format/mesh.h): width x 2*height,
// 3 channels (sRGB), the front layer's colours in the top half and the back
// layer's in the bottom half. A pixel without a node of its layer takes the
// colour of the other layer's node at that pixel (black if there is none), so
// that texture filtering along the border of a layer's region, and the coarse
// mipmap levels, do not blend in black.
Image8 BuildColorAtlas(const TwoLayerPanorama& pano);

// Deprecated: the earlier name of BuildColorAtlas (docs/SDK.md, "Deprecated names").
[[deprecated("use BuildColorAtlas")]] inline Image8 BuildColourAtlas(const TwoLayerPanorama& pano) {
  return BuildColorAtlas(pano);
}

// Checks that `mesh` can be exported: positions, uvs and indices present and
// consistent (3 floats per vertex, 2 uvs per vertex, normals empty or 3 per
// vertex, 3 indices per triangle, every index < num_vertices), positions
// finite, at least one triangle, and fewer than 2^32 - 1 vertices. Returns
// InvalidArgument naming the problem.
Status CheckMeshForExport(const Mesh& mesh);

// Builds the GLB file in memory. `atlas` is the colour atlas the mesh's uvs
// point into (8 bits, 3 channels RGB or 4 channels RGBA; JPEG drops alpha).
// Errors: InvalidArgument for bad options, mesh or atlas; InternalError when
// an encoder (PNG, JPEG, Draco, glTF serializer) fails.
StatusOr<std::vector<uint8_t>> EncodeGlb(const Mesh& mesh, const Image8& atlas,
                                         const GltfExportOptions& options,
                                         GltfExportStats* stats = nullptr);

// EncodeGlb, then writes the result atomically to `path` (an existing file is
// replaced only once the new one is complete). IoError names `path` when the
// file cannot be written; `path` is then left as it was.
Status ExportGlb(const Mesh& mesh, const Image8& atlas, const GltfExportOptions& options,
                 const std::string& path, GltfExportStats* stats = nullptr);

}  // namespace casual3d::encoder
