#pragma once

// The equirectangular projection and axis convention of casual3d, used by every
// stage and by the viewer. spec/projection.md is the normative text; this header
// is its one implementation.
//
// Panorama frame: right-handed, +X right, +Y up, -Z forward (as OpenGL and glTF).
// Longitude lon in [-pi, pi): 0 looks along -Z (forward), +pi/2 along +X (right).
// Latitude  lat in [-pi/2, pi/2]: +pi/2 is straight up (+Y).
//   direction(lon, lat) = (cos(lat) sin(lon), sin(lat), -cos(lat) cos(lon))
// Pixel coordinates (u, v) are continuous; pixel (i, j) covers [i, i+1) x [j, j+1)
// and its centre is (i + 0.5, j + 0.5). Column 0 starts at lon = -pi (behind),
// row 0 starts at the zenith:
//   lon = (u / width - 0.5) * 2 pi,   lat = (0.5 - v / height) * pi
// Columns wrap: column -1 is column width-1 (the seam at +-180 degrees). Rows do
// not wrap: rows above 0 or below height-1 do not exist.

#include <cmath>

namespace casual3d {

constexpr double kPi = 3.14159265358979323846;

struct Vec3d {
  double x = 0, y = 0, z = 0;
};

inline Vec3d LonLatToDirection(double lon_rad, double lat_rad) {
  const double c = std::cos(lat_rad);
  return {c * std::sin(lon_rad), std::sin(lat_rad), -c * std::cos(lon_rad)};
}

// `d` need not be unit length; the zero vector maps to (0, 0).
inline void DirectionToLonLat(const Vec3d& d, double* lon_rad, double* lat_rad) {
  const double horizontal = std::sqrt(d.x * d.x + d.z * d.z);
  *lon_rad = std::atan2(d.x, 0.0 - d.z);  // 0 - z: atan2(0, -0.0) would give pi.
  *lat_rad = std::atan2(d.y, horizontal);
}

// Continuous pixel coordinates to a unit direction in the panorama frame.
inline Vec3d EquirectPixelToDirection(double u, double v, int width, int height) {
  const double lon = (u / width - 0.5) * 2.0 * kPi;
  const double lat = (0.5 - v / height) * kPi;
  return LonLatToDirection(lon, lat);
}

// Unit direction to continuous pixel coordinates; u in [0, width], v in [0, height].
inline void DirectionToEquirectPixel(const Vec3d& d, int width, int height, double* u, double* v) {
  double lon, lat;
  DirectionToLonLat(d, &lon, &lat);
  *u = (lon / (2.0 * kPi) + 0.5) * width;
  *v = (0.5 - lat / kPi) * height;
}

// Wraps a column index into [0, width).
inline int WrapColumn(int x, int width) {
  x %= width;
  return x < 0 ? x + width : x;
}

// The 3D photo's frame in the capture's world coordinates (COLMAP's world):
// p_panorama = rotation * (p_world - centre); rotation is row-major, orthonormal,
// det +1. Depth in a 3D photo is the distance from `centre` along the ray.
struct PanoramaFrame {
  double centre[3] = {0, 0, 0};
  double rotation[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
};

}  // namespace casual3d
