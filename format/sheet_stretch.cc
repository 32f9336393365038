#include "format/sheet_stretch.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace casual3d {
namespace {

void Direction(const float p[3], const double from[3], double out[3]) {
  const double d[3] = {p[0] - from[0], p[1] - from[1], p[2] - from[2]};
  const double n = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  for (int k = 0; k < 3; ++k) out[k] = n > 0 ? d[k] / n : 0.0;
}

double Dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Gram matrix (g11, g12, g22) of the edges of directions d0, d1, d2.
void Gram(const double d[3][3], double g[3]) {
  double e1[3], e2[3];
  for (int k = 0; k < 3; ++k) {
    e1[k] = d[1][k] - d[0][k];
    e2[k] = d[2][k] - d[0][k];
  }
  g[0] = Dot(e1, e1);
  g[1] = Dot(e1, e2);
  g[2] = Dot(e2, e2);
}

}  // namespace

double SmallerGeneralisedEigenvalue(const double gu[3], const double ge[3]) {
  // det(Gu - l Ge) = A l^2 - B l + C.
  const double A = ge[0] * ge[2] - ge[1] * ge[1];
  const double B = gu[0] * ge[2] + gu[2] * ge[0] - 2.0 * gu[1] * ge[1];
  const double C = gu[0] * gu[2] - gu[1] * gu[1];
  if (!(A > 0)) return -1.0;
  const double disc = std::max(0.0, B * B - 4.0 * A * C);
  const double big = B + std::sqrt(disc);  // 2 A times the larger root.
  return big > 0 ? std::max(0.0, 2.0 * C / big) : 0.0;
}

double SheetStretch(const float a[3], const float b[3], const float c[3], const double eye[3]) {
  static const double kCentre[3] = {0, 0, 0};
  const float* p[3] = {a, b, c};
  double u[3][3], e[3][3];
  for (int k = 0; k < 3; ++k) {
    Direction(p[k], kCentre, u[k]);
    Direction(p[k], eye, e[k]);
  }
  double gu[3], ge[3];
  Gram(u, gu);
  Gram(e, ge);
  const double l = SmallerGeneralisedEigenvalue(gu, ge);
  if (l < 0) return 0.0;
  if (l == 0) return std::numeric_limits<double>::infinity();
  return 1.0 / std::sqrt(l);
}

}  // namespace casual3d
