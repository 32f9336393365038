#include "reconstruct/eval/captured_field.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "format/mesh_builder.h"

namespace casual3d::eval {
namespace {

using Grid = std::vector<unsigned char>;

// Max (dilate) or min (erode) over a (2r + 1)^2 window: columns wrap, rows
// are clamped to the grid (the poles neither grow nor eat the content).
Grid Morph(const Grid& in, int w, int h, int r, bool dilate) {
  Grid rows(in.size()), out(in.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      unsigned char v = dilate ? 0 : 1;
      for (int dx = -r; dx <= r; ++dx) {
        const unsigned char c = in[size_t(y) * w + WrapColumn(x + dx, w)];
        v = dilate ? std::max(v, c) : std::min(v, c);
      }
      rows[size_t(y) * w + x] = v;
    }
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      unsigned char v = dilate ? 0 : 1;
      for (int dy = std::max(0, y - r); dy <= std::min(h - 1, y + r); ++dy) {
        const unsigned char c = rows[size_t(dy) * w + x];
        v = dilate ? std::max(v, c) : std::min(v, c);
      }
      out[size_t(y) * w + x] = v;
    }
  return out;
}

// Median front depth of each cell (0 where it has no front node).
std::vector<float> CellDepths(const TwoLayerPanorama& pano, int cell, int gw, int gh) {
  std::vector<float> out(size_t(gw) * gh, 0.0f), values;
  const LayerData& front = pano.layer(kFront);
  for (int cy = 0; cy < gh; ++cy)
    for (int cx = 0; cx < gw; ++cx) {
      values.clear();
      for (int y = cy * cell; y < std::min(pano.height(), (cy + 1) * cell); ++y)
        for (int x = cx * cell; x < std::min(pano.width(), (cx + 1) * cell); ++x) {
          const size_t i = pano.index(x, y);
          if (front.present[i] && std::isfinite(front.depth_m[i]) && front.depth_m[i] > 0)
            values.push_back(front.depth_m[i]);
        }
      if (values.empty()) continue;
      std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
      out[size_t(cy) * gw + cx] = values[values.size() / 2];
    }
  return out;
}

// Gives every content cell without a depth the mean of its neighbours that
// have one, pass after pass (each pass reads the previous one's depths).
void FillDepths(const Grid& cells, int gw, int gh, std::vector<float>* depth) {
  for (bool changed = true; changed;) {
    changed = false;
    std::vector<float> next = *depth;
    for (int y = 0; y < gh; ++y)
      for (int x = 0; x < gw; ++x) {
        const size_t i = size_t(y) * gw + x;
        if (!cells[i] || (*depth)[i] > 0) continue;
        double sum = 0;
        int n = 0;
        const int nx[4] = {WrapColumn(x + 1, gw), WrapColumn(x - 1, gw), x, x};
        const int ny[4] = {y, y, y - 1, y + 1};
        for (int k = 0; k < 4; ++k) {
          if (ny[k] < 0 || ny[k] >= gh) continue;
          const float d = (*depth)[size_t(ny[k]) * gw + nx[k]];
          if (d > 0) sum += d, ++n;
        }
        if (n > 0) next[i] = static_cast<float>(sum / n), changed = true;
      }
    *depth = std::move(next);
  }
}

// The cells of `cells` plus its holes that `closed` (its closing) covers
// whole: 4-connected components of non-content cells (columns wrap, rows do
// not) all of whose cells are in `closed`. A notch of the outline belongs to
// the component outside the content, which reaches beyond the closing, so it
// stays out.
Grid AddNarrowHoles(const Grid& cells, const Grid& closed, int gw, int gh) {
  Grid out = cells;
  std::vector<int> seen(cells.size(), 0), component, stack;
  for (size_t start = 0; start < cells.size(); ++start) {
    if (cells[start] || seen[start]) continue;
    component.clear();
    stack.assign(1, static_cast<int>(start));
    seen[start] = 1;
    bool enclosed = true;
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      component.push_back(i);
      enclosed = enclosed && closed[i];
      const int x = i % gw, y = i / gw;
      const int nx[4] = {WrapColumn(x + 1, gw), WrapColumn(x - 1, gw), x, x};
      const int ny[4] = {y, y, y - 1, y + 1};
      for (int k = 0; k < 4; ++k) {
        if (ny[k] < 0 || ny[k] >= gh) continue;
        const int j = ny[k] * gw + nx[k];
        if (cells[j] || seen[j]) continue;
        seen[j] = 1;
        stack.push_back(j);
      }
    }
    if (enclosed)
      for (const int i : component) out[i] = 1;
  }
  return out;
}

bool WithinExtent(const ViewHints& hints, double lon_deg, double lat_deg) {
  if (lat_deg < hints.content_pitch_min_deg || lat_deg > hints.content_pitch_max_deg) return false;
  const double span = hints.content_yaw_max_deg - hints.content_yaw_min_deg;
  double offset = std::fmod(lon_deg - hints.content_yaw_min_deg, 360.0);
  if (offset < 0) offset += 360.0;
  return span >= 360.0 || offset <= span;
}

}  // namespace

CapturedField::CapturedField(const TwoLayerPanorama& pano, const ViewHints& hints,
                             double closing_deg) {
  if (!(closing_deg >= 0 && closing_deg <= 45))
    throw std::invalid_argument("captured field: closing_deg " + std::to_string(closing_deg) +
                                " is outside [0, 45]");
  const int w = pano.width(), h = pano.height();
  const int cell = std::max(1, static_cast<int>(std::lround(w / 512.0)));
  width_ = w;
  height_ = h;
  cell_px_ = cell;
  grid_width_ = (w + cell - 1) / cell;
  grid_height_ = (h + cell - 1) / cell;
  const int gw = grid_width_, gh = grid_height_;
  std::vector<int> count(size_t(gw) * gh, 0), total(count.size(), 0);
  const LayerData& front = pano.layer(kFront);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t c = size_t(y / cell) * gw + x / cell;
      ++total[c];
      count[c] += front.present[pano.index(x, y)] != 0;
    }
  cells_.assign(count.size(), 0);
  for (int cy = 0; cy < gh; ++cy)
    for (int cx = 0; cx < gw; ++cx) {
      const size_t c = size_t(cy) * gw + cx;
      const double u = 0.5 * (cx * cell + std::min(w, (cx + 1) * cell));
      const double v = 0.5 * (cy * cell + std::min(h, (cy + 1) * cell));
      cells_[c] = 2 * count[c] > total[c] &&
                  WithinExtent(hints, (u / w - 0.5) * 360.0, (0.5 - v / h) * 180.0);
    }
  const double cell_deg = 360.0 * cell / w;
  const int r = static_cast<int>(std::ceil(closing_deg / cell_deg - 1e-9));
  if (r > 0)
    cells_ = AddNarrowHoles(cells_, Morph(Morph(cells_, gw, gh, r, true), gw, gh, r, false), gw, gh);

  // The proxy surface.
  std::vector<float> depth = CellDepths(pano, cell, gw, gh);
  for (size_t c = 0; c < cells_.size(); ++c)
    if (!cells_[c]) depth[c] = 0;
  FillDepths(cells_, gw, gh, &depth);
  TwoLayerPanorama proxy(gw, gh);
  LayerData& p = proxy.layer(kFront);
  for (size_t c = 0; c < cells_.size(); ++c) {
    if (!cells_[c] || !(depth[c] > 0)) continue;
    p.present[c] = 1;
    p.depth_m[c] = depth[c];
  }
  for (int y = 0; y < gh; ++y)
    for (int x = 0; x < gw; ++x) {
      if (!p.present[proxy.index(x, y)]) continue;
      for (const Direction d : {kRight, kDown}) {
        int nx, ny;
        if (!proxy.Neighbour(x, y, d, &nx, &ny) || (nx == x && ny == y)) continue;
        if (!p.present[proxy.index(nx, ny)]) continue;
        uint8_t& a = p.links[proxy.index(x, y)];
        uint8_t& b = p.links[proxy.index(nx, ny)];
        a = SetLink(a, d, Link::kFront);
        b = SetLink(b, Opposite(d), Link::kFront);
      }
    }
  MeshBuildOptions build;
  build.include_back_layer = false;
  StatusOr<Mesh> mesh = BuildMesh(proxy, build);
  if (!mesh.ok()) throw std::runtime_error("captured field proxy: " + mesh.status().message());
  proxy_ = std::move(*mesh);
}

Image8 CapturedField::Mask(const render::PinholeView& view,
                           const render::RenderOptions& options) const {
  render::RenderOptions o = options;
  o.color_source = render::ColorSource::kVertexColors;
  o.want_triangle_ids = false;
  o.sheet_stretch = 0;  // The field's proxy surface is drawn whole.
  return render::RenderMesh(proxy_, {}, view, o).mask;
}

bool CapturedField::Contains(const Vec3d& d) const {
  double lon, lat;
  DirectionToLonLat(d, &lon, &lat);
  // The panorama pixel of the direction, then its cell.
  const int px = std::clamp(static_cast<int>((lon / (2 * kPi) + 0.5) * width_), 0, width_ - 1);
  const int py = std::clamp(static_cast<int>((0.5 - lat / kPi) * height_), 0, height_ - 1);
  return cell(px / cell_px_, py / cell_px_);
}

}  // namespace casual3d::eval
