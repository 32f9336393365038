#pragma once

// Procedural textures for the synthetic scene: hashing, band-limited value
// noise (fractal sums whose octaves fade out as they approach the pixel
// footprint, so that a single ray per pixel does not alias), a periodic brick
// pattern (the "repeated texture" case), leaves, and window grids. All are
// pure functions of their arguments: rendering is deterministic whatever the
// thread partitioning.

#include <cstdint>

#include <Eigen/Core>

namespace casual3d::synth {

// A 64-bit mix of up to four integers (splitmix64 finaliser chain).
uint64_t Hash(uint64_t a, uint64_t b = 0, uint64_t c = 0, uint64_t d = 0);
// Uniform in [0, 1) from a hash.
double HashToUnit(uint64_t h);
// A standard normal sample from two hashes (Box-Muller).
double HashToNormal(uint64_t h1, uint64_t h2);

// Value noise in [0, 1] on the integer lattice, smoothly (C1) interpolated.
double ValueNoise3(const Eigen::Vector3d& p, uint64_t seed);

// A fractal sum of `octaves` value-noise octaves starting at `base_frequency`
// (cycles per metre), each octave doubling the frequency and multiplying the
// amplitude by `gain`. Octaves whose wavelength is below two `footprint_m`
// fade to their mean (0.5), so the result is band-limited. Result in [0, 1].
double FractalNoise(const Eigen::Vector3d& p_m, double base_frequency, int octaves, double gain,
                    double footprint_m, uint64_t seed);

// The fraction of a 1D box filter of width `footprint` centred on `x` where
// frac(x / period) < duty (a filtered square wave).
double FilteredPulse(double x, double period, double duty, double footprint);

enum class TextureKind : int {
  kFlat = 0,     // Constant colour: the textureless wall.
  kNoise = 1,    // Two colours mixed by fractal noise: ground, stone, bark, paint.
  kBricks = 2,   // Running-bond bricks whose colours repeat every 4 x 3 bricks.
  kLeaves = 3,   // Foliage: high-frequency light/dark greens over low-frequency variation.
  kWindows = 4,  // A facade: noise with a regular grid of dark windows.
};

struct Material {
  TextureKind kind = TextureKind::kNoise;
  Eigen::Vector3d color_a{0.5, 0.5, 0.5};  // Linear albedo, [0, 1].
  Eigen::Vector3d color_b{0.5, 0.5, 0.5};  // Second linear albedo, [0, 1].
  double frequency = 4.0;   // Base noise frequency, cycles per metre.
  double cell_m = 0.25;     // Brick length or window period, metres.
  uint64_t seed = 0;        // Decorrelates materials.
};

// Linear albedo of `material` at a surface point. `p_world` is the 3D point,
// `uv_m` face coordinates in metres (used by bricks and windows), `footprint_m`
// the size of the pixel on the surface.
Eigen::Vector3d EvaluateAlbedo(const Material& material, const Eigen::Vector3d& p_world,
                               const Eigen::Vector2d& uv_m, double footprint_m);

}  // namespace casual3d::synth
