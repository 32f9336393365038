#pragma once

// The texture of an exported glTF file (gltf_export.h): the colour atlas
// shrunk to the size limit by area resampling, encoded as PNG (libpng) or
// JPEG (libjpeg). Internal to the encoder library.

#include <cstdint>
#include <vector>

#include "format/image.h"
#include "format/status.h"

namespace casual3d::encoder::gltf {

// `src` resampled to width x height by area averaging (each output pixel the
// mean of the source area it covers).
Image8 ResizeArea(const Image8& src, int width, int height);

// The stored texture size: the atlas scaled so that its longest side is at most
// max_size, with an even height so the front (top) and back (bottom) halves of
// the atlas map onto whole rows.
void FitTextureSize(int width, int height, int max_size, int* out_width, int* out_height);

// An RGB image as PNG or as JPEG of `quality` 1..100; kInternal with the
// library's message if encoding fails.
StatusOr<std::vector<uint8_t>> EncodePng(const Image8& image);
StatusOr<std::vector<uint8_t>> EncodeJpeg(const Image8& image, int quality);

}  // namespace casual3d::encoder::gltf
