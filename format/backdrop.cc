#include "format/backdrop.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <cmath>
#include <string>
#include <vector>

#include "format/mesh_builder.h"

namespace casual3d {
namespace {


// Per cell: the largest node depth (either layer), 0 for a cell without
// nodes, and the mean colour of the cell's nodes within 5% of it (the
// background's colour where the cell holds a depth edge).
struct Cells {
  int nx = 0, ny = 0;
  std::vector<float> far;
  std::vector<uint8_t> rgb;
};

Cells CellFarDepths(const TwoLayerPanorama& pano, int cell, int cells_x, int cells_y) {
  Cells cells;
  cells.nx = cells_x;
  cells.ny = cells_y;
  cells.far.assign(static_cast<size_t>(cells_x) * cells_y, 0.0f);
  for (int y = 0; y < pano.height(); ++y) {
    float* row = &cells.far[static_cast<size_t>(y / cell) * cells_x];
    for (int x = 0; x < pano.width(); ++x) {
      for (int l = 0; l < kNumLayers; ++l) {
        if (!pano.present(l, x, y)) continue;
        float& f = row[x / cell];
        f = std::max(f, pano.layer(l).depth_m[pano.index(x, y)]);
      }
    }
  }
  std::vector<uint32_t> sum(3 * cells.far.size(), 0), count(cells.far.size(), 0);
  for (int y = 0; y < pano.height(); ++y) {
    for (int x = 0; x < pano.width(); ++x) {
      const size_t c = static_cast<size_t>(y / cell) * cells_x + x / cell;
      for (int l = 0; l < kNumLayers; ++l) {
        if (!pano.present(l, x, y)) continue;
        const size_t i = pano.index(x, y);
        if (pano.layer(l).depth_m[i] < 0.95f * cells.far[c]) continue;
        for (int k = 0; k < 3; ++k) sum[3 * c + k] += pano.layer(l).rgb[3 * i + k];
        ++count[c];
      }
    }
  }
  cells.rgb.assign(3 * cells.far.size(), 0);
  for (size_t c = 0; c < cells.far.size(); ++c) {
    if (count[c] == 0) continue;
    for (int k = 0; k < 3; ++k)
      cells.rgb[3 * c + k] = static_cast<uint8_t>((sum[3 * c + k] + count[c] / 2) / count[c]);
  }
  return cells;
}

// For each cell, the index of the cell of largest far depth within `r` cells
// (square window; columns wrap, rows clamp; the first in row-major order
// among equals), by two separable passes; SIZE_MAX where the window has no
// node. A cell is keyed by its far depth's bits (positive floats order as
// their bits do) above its inverted index, so one integer maximum picks it.
std::vector<size_t> SpreadFar(const Cells& cells, int r) {
  const int nx = cells.nx, ny = cells.ny;
  const size_t n = cells.far.size();
  std::vector<uint64_t> key(n), rows(n);
  for (size_t c = 0; c < n; ++c) {
    uint32_t bits;
    std::memcpy(&bits, &cells.far[c], sizeof bits);
    key[c] = cells.far[c] > 0.0f ? (uint64_t{bits} << 32) | (UINT32_MAX - static_cast<uint32_t>(c)) : 0;
  }
  const int left = std::min(r, nx / 2), right = std::min(r, (nx - 1) / 2);
  for (int y = 0; y < ny; ++y) {
    const uint64_t* in = &key[static_cast<size_t>(y) * nx];
    uint64_t* out = &rows[static_cast<size_t>(y) * nx];
    for (int x = 0; x < nx; ++x) {
      uint64_t m = 0;
      if (x - left >= 0 && x + right < nx) {
        for (int k = x - left; k <= x + right; ++k) m = std::max(m, in[k]);
      } else {
        for (int d = -left; d <= right; ++d) m = std::max(m, in[((x + d) % nx + nx) % nx]);
      }
      out[x] = m;
    }
  }
  std::vector<uint64_t> column(static_cast<size_t>(nx));
  std::vector<size_t> result(n, SIZE_MAX);
  for (int y = 0; y < ny; ++y) {
    const int y0 = std::max(0, y - r), y1 = std::min(ny - 1, y + r);
    std::fill(column.begin(), column.end(), 0);
    for (int k = y0; k <= y1; ++k) {
      const uint64_t* row = &rows[static_cast<size_t>(k) * nx];
      for (int x = 0; x < nx; ++x) column[x] = std::max(column[x], row[x]);
    }
    for (int x = 0; x < nx; ++x) {
      if (column[x] != 0)
        result[static_cast<size_t>(y) * nx + x] = UINT32_MAX - static_cast<uint32_t>(column[x] & UINT32_MAX);
    }
  }
  return result;
}

// Replaces `values` (`channels` interleaved per cell) by their sums over the
// square window of `r` cells around each cell (columns wrap, rows stop at the
// edges), by two separable passes that add each window's values in the same
// order: the same doubles in the Emscripten build, and no cancellation where a
// large value leaves a window of small ones (as running sums would have).
// O(r) per cell and channel.
void BoxSums(int nx, int ny, int channels, int r, std::vector<double>* values) {
  const size_t ch = static_cast<size_t>(channels);
  const size_t row_len = static_cast<size_t>(nx) * ch;
  const int left = std::min(r, nx / 2), right = std::min(r, (nx - 1) / 2);
  std::vector<double> rows(values->size(), 0.0);
  for (int y = 0; y < ny; ++y) {
    const double* in = &(*values)[static_cast<size_t>(y) * row_len];
    double* out = &rows[static_cast<size_t>(y) * row_len];
    for (int x = 0; x < nx; ++x) {
      const bool inside = x - left >= 0 && x + right < nx;  // No wrap: no modulo.
      for (int d = -left; d <= right; ++d) {
        const int column = inside ? x + d : ((x + d) % nx + nx) % nx;
        const size_t from = static_cast<size_t>(column) * ch;
        for (size_t k = 0; k < ch; ++k) out[x * ch + k] += in[from + k];
      }
    }
  }
  for (int y = 0; y < ny; ++y) {
    double* out = &(*values)[static_cast<size_t>(y) * row_len];
    std::fill(out, out + row_len, 0.0);
    for (int k = std::max(0, y - r); k <= std::min(ny - 1, y + r); ++k) {
      const double* in = &rows[static_cast<size_t>(k) * row_len];
      for (size_t i = 0; i < row_len; ++i) out[i] += in[i];
    }
  }
}

// The backdrop's colour around each cell: the mean colour of the cells with
// nodes within `r`, each weighted by (f / F)^4, where f is its far depth
// clipped to 1.5 times the mean far depth of the other cells with nodes
// within `r` of it (unclipped without such cells) and F the largest f. Farther
// surfaces outweigh nearer ones (twice as far, 16 times the weight), so the
// colour is the background's where the window holds some; one cell of far
// outliers (the noisy depth of a real capture) weighs at most 1.5^4 = 5
// times a cell of the surface around it. A blurred fill that follows the
// surface it shows through, as an inpainting would give. Cells whose far
// depth is not finite take no part.
std::vector<uint8_t> BlurredFarColors(const Cells& cells, int r) {
  const int nx = cells.nx, ny = cells.ny;
  const size_t n = cells.far.size();
  constexpr double kClip = 1.5;
  auto measured = [&](size_t c) { return cells.far[c] > 0.0f && std::isfinite(cells.far[c]); };
  std::vector<double> local(2 * n, 0.0);  // Far depth and count, then their window sums.
  for (size_t c = 0; c < n; ++c) {
    if (!measured(c)) continue;
    local[2 * c] = cells.far[c];
    local[2 * c + 1] = 1.0;
  }
  BoxSums(nx, ny, 2, r, &local);
  std::vector<double> clipped(n, 0.0);
  double farthest = 0.0;
  for (size_t c = 0; c < n; ++c) {
    if (!measured(c)) continue;
    const double far = cells.far[c], others = local[2 * c + 1] - 1.0;
    clipped[c] = others > 0.0 ? std::min(far, kClip * (local[2 * c] - far) / others) : far;
    farthest = std::max(farthest, clipped[c]);
  }
  std::vector<double> weighted(4 * n, 0.0);
  for (size_t c = 0; c < n; ++c) {
    if (!measured(c)) continue;
    const double f = clipped[c] / farthest;
    const double w = (f * f) * (f * f);
    for (int k = 0; k < 3; ++k) weighted[4 * c + k] = w * cells.rgb[3 * c + k];
    weighted[4 * c + 3] = w;
  }
  BoxSums(nx, ny, 4, r, &weighted);
  std::vector<uint8_t> rgb(3 * n, 0);
  for (size_t c = 0; c < n; ++c) {
    const double w = weighted[4 * c + 3];
    if (!(w > 0.0)) continue;
    for (int k = 0; k < 3; ++k) {
      rgb[3 * c + k] = static_cast<uint8_t>(std::clamp(std::floor(weighted[4 * c + k] / w + 0.5), 0.0, 255.0));
    }
  }
  return rgb;
}

}  // namespace

Status BackdropOptions::Check() const {
  if (cell_px < 0 || cell_px > 256) {
    return InvalidArgument("cell_px " + std::to_string(cell_px) + " is outside [0, 256]");
  }
  if (spread_px < 0 || spread_px > 4096) {
    return InvalidArgument("spread_px " + std::to_string(spread_px) + " is outside [0, 4096]");
  }
  if (!(depth_factor >= 1.0 && depth_factor <= 2.0)) {
    return InvalidArgument("depth_factor " + std::to_string(depth_factor) + " is outside [1, 2]");
  }
  if (max_pixels < 1 || max_pixels > kMeshPixelLimit) {
    return InvalidArgument("max_pixels " + std::to_string(max_pixels) + " is outside [1, " +
                           std::to_string(kMeshPixelLimit) + "]");
  }
  return Status::Ok();
}

int BackdropCellPixels(const BackdropOptions& options, int width) {
  if (options.cell_px > 0) return options.cell_px;
  return std::max(1, static_cast<int>(std::lround(width / 1024.0)));
}

int BackdropSpreadPixels(const BackdropOptions& options, int width) {
  if (options.spread_px > 0) return options.spread_px;
  return static_cast<int>(std::lround(0.012 * width));
}

StatusOr<Mesh> BuildBackdrop(const TwoLayerPanorama& pano, const BackdropOptions& options) {
  CASUAL3D_RETURN_IF_ERROR(options.Check());
  CASUAL3D_RETURN_IF_ERROR(CheckMeshInput(pano, options.max_pixels, /*validate=*/false));
  const int w = pano.width(), h = pano.height();
  const int cell = BackdropCellPixels(options, w);
  const int cells_x = (w + cell - 1) / cell, cells_y = (h + cell - 1) / cell;
  const Cells cells = CellFarDepths(pano, cell, cells_x, cells_y);
  const std::vector<float>& far = cells.far;
  const int reach = 1 + (BackdropSpreadPixels(options, w) + cell - 1) / cell;
  const std::vector<size_t> source = SpreadFar(cells, reach);
  // Colour from a quarter of the reach (at most 16 cells): the surface around
  // the vertex, which the backdrop shows through where a sheet between its
  // nodes is left out.
  const std::vector<uint8_t> colors = BlurredFarColors(cells, std::clamp(reach / 4, 1, 16));

  // Vertex grid: columns 0..cells_x (column cells_x is the seam copy of
  // column 0, at pixel x = w), rows 0..rows-1 at pixel y = j * cell.
  const int rows = (h - 1) / cell + 1;
  const int cols = cells_x + 1;
  // Quads: cell (i, j) with a node, and a row of vertices below it.
  std::vector<uint32_t> vertex_of(static_cast<size_t>(cols) * rows, UINT32_MAX);
  std::vector<std::pair<int, int>> quads;
  for (int j = 0; j + 1 < rows; ++j) {
    for (int i = 0; i < cells_x; ++i) {
      if (far[static_cast<size_t>(j) * cells_x + i] <= 0.0f) continue;
      quads.emplace_back(i, j);
      for (int dj = 0; dj < 2; ++dj) {
        for (int di = 0; di < 2; ++di) vertex_of[static_cast<size_t>(j + dj) * cols + i + di] = 0;
      }
    }
  }

  Mesh mesh;
  uint32_t count = 0;
  for (uint32_t& v : vertex_of) {
    if (v != UINT32_MAX) v = count++;
  }
  mesh.positions.resize(3 * static_cast<size_t>(count));
  mesh.normals.assign(3 * static_cast<size_t>(count), 0.0f);
  mesh.uvs.resize(2 * static_cast<size_t>(count));
  mesh.colors.resize(3 * static_cast<size_t>(count));
  // Longitude of each vertex column (the seam copy's is column 0's).
  std::vector<double> sin_lon(static_cast<size_t>(cols)), cos_lon(static_cast<size_t>(cols));
  for (int i = 0; i < cols; ++i) {
    const int px = std::min(i * cell, w) % w;
    DeterministicSinCos(((px + 0.5) / w - 0.5) * 2.0 * kPi, &sin_lon[i], &cos_lon[i]);
  }
  for (int j = 0; j < rows; ++j) {
    const int y = j * cell;
    double sin_lat, cos_lat;
    DeterministicSinCos((0.5 - (y + 0.5) / h) * kPi, &sin_lat, &cos_lat);
    for (int i = 0; i < cols; ++i) {
      const uint32_t v = vertex_of[static_cast<size_t>(j) * cols + i];
      if (v == UINT32_MAX) continue;
      const int x = std::min(i * cell, w);  // w: the seam copy of column 0.
      // Every vertex of a quad has a node in its window (the quad's cell).
      const size_t from = source[static_cast<size_t>(j) * cells_x + i % cells_x];
      const double d = far[from] * options.depth_factor;
      float* position = &mesh.positions[3 * static_cast<size_t>(v)];
      position[0] = static_cast<float>(cos_lat * d * sin_lon[i]);
      position[1] = static_cast<float>(sin_lat * d);
      position[2] = static_cast<float>(-(cos_lat * d * cos_lon[i]));
      float* uv = &mesh.uvs[2 * static_cast<size_t>(v)];
      uv[0] = static_cast<float>((x + 0.5) / w);
      uv[1] = static_cast<float>((y + 0.5 + h) / (2.0 * h));
      const size_t own = static_cast<size_t>(j) * cells_x + i % cells_x;  // rows == cells_y.
      for (int c = 0; c < 3; ++c) mesh.colors[3 * static_cast<size_t>(v) + c] = colors[3 * own + c];
    }
  }
  mesh.indices.reserve(6 * quads.size());
  for (const auto& [i, j] : quads) {
    const uint32_t a = vertex_of[static_cast<size_t>(j) * cols + i];
    const uint32_t b = vertex_of[static_cast<size_t>(j) * cols + i + 1];
    const uint32_t c = vertex_of[static_cast<size_t>(j + 1) * cols + i];
    const uint32_t d = vertex_of[static_cast<size_t>(j + 1) * cols + i + 1];
    // Counter-clockwise seen from the centre, as the mesh's quads (B, A, D), (C, D, A).
    mesh.indices.insert(mesh.indices.end(), {b, a, d, c, d, a});
  }
  return mesh;
}

void AppendMesh(const Mesh& extra, Mesh* mesh) {
  const uint32_t offset = static_cast<uint32_t>(mesh->num_vertices());
  mesh->positions.insert(mesh->positions.end(), extra.positions.begin(), extra.positions.end());
  mesh->normals.insert(mesh->normals.end(), extra.normals.begin(), extra.normals.end());
  mesh->uvs.insert(mesh->uvs.end(), extra.uvs.begin(), extra.uvs.end());
  mesh->colors.insert(mesh->colors.end(), extra.colors.begin(), extra.colors.end());
  mesh->indices.reserve(mesh->indices.size() + extra.indices.size());
  for (uint32_t i : extra.indices) mesh->indices.push_back(i + offset);
}

}  // namespace casual3d
