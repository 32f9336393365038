#include "format/two_layer.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "format/parallel.h"

namespace casual3d {
namespace {

// Limits of spec/data-model.md, Sec. "Limits". They keep every array below
// 2^31 elements and every mesh index below 2^32.
constexpr int kMaxWidth = 32768;
constexpr int kMaxHeight = 16384;

// Tolerance on the length of a normal: |len - 1| <= kNormalLengthTolerance.
// Normals quantised to 2 x 16-bit octahedral codes are within 1e-4 of unit.
constexpr double kNormalLengthTolerance = 1e-3;
// Tolerance on R R^T = I and det R = 1 for the frame rotation.
constexpr double kRotationTolerance = 1e-6;

const char* LayerName(int l) { return l == kFront ? "front" : "back"; }
const char* DirectionName(int d) {
  static const char* const kNames[kNumDirections] = {"right", "down", "left", "up"};
  return kNames[d];
}

std::string Where(int l, int x, int y) {
  return std::string(LayerName(l)) + " node (" + std::to_string(x) + ", " + std::to_string(y) + ")";
}

Status CheckSize(const char* name, int l, size_t actual, size_t expected) {
  if (actual == expected) return Status::Ok();
  return InvalidData(std::string(LayerName(l)) + " layer: " + name + " has " +
                     std::to_string(actual) + " elements, expected " + std::to_string(expected));
}

Status ValidateFrame(const PanoramaFrame& f) {
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(f.centre[i])) return InvalidData("frame: centre is not finite");
  }
  for (int i = 0; i < 9; ++i) {
    if (!std::isfinite(f.rotation[i])) return InvalidData("frame: rotation is not finite");
  }
  const double* r = f.rotation;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const double dot =
          r[3 * i] * r[3 * j] + r[3 * i + 1] * r[3 * j + 1] + r[3 * i + 2] * r[3 * j + 2];
      if (std::fabs(dot - (i == j ? 1.0 : 0.0)) > kRotationTolerance) {
        return InvalidData("frame: rotation is not orthonormal");
      }
    }
  }
  const double det = r[0] * (r[4] * r[8] - r[5] * r[7]) - r[1] * (r[3] * r[8] - r[5] * r[6]) +
                     r[2] * (r[3] * r[7] - r[4] * r[6]);
  if (det < 0) return InvalidData("frame: rotation is a reflection (determinant -1)");
  return Status::Ok();
}

// kLinkPairs.invalid[code] for the links across one edge between pixels p and q
// (q to the right of or below p): code bits 0-1 and 2-3 hold the front and
// back links of p towards q, bits 4-5 and 6-7 those of q towards p. The edge
// is valid iff no link is the reserved value 3 and every link is answered by
// its target: a link from layer l to layer t (Link t + 1) needs the link of
// node t on the other side to be Link l + 1. An answered link also proves its
// target present, because absent nodes must have no links.
struct LinkPairTable {
  bool invalid[256];
  constexpr LinkPairTable() : invalid() {
    for (int code = 0; code < 256; ++code) {
      const int p[2] = {code & 3, (code >> 2) & 3};
      const int q[2] = {(code >> 4) & 3, (code >> 6) & 3};
      bool bad = false;
      for (int l = 0; l < kNumLayers; ++l) {
        if (p[l] == 3 || q[l] == 3) {
          bad = true;
          continue;
        }
        if (p[l] != 0 && q[p[l] - 1] != l + 1) bad = true;
        if (q[l] != 0 && p[q[l] - 1] != l + 1) bad = true;
      }
      invalid[code] = bad;
    }
  }
};
constexpr LinkPairTable kLinkPairs;

// Bits of the packed links byte per direction (two_layer.h, GetLink).
constexpr unsigned kRightBits = 0, kDownBits = 2, kLeftBits = 4, kUpBits = 6;

inline unsigned PairCode(unsigned front_p, unsigned back_p, unsigned p_shift, unsigned front_q,
                         unsigned back_q, unsigned q_shift) {
  return ((front_p >> p_shift) & 3) | (((back_p >> p_shift) & 3) << 2) |
         (((front_q >> q_shift) & 3) << 4) | (((back_q >> q_shift) & 3) << 6);
}

// Squared normal lengths that pass |sqrt(len2) - 1| <= kNormalLengthTolerance
// for sure (a margin well above double rounding); values outside this band
// but near it are decided by the exact test.
constexpr double kSureMinLength2 =
    (1.0 - kNormalLengthTolerance + 1e-9) * (1.0 - kNormalLengthTolerance + 1e-9);
constexpr double kSureMaxLength2 =
    (1.0 + kNormalLengthTolerance - 1e-9) * (1.0 + kNormalLengthTolerance - 1e-9);

// The bits of a float without its sign: zero exactly when the float == 0.0f
// (so -0.0f counts as zero, as in Validate's comparisons; NaN does not).
inline uint32_t MagnitudeBits(float v) {
  uint32_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  return bits & 0x7fffffffu;
}

// Whether node i of layer d breaks a per-node rule of Validate. Nodes come in
// long runs of present or absent ones, so the branch on `present` predicts
// well; the checks inside are combined without further branches.
inline bool NodeInvalid(const LayerData& d, size_t i) {
  const uint8_t present = d.present[i];
  const uint8_t* rgb = &d.rgb[3 * i];
  const float* nrm = &d.normal[3 * i];
  const float depth = d.depth_m[i];
  const uint8_t label = d.label[i];
  if (present == 0) {
    return ((rgb[0] | rgb[1] | rgb[2] | label | d.links[i]) |
            (MagnitudeBits(depth) | MagnitudeBits(nrm[0]) | MagnitudeBits(nrm[1]) |
             MagnitudeBits(nrm[2]))) != 0;
  }
  // depth > 0 and <= FLT_MAX is "finite and positive" (NaN fails both). A
  // non-finite normal component makes len2 infinite or NaN, which fails the
  // length test, as Validate's explicit finiteness test does.
  const double len2 = static_cast<double>(nrm[0]) * nrm[0] + static_cast<double>(nrm[1]) * nrm[1] +
                      static_cast<double>(nrm[2]) * nrm[2];
  bool normal_ok = (len2 == 0.0) | ((len2 >= kSureMinLength2) & (len2 <= kSureMaxLength2));
  if (!normal_ok) normal_ok = std::fabs(std::sqrt(len2) - 1.0) <= kNormalLengthTolerance;
  return (present > 1) | !(depth > 0.0f) | !(depth <= std::numeric_limits<float>::max()) |
         !normal_ok | (label > static_cast<uint8_t>(NodeLabel::kB));
}

}  // namespace

TwoLayerPanorama::TwoLayerPanorama(int width, int height) : width_(width), height_(height) {
  const size_t n = static_cast<size_t>(width > 0 ? width : 0) * (height > 0 ? height : 0);
  for (LayerData& layer : layers_) {
    layer.present.assign(n, 0);
    layer.rgb.assign(3 * n, 0);
    layer.depth_m.assign(n, 0.0f);
    layer.normal.assign(3 * n, 0.0f);
    layer.label.assign(n, 0);
    layer.links.assign(n, 0);
  }
}

TwoLayerPanorama TwoLayerPanorama::Unfilled(int width, int height) {
  TwoLayerPanorama p;
  p.width_ = width;
  p.height_ = height;
  const size_t n = static_cast<size_t>(width > 0 ? width : 0) * (height > 0 ? height : 0);
  for (LayerData& layer : p.layers_) {
    layer.present.resize(n);
    layer.rgb.resize(3 * n);
    layer.depth_m.resize(n);
    layer.normal.resize(3 * n);
    layer.label.resize(n);
    layer.links.resize(n);
  }
  return p;
}

bool TwoLayerPanorama::NodeDepthRange(double* near_m, double* far_m) const {
  float lo = std::numeric_limits<float>::infinity(), hi = -lo;
  for (const LayerData& L : layers_) {
    for (size_t i = 0; i < L.present.size(); ++i) {
      if (!L.present[i] || !std::isfinite(L.depth_m[i])) continue;
      lo = std::min(lo, L.depth_m[i]);
      hi = std::max(hi, L.depth_m[i]);
    }
  }
  if (!(lo <= hi)) return false;
  *near_m = lo;
  *far_m = hi;
  return true;
}

template <bool kCheckNodes>
bool TwoLayerPanorama::ScanIsValid(int num_threads) const {
  const LayerData& front = layers_[kFront];
  const LayerData& back = layers_[kBack];
  const uint8_t* front_links = front.links.data();
  const uint8_t* back_links = back.links.data();
  const size_t w = static_cast<size_t>(width_);
  // Links across the top and bottom rows point outside the panorama.
  for (size_t x = 0; x < w; ++x) {
    const size_t bottom = static_cast<size_t>(height_ - 1) * w + x;
    if (((front_links[x] | back_links[x]) >> kUpBits) & 3) return false;
    if (((front_links[bottom] | back_links[bottom]) >> kDownBits) & 3) return false;
  }
  // Bands of rows on up to num_threads threads.
  const int threads = ResolveThreads(num_threads);
  const int bands = std::min(height_, threads > 1 ? 4 * threads : 1);
  std::atomic<bool> valid(true);
  ParallelFor(0, bands, threads, [&](int64_t band) {
    int64_t y_begin, y_end;
    ChunkRange(height_, bands, band, &y_begin, &y_end);
    for (int y = static_cast<int>(y_begin); y < y_end; ++y) {
      if (!valid.load(std::memory_order_relaxed)) return;
      const size_t row = static_cast<size_t>(y) * w;
      const bool has_below = y + 1 < height_;
      bool bad = false;
      for (size_t x = 0; x < w; ++x) {
        const size_t i = row + x;
        if (kCheckNodes) {
          bad |= NodeInvalid(front, i);
          bad |= NodeInvalid(back, i);
        }
        // The edge to the right neighbour (wrapping at the seam) and the one below.
        const size_t r = x + 1 == w ? row : i + 1;
        bad |= kLinkPairs.invalid[PairCode(front_links[i], back_links[i], kRightBits,
                                           front_links[r], back_links[r], kLeftBits)];
        if (has_below) {
          const size_t b = i + w;
          bad |= kLinkPairs.invalid[PairCode(front_links[i], back_links[i], kDownBits,
                                             front_links[b], back_links[b], kUpBits)];
        }
      }
      if (bad) {
        valid.store(false, std::memory_order_relaxed);
        return;
      }
    }
  });
  return valid.load();
}

Status TwoLayerPanorama::Validate(int num_threads, NodeProblem* where) const {
  return Check(true, num_threads, where);
}
Status TwoLayerPanorama::ValidateLinks(int num_threads, NodeProblem* where) const {
  return Check(false, num_threads, where);
}

Status TwoLayerPanorama::Check(bool nodes, int num_threads, NodeProblem* where) const {
  if (where != nullptr) *where = NodeProblem();
  if (width_ < 1 || height_ < 1) {
    return InvalidData("panorama size " + std::to_string(width_) + "x" + std::to_string(height_) +
                       " is empty");
  }
  if (width_ > kMaxWidth || height_ > kMaxHeight) {
    return LimitExceeded("panorama size " + std::to_string(width_) + "x" + std::to_string(height_) +
                         " exceeds the limit of " + std::to_string(kMaxWidth) + "x" +
                         std::to_string(kMaxHeight));
  }
  CASUAL3D_RETURN_IF_ERROR(ValidateFrame(frame_));
  if (view_hints_) {
    const Status hints = view_hints_->Validate();
    if (!hints.ok()) return Status(hints.code(), "view hints: " + hints.message());
  }
  const size_t n = static_cast<size_t>(width_) * height_;
  for (int l = 0; l < kNumLayers; ++l) {
    const LayerData& d = layers_[l];
    CASUAL3D_RETURN_IF_ERROR(CheckSize("present", l, d.present.size(), n));
    CASUAL3D_RETURN_IF_ERROR(CheckSize("rgb", l, d.rgb.size(), 3 * n));
    CASUAL3D_RETURN_IF_ERROR(CheckSize("depth_m", l, d.depth_m.size(), n));
    CASUAL3D_RETURN_IF_ERROR(CheckSize("normal", l, d.normal.size(), 3 * n));
    CASUAL3D_RETURN_IF_ERROR(CheckSize("label", l, d.label.size(), n));
    CASUAL3D_RETURN_IF_ERROR(CheckSize("links", l, d.links.size(), n));
  }
  // Valid panoramas (the common case: every level the viewer shows) pass one
  // fast scan; only a rejected one is scanned again, node by node, to name its
  // first problem in the order documented below.
  if (nodes ? ScanIsValid<true>(num_threads) : ScanIsValid<false>(num_threads)) return Status::Ok();
  return FirstNodeOrLinkProblem(where);
}

Status TwoLayerPanorama::FirstNodeOrLinkProblem(NodeProblem* where) const {
  NodeProblem unused;
  if (where == nullptr) where = &unused;
  // Per-node values first, so that the link pass can rely on `present` being 0 or 1.
  for (int l = 0; l < kNumLayers; ++l) {
    const LayerData& d = layers_[l];
    for (int y = 0; y < height_; ++y) {
      for (int x = 0; x < width_; ++x) {
        *where = NodeProblem{l, x, y};
        const size_t i = index(x, y);
        const float* nrm = &d.normal[3 * i];
        if (d.present[i] > 1) {
          return InvalidData(Where(l, x, y) + ": present flag " + std::to_string(d.present[i]) +
                             " is not 0 or 1");
        }
        if (!d.present[i]) {
          if (d.rgb[3 * i] || d.rgb[3 * i + 1] || d.rgb[3 * i + 2] || d.depth_m[i] != 0.0f ||
              nrm[0] != 0.0f || nrm[1] != 0.0f || nrm[2] != 0.0f || d.label[i] || d.links[i]) {
            return InvalidData(Where(l, x, y) + ": absent node has non-zero fields");
          }
          continue;
        }
        if (!std::isfinite(d.depth_m[i]) || !(d.depth_m[i] > 0.0f)) {
          return InvalidData(Where(l, x, y) + ": depth " + std::to_string(d.depth_m[i]) +
                             " m is not finite and positive");
        }
        if (!std::isfinite(nrm[0]) || !std::isfinite(nrm[1]) || !std::isfinite(nrm[2])) {
          return InvalidData(Where(l, x, y) + ": normal is not finite");
        }
        const double len2 = static_cast<double>(nrm[0]) * nrm[0] +
                            static_cast<double>(nrm[1]) * nrm[1] +
                            static_cast<double>(nrm[2]) * nrm[2];
        if (len2 != 0.0 && std::fabs(std::sqrt(len2) - 1.0) > kNormalLengthTolerance) {
          return InvalidData(Where(l, x, y) + ": normal has length " +
                             std::to_string(std::sqrt(len2)) + ", expected 1 or 0");
        }
        if (d.label[i] > static_cast<uint8_t>(NodeLabel::kB)) {
          return InvalidData(Where(l, x, y) + ": label " + std::to_string(d.label[i]) +
                             " is not 0 (F) or 1 (B)");
        }
      }
    }
  }
  for (int l = 0; l < kNumLayers; ++l) {
    const LayerData& d = layers_[l];
    for (int y = 0; y < height_; ++y) {
      for (int x = 0; x < width_; ++x) {
        const size_t i = index(x, y);
        if (!d.present[i]) continue;
        for (int di = 0; di < kNumDirections; ++di) {
          const Direction dir = static_cast<Direction>(di);
          const Link link = GetLink(d.links[i], dir);
          if (link == Link::kNone) continue;
          *where = NodeProblem{l, x, y, true};
          if (static_cast<int>(link) > static_cast<int>(Link::kBack)) {
            return InvalidData(Where(l, x, y) + ": " + DirectionName(di) +
                               " link has the reserved value 3");
          }
          int nx, ny;
          if (!Neighbour(x, y, dir, &nx, &ny)) {
            return InvalidData(Where(l, x, y) + ": " + DirectionName(di) +
                               " link points outside the panorama (rows do not wrap)");
          }
          where->target_x = nx;
          where->target_y = ny;
          const int target_layer = link == Link::kFront ? kFront : kBack;
          const LayerData& t = layers_[target_layer];
          const size_t j = index(nx, ny);
          if (!t.present[j]) {
            return InvalidData(Where(l, x, y) + ": " + DirectionName(di) + " link points at " +
                               Where(target_layer, nx, ny) + ", which is absent");
          }
          const Link back = GetLink(t.links[j], Opposite(dir));
          const Link expected = l == kFront ? Link::kFront : Link::kBack;
          if (back != expected) {
            return InvalidData(Where(l, x, y) + ": " + DirectionName(di) + " link to " +
                               Where(target_layer, nx, ny) + " is not mutual");
          }
        }
      }
    }
  }
  *where = NodeProblem();
  return Status::Ok();
}

bool TwoLayerPanorama::operator==(const TwoLayerPanorama& o) const {
  if (width_ != o.width_ || height_ != o.height_) return false;
  for (int i = 0; i < 3; ++i) {
    if (frame_.centre[i] != o.frame_.centre[i]) return false;
  }
  for (int i = 0; i < 9; ++i) {
    if (frame_.rotation[i] != o.frame_.rotation[i]) return false;
  }
  if (view_hints_ != o.view_hints_) return false;
  for (int l = 0; l < kNumLayers; ++l) {
    const LayerData& a = layers_[l];
    const LayerData& b = o.layers_[l];
    if (a.present != b.present || a.rgb != b.rgb || a.depth_m != b.depth_m ||
        a.normal != b.normal || a.label != b.label || a.links != b.links) {
      return false;
    }
  }
  return true;
}

}  // namespace casual3d
