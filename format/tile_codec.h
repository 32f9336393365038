#pragma once

// Quantization and bit packing of a two-layer panorama into the four images of
// a package tile, and back (spec/package.md, "Tile images"). Standard library
// only, no exceptions; decoding takes untrusted pixels and returns a Status.
//
// A tile covers pixels [x0, x0+w) x [y0, y0+h) of the panorama of its level.
// Its images are 3-channel (RGB) 8-bit; decoders may hand in 4-channel RGBA,
// whose alpha is ignored. For colour, depth and normal the image is w x 2h: rows
// [0, h) hold the front layer and rows [h, 2h) the back layer. The graph image
// is w x h.
//   colour (lossy):   R, G, B = sRGB colour; pixels without a node are filled
//                     with the nearest node's colour in the row (decoders ignore
//                     them).
//   depth (lossless): R = code >> 8, G = code & 255, B = 0, with code the
//                     log-depth code of QuantizeDepth (0: no node).
//   normal (lossless, encoding "octahedral"): R, G = octahedral code
//                     (EncodeOctahedral), B = 0.
//   normal (lossy, encoding "octahedral-lossy", version 1.2): 2w x 2h, grey;
//                     G of pixel (x, y) is the node's u code and G of (w + x,
//                     y) its v code (EncodeOctahedralLossy); alpha below 128
//                     at (x, y) marks the zero normal (unlit).
//   graph (lossless): R = front links, G = back links (TwoLayerPanorama's packed
//                     byte: 2 bits per direction; from version 2.0 the right
//                     and down links only, bits 4-7 zero, CompleteLinks),
//                     B = flags: bit 0 front present, bit 1 back present,
//                     bit 2 front label, bit 3 back label; bits 4-7 are 0.

#include <cstdint>
#include <vector>

#include "format/image.h"
#include "format/reader_checks.h"
#include "format/status.h"
#include "format/two_layer.h"

namespace casual3d {

enum class TileImageKind : int { kColor = 0, kDepth = 1, kNormal = 2, kGraph = 3 };
constexpr int kNumTileImageKinds = 4;

// "color", "depth", "normal", "graph": the names used in the manifest.
const char* TileImageKindName(TileImageKind kind);

// The manifest's normal_encoding type (spec/package.md Sec. 4.3):
// "octahedral" (lossless codes of 4..8 bits) or, from version 1.2,
// "octahedral-lossy" (a lossy grey image of 8-bit codes, Sec. 4.3.1).
enum class NormalEncoding : int { kOctahedral = 0, kOctahedralLossy = 1 };

// Pixel size of the image of `kind` for a tile of w x h panorama pixels: w x h
// for the graph, w x 2h for the others, but 2w x 2h for lossy normals.
void TileImageSize(TileImageKind kind, int w, int h, int* image_w, int* image_h,
                   NormalEncoding normal_encoding = NormalEncoding::kOctahedral);

// Whether the image of `kind` must be stored lossless: depth, graph and, with
// the "octahedral" encoding, normals.
inline bool TileImageIsLossless(TileImageKind kind,
                                NormalEncoding normal_encoding = NormalEncoding::kOctahedral) {
  return kind != TileImageKind::kColor &&
         !(kind == TileImageKind::kNormal && normal_encoding == NormalEncoding::kOctahedralLossy);
}

// How a WebP file codes its image, from its RIFF container alone
// (spec/package.md Sec. 4): kLossless when the image is one VP8L chunk (the
// file's first chunk, or after a VP8X header without ALPH or animation
// chunks); kLossy when it is a VP8 chunk (with or without VP8X and ALPH);
// kNotStill for an animation; kNotWebp when the container is malformed.
// Reads only within [data, data + size).
enum class WebpCoding { kLossless, kLossy, kNotStill, kNotWebp };
WebpCoding WebpContainerCoding(const uint8_t* data, size_t size);

// The "log" depth encoding with b bits (8..16), M = 2^b - 1: code 0 means "no
// node"; codes 1..M map depths in [near_m, far_m] logarithmically, so the
// relative error is uniform:
//   code  = 1 + round((M - 1) * ln(d / near) / ln(far / near))   (d clamped)
//   depth = near * exp((code - 1) / (M - 1) * ln(far / near))
// Codes above M are invalid. The largest relative error is
// exp(ln(far / near) / (2 (M - 1))) - 1 (0.084% for b = 12 and far / near =
// 1000). If far == near every valid code decodes to near.
struct DepthQuantization {
  double near_m = 1.0;  // Smallest encodable depth, metres, > 0.
  double far_m = 100.0; // Largest encodable depth, metres, >= near_m, finite.
  int bits = 16;        // Code bits b, 8..16.

  // near_m > 0, far_m >= near_m, both finite, far/near at most 1e9, bits 8..16.
  Status Check() const;
  // Largest valid code M = 2^bits - 1.
  int MaxCode() const { return (1 << bits) - 1; }
  // Worst-case relative depth error of this encoding.
  double MaxRelativeError() const;
};

// Depth to its code in 1..MaxCode() (clamped into [near, far]).
uint16_t QuantizeDepth(double depth_m, const DepthQuantization& q);
// Code 1..MaxCode() to depth in metres; 0 gives 0. Precondition: code <= MaxCode().
double DequantizeDepth(uint16_t code, const DepthQuantization& q);

// The octahedral normal encoding with b bits per coordinate (4..8), M = 2^b - 1:
// the unit normal n is mapped to the octahedron (u, v) = (x, y) / (|x| + |y| +
// |z|), folded for z < 0 as (u, v) <- ((1 - |v|) sgn u, (1 - |u|) sgn v) with
// sgn 0 = +1; each of u, v in [-1, 1] is stored as 1 + round((u + 1) / 2 (M - 1)),
// i.e. 1..M. The code (0, 0) means the zero normal (unlit, such as sky). A code
// with exactly one 0, or above M, is invalid. Angular error at most about
// 230 / (M - 1) degrees (0.9 degrees for b = 8).
//
// The lossy encoding ("octahedral-lossy") stores the same (u, v) as codes
// round((u + 1) * 127.5) in 0..255, every one valid, in a lossy image: the
// zero normal has no code there (the image's alpha marks it). The writer
// bounds, per tile, the mean and the 99th percentile of the angle between the
// normals it encoded and those a reader decodes, over the tile's lit present
// nodes: mean_error_deg and p99_error_deg, which the manifest declares.
struct NormalQuantization {
  NormalEncoding type = NormalEncoding::kOctahedral;
  int bits = 8;  // Bits b per coordinate, 4..8 (8 for the lossy encoding).
  // The lossy encoding's declared bounds, degrees, in (0, 90] (0 otherwise).
  double mean_error_deg = 0.0;
  double p99_error_deg = 0.0;

  bool lossy() const { return type == NormalEncoding::kOctahedralLossy; }
  Status Check() const;
  int MaxCode() const { return (1 << bits) - 1; }
};

void EncodeOctahedral(const float normal[3], const NormalQuantization& q, uint8_t code[2]);
// Returns false for an invalid code (leaving `normal` zero).
bool DecodeOctahedral(const uint8_t code[2], const NormalQuantization& q, float normal[3]);

// The lossy encoding's codes of a unit normal (0..255 each); returns false,
// writing (128, 128), for the zero (or a non-finite) normal, which this
// encoding marks outside the codes.
bool EncodeOctahedralLossy(const float normal[3], uint8_t code[2]);
// Any code pair to its unit normal.
void DecodeOctahedralLossy(const uint8_t code[2], float normal[3]);

// How a package quantizes depth and normals (the manifest's encodings).
struct TileQuantization {
  DepthQuantization depth;
  NormalQuantization normal;
  // Graph images hold each node's right and down links only (version 2.x);
  // the left and up links follow from them (CompleteLinks).
  bool right_down_links = false;

  Status Check() const;
};

// Builds the RGB image of `kind` for the tile [x0, x0+w) x [y0, y0+h) of
// `pano` (RGBA for lossy normals, alpha 255 at lit nodes and 0 at unlit
// ones; absent nodes are (0, 0, 0, 255)). Preconditions: the region lies inside the panorama, q.Check() is ok
// and every present node's depth lies in [near, far] (others are clamped).
Image8 EncodeTileImage(const TwoLayerPanorama& pano, int x0, int y0, int w, int h,
                       TileImageKind kind, const TileQuantization& q);

// Precomputed DequantizeDepth for all 65536 codes (256 KB) and
// DecodeOctahedral (or DecodeOctahedralLossy) for all 65536 code pairs (768
// KB), for fast decoding with
// exactly the values of those functions. Invalid codes decode to markers that
// FinishDecodedPanorama refuses at present nodes and clears at absent ones
// (spec/package.md Sec. 5): depth -1 for a code above the maximum, a NaN
// normal for an invalid octahedral code. With the depth-code-above-max check
// off such codes decode as the maximum; with normal-code-invalid off as the
// zero normal. Precondition: q.Check() is ok.
class TileDecoder {
 public:
  explicit TileDecoder(const TileQuantization& q, const ReaderChecks& checks = ReaderChecks());
  const TileQuantization& quantization() const { return q_; }
  const ReaderChecks& checks() const { return checks_; }
  // Depth of `code`: 0 for code 0, -1 for a code above the maximum.
  float Depth(uint16_t code) const { return table_[code]; }
  // DecodeOctahedral(code), or NaNs for an invalid code.
  const float* Normal(const uint8_t code[2]) const {
    return &normal_table_[3 * (static_cast<size_t>(code[0]) << 8 | code[1])];
  }

 private:
  TileQuantization q_;
  ReaderChecks checks_;
  std::vector<float> table_;         // 65536 depths.
  std::vector<float> normal_table_;  // 3 floats per code pair (code[0] << 8 | code[1]).
};

// Writes the content of a decoded image of `kind` into the tile [x0, x0+w) x
// [y0, y0+h) of `pano`. The image must have the size of TileImageSize (with the
// wrong-tile-size check off: at least that size, of which the top-left part is
// read) and 3 or 4 channels. The graph image sets presence, labels and links;
// the others set values whether or not a node is present, invalid codes as the
// decoder's markers (FinishDecodedPanorama clears absent nodes and refuses
// markers at present ones). The B channel of depth and normal images and any
// alpha are ignored. Returns kInvalidData for a wrong size or, naming the
// pixel, reserved flag bits (checks as in the decoder). Never reads or writes
// out of bounds. Rows are shared among `num_threads` threads (format/parallel.h;
// 0: all hardware threads); the result does not depend on it.
Status DecodeTileImage(ImageView<const uint8_t> image, TileImageKind kind, int x0, int y0, int w,
                       int h, const TileDecoder& decoder, TwoLayerPanorama* pano,
                       int num_threads = 1);

// Where FinishDecodedPanorama found its problem: the node and the kind of the
// tile image whose value is wrong (depth or normal).
struct DecodedNodeProblem {
  int x = 0, y = 0, layer = 0;
  TileImageKind kind = TileImageKind::kDepth;
};

// After all tiles are decoded: checks every present node (a depth code in
// 1..M, a depth range within 32-bit floats, a valid normal code) and zeroes
// every field of absent nodes, whatever their codes. Returns the first problem
// (by layer, then node) and, if `problem` is not null, where it is. With the
// present-node-without-depth check off a present node may keep depth 0.
// Afterwards every node value is one that TwoLayerPanorama::Validate() accepts
// (but that depth), so only the links remain to check
// (TwoLayerPanorama::ValidateLinks()).
// Nodes are shared among `num_threads` threads as in DecodeTileImage.
Status FinishDecodedPanorama(TwoLayerPanorama* pano, int num_threads = 1,
                             const ReaderChecks& checks = ReaderChecks(),
                             DecodedNodeProblem* problem = nullptr);

// For graph images of right and down links only (version 2.x,
// TileQuantization::right_down_links), after FinishDecodedPanorama: gives
// every present node the left and up links that its neighbours' right and
// down links imply (links are mutual, spec/package.md Sec. 4.1). A node
// linked into from one side by both nodes of the neighbouring pixel keeps
// the front one's link, and the back one's stays without its reverse; a
// link into an absent node gives nothing: TwoLayerPanorama::ValidateLinks
// then refuses both. A present node with left or up bits set is refused
// (kInvalidData, the first in node order in `problem`; the panorama is then
// left half completed) when the left-up-link-bits check is on, and those
// bits are dropped otherwise. One pass in place over the nodes.
Status CompleteLinks(TwoLayerPanorama* pano, const ReaderChecks& checks = ReaderChecks(),
                     DecodedNodeProblem* problem = nullptr);

}  // namespace casual3d
