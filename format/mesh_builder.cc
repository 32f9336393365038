#include "format/mesh_builder.h"

#include <cmath>
#include <string>
#include <utility>

namespace casual3d {
namespace {

// pi/2 split so that q * kPiOver2Hi is exact for |q| < 2^20 (fdlibm's pio2_1).
constexpr double kPiOver2Hi = 1.57079632673412561417e+00;
constexpr double kPiOver2Lo = 6.07710050650619224932e-11;
constexpr double kTwoOverPi = 6.36619772367581382433e-01;

}  // namespace

Status MeshBuildOptions::Check() const {
  if (max_pixels < 1 || max_pixels > kMeshPixelLimit) {
    return InvalidArgument("max_pixels " + std::to_string(max_pixels) + " is outside [1, " +
                           std::to_string(kMeshPixelLimit) + "]");
  }
  return Status::Ok();
}

void DeterministicSinCos(double angle_rad, double* sin_out, double* cos_out) {
  // Cody-Waite reduction to r in [-pi/4, pi/4], then Taylor polynomials whose
  // first omitted terms are below 1e-19 on that interval.
  const double q = std::floor(angle_rad * kTwoOverPi + 0.5);
  const double r = (angle_rad - q * kPiOver2Hi) - q * kPiOver2Lo;
  const double r2 = r * r;
  const double s =
      r +
      r * r2 *
          (-1.0 / 6 +
           r2 * (1.0 / 120 +
                 r2 * (-1.0 / 5040 +
                       r2 * (1.0 / 362880 + r2 * (-1.0 / 39916800 +
                                                  r2 * (1.0 / 6227020800.0 +
                                                        r2 * (-1.0 / 1307674368000.0 +
                                                              r2 * (1.0 / 355687428096000.0))))))));
  const double c =
      1.0 +
      r2 * (-0.5 +
            r2 * (1.0 / 24 +
                  r2 * (-1.0 / 720 +
                        r2 * (1.0 / 40320 + r2 * (-1.0 / 3628800 +
                                                  r2 * (1.0 / 479001600.0 +
                                                        r2 * (-1.0 / 87178291200.0 +
                                                              r2 * (1.0 / 20922789888000.0))))))));
  const int quadrant = static_cast<int>(q - 4.0 * std::floor(q * 0.25));  // q mod 4 in [0, 3].
  switch (quadrant) {
    case 0:
      *sin_out = s;
      *cos_out = c;
      break;
    case 1:
      *sin_out = c;
      *cos_out = -s;
      break;
    case 2:
      *sin_out = -s;
      *cos_out = -c;
      break;
    default:
      *sin_out = -c;
      *cos_out = s;
      break;
  }
}

namespace {

// Counts instead of collecting triangles.
struct TriangleCounter {
  int count = 0;
  void AddTriangle(NodeRef, NodeRef, NodeRef) { ++count; }
};

// Spec/mesh.md Sec. 4: the corner triangles of one pixel quad.
template <typename Sink>
void QuadTriangles(const TwoLayerPanorama& p, int x, int y, bool use_back, unsigned skip_layers,
                   Sink* out) {
  // Corners A (top-left), B (top-right), C (bottom-left), D (bottom-right).
  enum { A = 0, B = 1, C = 2, D = 3 };
  const bool wrap = x + 1 == p.width();  // B and D are column 0, seen as column width.
  const int xb = wrap ? 0 : x + 1;
  const size_t idx[4] = {p.index(x, y), p.index(xb, y), p.index(x, y + 1), p.index(xb, y + 1)};
  // Local copies: bit l of present[c] is set if corner c has a usable node of
  // layer l; links[c][l] are its links (0 otherwise).
  unsigned present[4] = {0, 0, 0, 0};
  uint8_t links[4][kNumLayers] = {};
  for (int l = 0; l < (use_back ? kNumLayers : 1); ++l) {
    const LayerData& d = p.layer(l);
    for (int c = 0; c < 4; ++c) {
      if (d.present[idx[c]]) {
        present[c] |= 1u << l;
        links[c][l] = d.links[idx[c]];
      }
    }
  }
  if (!(present[A] | present[B] | present[C] | present[D])) return;
  // The layer of the node that (corner c, layer l) links to at corner oc in
  // direction dir, or -1. Never trusts a link blindly: the target must be a
  // usable node, so invalid panoramas stay safe.
  auto target = [&](int c, int l, Direction dir, int oc) -> int {
    const unsigned link = (links[c][l] >> (2 * dir)) & 3u;
    if (link == 0 || link == 3) return -1;
    const int t = static_cast<int>(link) - 1;
    return (present[oc] >> t) & 1u ? t : -1;
  };
  auto ref = [&](int c, int l) {
    return static_cast<NodeRef>(idx[c] * 2 + l) | (wrap && (c == B || c == D) ? kSeamBit : 0u);
  };
  auto usable = [&](int c, int l) { return ((present[c] & ~skip_layers) >> l) & 1u; };
  // Corner A: links right and down; only where neither B nor C closes the
  // quad, otherwise the corner-B/C triangles cover this area.
  for (int l = 0; l < kNumLayers; ++l) {
    if (!usable(A, l)) continue;
    const int lb = target(A, l, kRight, B), lc = target(A, l, kDown, C);
    if (lb < 0 || lc < 0 || target(B, lb, kDown, D) >= 0 || target(C, lc, kRight, D) >= 0) continue;
    out->AddTriangle(ref(A, l), ref(C, lc), ref(B, lb));
  }
  // Corner B: links left and down; the quad splits along the A-D diagonal.
  for (int l = 0; l < kNumLayers; ++l) {
    if (!usable(B, l)) continue;
    const int la = target(B, l, kLeft, A), ld = target(B, l, kDown, D);
    if (la < 0 || ld < 0) continue;
    out->AddTriangle(ref(B, l), ref(A, la), ref(D, ld));
  }
  // Corner C: links up and right.
  for (int l = 0; l < kNumLayers; ++l) {
    if (!usable(C, l)) continue;
    const int la = target(C, l, kUp, A), ld = target(C, l, kRight, D);
    if (la < 0 || ld < 0) continue;
    out->AddTriangle(ref(C, l), ref(D, ld), ref(A, la));
  }
  // Corner D: links up and left; only where neither B nor C closes the quad.
  for (int l = 0; l < kNumLayers; ++l) {
    if (!usable(D, l)) continue;
    const int lb = target(D, l, kUp, B), lc = target(D, l, kLeft, C);
    if (lb < 0 || lc < 0 || target(B, lb, kLeft, A) >= 0 || target(C, lc, kUp, A) >= 0) continue;
    out->AddTriangle(ref(D, l), ref(B, lb), ref(C, lc));
  }
}

}  // namespace

void AddQuadTriangles(const TwoLayerPanorama& pano, int x, int y, bool use_back,
                      unsigned skip_layers, MeshAssembler* out) {
  QuadTriangles(pano, x, y, use_back, skip_layers, out);
}

int CountQuadTriangles(const TwoLayerPanorama& pano, int x, int y, bool use_back,
                       unsigned skip_layers) {
  TriangleCounter counter;
  QuadTriangles(pano, x, y, use_back, skip_layers, &counter);
  return counter.count;
}

Mesh MeshAssembler::Finish() {
  const int w = pano_.width(), h = pano_.height();
  const size_t nodes = static_cast<size_t>(w) * h * 2;
  std::vector<uint32_t> vertex_of(nodes, 0);  // 0: unused, else index + 1.
  std::vector<uint32_t> seam_vertex_of(2 * static_cast<size_t>(h), 0);
  for (NodeRef r : refs_) {
    const uint32_t node = r & ~kSeamBit;
    if (r & kSeamBit) {
      seam_vertex_of[2 * ((node >> 1) / w) + (node & 1)] = 1;
    } else {
      vertex_of[node] = 1;
    }
  }
  uint32_t count = 0;
  for (uint32_t& v : vertex_of) {
    if (v) v = ++count;
  }
  for (uint32_t& v : seam_vertex_of) {
    if (v) v = ++count;
  }

  // Direction tables (Sec. 3 of spec/mesh.md): longitude per column and
  // latitude per row at pixel centres, with the deterministic sine/cosine.
  std::vector<double> sin_lon(w), cos_lon(w), sin_lat(h), cos_lat(h);
  for (int x = 0; x < w; ++x) {
    DeterministicSinCos(((x + 0.5) / w - 0.5) * 2.0 * kPi, &sin_lon[x], &cos_lon[x]);
  }
  for (int y = 0; y < h; ++y) {
    DeterministicSinCos((0.5 - (y + 0.5) / h) * kPi, &sin_lat[y], &cos_lat[y]);
  }

  // Texture coordinates per column and per (row, layer), spec/mesh.md Sec. 3.
  std::vector<float> u_of(w + 1), v_of(2 * static_cast<size_t>(h));
  for (int x = 0; x <= w; ++x) u_of[x] = static_cast<float>((x + 0.5) / w);
  for (int y = 0; y < h; ++y) {
    for (int l = 0; l < kNumLayers; ++l) {
      v_of[2 * y + l] = static_cast<float>((y + 0.5 + l * static_cast<double>(h)) / (2.0 * h));
    }
  }

  Mesh mesh;
  mesh.positions.reserve(3 * static_cast<size_t>(count));
  mesh.normals.reserve(3 * static_cast<size_t>(count));
  mesh.uvs.reserve(2 * static_cast<size_t>(count));
  mesh.colors.reserve(3 * static_cast<size_t>(count));
  // Vertices are appended in index order: regular nodes, then seam copies.
  auto emit = [&](int x, int y, int layer, bool seam) {
    const LayerData& d = pano_.layer(layer);
    const size_t i = pano_.index(x, y);
    const double depth = d.depth_m[i];
    const double horizontal = cos_lat[y] * depth;
    mesh.positions.push_back(static_cast<float>(horizontal * sin_lon[x]));
    mesh.positions.push_back(static_cast<float>(sin_lat[y] * depth));
    mesh.positions.push_back(static_cast<float>(-(horizontal * cos_lon[x])));
    for (int c = 0; c < 3; ++c) {
      mesh.normals.push_back(d.normal[3 * i + c]);
      mesh.colors.push_back(d.rgb[3 * i + c]);
    }
    mesh.uvs.push_back(u_of[seam ? w : x]);
    mesh.uvs.push_back(v_of[2 * y + layer]);
  };
  size_t node = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int l = 0; l < kNumLayers; ++l, ++node) {
        if (vertex_of[node]) emit(x, y, l, false);
      }
    }
  }
  for (int y = 0; y < h; ++y) {
    for (int l = 0; l < kNumLayers; ++l) {
      if (seam_vertex_of[2 * y + l]) emit(0, y, l, true);
    }
  }
  // References become indices in place (both are 32-bit).
  for (NodeRef& r : refs_) {
    const uint32_t n = r & ~kSeamBit;
    r = ((r & kSeamBit) ? seam_vertex_of[2 * ((n >> 1) / w) + (n & 1)] : vertex_of[n]) - 1;
  }
  mesh.indices = std::move(refs_);
  refs_ = std::vector<NodeRef>();
  return mesh;
}

Status CheckMeshInput(const TwoLayerPanorama& pano, int64_t max_pixels, bool validate) {
  const int64_t pixels = static_cast<int64_t>(pano.width()) * pano.height();
  if (pixels > max_pixels) {
    return LimitExceeded("panorama " + std::to_string(pano.width()) + "x" +
                         std::to_string(pano.height()) + " has " + std::to_string(pixels) +
                         " pixels, more than the mesh builder's limit of " +
                         std::to_string(max_pixels));
  }
  if (validate) {
    CASUAL3D_RETURN_IF_ERROR(pano.Validate());
  } else if (pano.width() < 1 || pano.height() < 1) {
    return InvalidData("panorama is empty");
  }
  if (pano.width() < 2) {
    return InvalidArgument("panorama width " + std::to_string(pano.width()) +
                           " is too small for a mesh: at least 2 columns are needed");
  }
  if (!validate) {
    // Without validation, at least make every array access in bounds.
    const size_t n = static_cast<size_t>(pixels);
    for (int l = 0; l < kNumLayers; ++l) {
      const LayerData& d = pano.layer(l);
      if (d.present.size() != n || d.rgb.size() != 3 * n || d.depth_m.size() != n ||
          d.normal.size() != 3 * n || d.label.size() != n || d.links.size() != n) {
        return InvalidData("panorama arrays do not match its size " + std::to_string(pano.width()) +
                           "x" + std::to_string(pano.height()));
      }
    }
  }
  return Status::Ok();
}

StatusOr<Mesh> BuildMesh(const TwoLayerPanorama& pano, const MeshBuildOptions& options) {
  CASUAL3D_RETURN_IF_ERROR(options.Check());
  CASUAL3D_RETURN_IF_ERROR(CheckMeshInput(pano, options.max_pixels, options.validate_input));
  const size_t pixels = static_cast<size_t>(pano.width()) * pano.height();
  MeshAssembler assembler(pano);
  // About two triangles per pixel when the front layer is fully linked.
  assembler.Reserve(2 * pixels + 1024);
  for (int y = 0; y + 1 < pano.height(); ++y) {
    for (int x = 0; x < pano.width(); ++x) {
      AddQuadTriangles(pano, x, y, options.include_back_layer, 0u, &assembler);
    }
  }
  return assembler.Finish();
}

}  // namespace casual3d
