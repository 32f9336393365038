#include "encoder/gltf_texture.h"

#include <algorithm>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

// (<jpeglib.h> needs <cstdio>, included above.)
#include <jpeglib.h>
#include <png.h>

namespace casual3d::encoder::gltf {
namespace {

// For each output index of a 1-D area resampling from `src` to `dst` samples,
// the source samples it covers and their weights (summing to 1).
struct Tap {
  int src;
  float weight;
};
std::vector<std::vector<Tap>> AreaTaps(int src, int dst) {
  std::vector<std::vector<Tap>> taps(dst);
  const double scale = static_cast<double>(src) / dst;
  for (int i = 0; i < dst; ++i) {
    const double lo = i * scale, hi = (i + 1) * scale;
    for (int s = static_cast<int>(std::floor(lo)); s < std::min<double>(src, std::ceil(hi)); ++s) {
      const double overlap = std::min<double>(hi, s + 1) - std::max<double>(lo, s);
      if (overlap > 1e-9) taps[i].push_back({s, static_cast<float>(overlap / scale)});
    }
  }
  return taps;
}

}  // namespace

// Area-average resize (separable). Each output pixel is the mean of the source
// area it covers, so shrinking never aliases and uniform regions stay exact.
Image8 ResizeArea(const Image8& src, int width, int height) {
  const int c = src.channels();
  const auto xtaps = AreaTaps(src.width(), width);
  const auto ytaps = AreaTaps(src.height(), height);
  std::vector<float> rows(static_cast<size_t>(width) * src.height() * c);
  for (int y = 0; y < src.height(); ++y) {
    const uint8_t* in = src.row(y);
    float* out = &rows[static_cast<size_t>(y) * width * c];
    for (int x = 0; x < width; ++x) {
      for (const Tap& t : xtaps[x]) {
        for (int k = 0; k < c; ++k) out[x * c + k] += t.weight * in[t.src * c + k];
      }
    }
  }
  Image8 dst(width, height, c);
  std::vector<float> acc(static_cast<size_t>(width) * c);
  for (int y = 0; y < height; ++y) {
    std::fill(acc.begin(), acc.end(), 0.0f);
    for (const Tap& t : ytaps[y]) {
      const float* in = &rows[static_cast<size_t>(t.src) * width * c];
      for (size_t i = 0; i < acc.size(); ++i) acc[i] += t.weight * in[i];
    }
    uint8_t* out = dst.row(y);
    for (size_t i = 0; i < acc.size(); ++i) {
      out[i] = static_cast<uint8_t>(std::clamp(std::lround(acc[i]), 0L, 255L));
    }
  }
  return dst;
}

// The stored texture size: the atlas scaled so that its longest side is at most
// max_size, with an even height so the front (top) and back (bottom) halves of
// the atlas map onto whole rows.
void FitTextureSize(int width, int height, int max_size, int* out_width, int* out_height) {
  if (width <= max_size && height <= max_size) {
    *out_width = width;
    *out_height = height;
    return;
  }
  const double scale = static_cast<double>(max_size) / std::max(width, height);
  *out_width = std::clamp(static_cast<int>(std::lround(width * scale)), 1, max_size);
  int h = std::clamp(static_cast<int>(std::lround(height * scale)), 1, max_size);
  if (height % 2 == 0 && h % 2 == 1) h = h == max_size ? h - 1 : h + 1;
  *out_height = std::max(h, 1);
}

StatusOr<std::vector<uint8_t>> EncodePng(const Image8& image) {
  png_image png;
  std::memset(&png, 0, sizeof(png));
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width());
  png.height = static_cast<png_uint_32>(image.height());
  png.format = image.channels() == 4 ? PNG_FORMAT_RGBA : PNG_FORMAT_RGB;
  const png_int_32 stride = image.width() * image.channels();
  png_alloc_size_t size = 0;
  if (!png_image_write_to_memory(&png, nullptr, &size, 0, image.data(), stride, nullptr)) {
    std::string message = png.message;
    png_image_free(&png);
    return InternalError("PNG encoder: " + message);
  }
  std::vector<uint8_t> bytes(size);
  if (!png_image_write_to_memory(&png, bytes.data(), &size, 0, image.data(), stride, nullptr)) {
    std::string message = png.message;
    png_image_free(&png);
    return InternalError("PNG encoder: " + message);
  }
  bytes.resize(size);
  return bytes;
}

namespace {

// libjpeg reports errors through a callback that must not return: it jumps
// back. Everything libjpeg touches lives in this struct (in memory, not in
// registers that longjmp may restore to stale values).
struct JpegJob {
  jpeg_compress_struct cinfo;
  jpeg_error_mgr err;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX] = {};
  unsigned char* out = nullptr;
  unsigned long out_size = 0;       // NOLINT(runtime/int): libjpeg's type.
  const uint8_t* pixels = nullptr;  // Tightly packed RGB rows.
  int width = 0, height = 0, quality = 0;
};

void JpegErrorExit(j_common_ptr cinfo) {
  auto* job = static_cast<JpegJob*>(cinfo->client_data);
  (*cinfo->err->format_message)(cinfo, job->message);
  std::longjmp(job->jump, 1);
}

// Runs the compression; false (with job->message) if libjpeg failed.
bool RunJpeg(JpegJob* job) {
  job->cinfo.err = jpeg_std_error(&job->err);
  job->err.error_exit = JpegErrorExit;
  if (setjmp(job->jump)) {
    jpeg_destroy_compress(&job->cinfo);
    return false;
  }
  jpeg_create_compress(&job->cinfo);
  job->cinfo.client_data = job;
  jpeg_mem_dest(&job->cinfo, &job->out, &job->out_size);
  job->cinfo.image_width = static_cast<JDIMENSION>(job->width);
  job->cinfo.image_height = static_cast<JDIMENSION>(job->height);
  job->cinfo.input_components = 3;
  job->cinfo.in_color_space = JCS_RGB;
  jpeg_set_defaults(&job->cinfo);
  jpeg_set_quality(&job->cinfo, job->quality, TRUE);
  job->cinfo.optimize_coding = TRUE;
  jpeg_start_compress(&job->cinfo, TRUE);
  while (job->cinfo.next_scanline < job->cinfo.image_height) {
    JSAMPROW row = const_cast<JSAMPROW>(
        job->pixels + static_cast<size_t>(job->cinfo.next_scanline) * job->width * 3);
    jpeg_write_scanlines(&job->cinfo, &row, 1);
  }
  jpeg_finish_compress(&job->cinfo);
  jpeg_destroy_compress(&job->cinfo);
  return true;
}

}  // namespace

StatusOr<std::vector<uint8_t>> EncodeJpeg(const Image8& image, int quality) {
  // libjpeg takes RGB only: drop alpha (documented in the header).
  std::vector<uint8_t> rgb;
  if (image.channels() == 4) {
    rgb.resize(static_cast<size_t>(image.width()) * image.height() * 3);
    for (size_t i = 0, n = rgb.size() / 3; i < n; ++i) {
      std::memcpy(&rgb[i * 3], image.data() + i * 4, 3);
    }
  }
  auto job = std::make_unique<JpegJob>();
  job->pixels = image.channels() == 4 ? rgb.data() : image.data();
  job->width = image.width();
  job->height = image.height();
  job->quality = quality;
  const bool ok = RunJpeg(job.get());
  std::vector<uint8_t> bytes;
  if (ok) bytes.assign(job->out, job->out + job->out_size);
  std::free(job->out);
  if (!ok) return InternalError(std::string("JPEG encoder: ") + job->message);
  return bytes;
}

}  // namespace casual3d::encoder::gltf
