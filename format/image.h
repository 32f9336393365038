#pragma once

// The one owning image type of the project and its non-owning, strided view.
// Pixels are row-major and interleaved: element (x, y, c) is at
// data[y * stride + x * channels + c], with stride counted in elements.
// Views let data go to libwebp, OpenEXR, WebGL and OpenCV without copies.

#include <cassert>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace casual3d {

template <typename T>
class ImageView {
 public:
  ImageView() = default;
  ImageView(T* data, int width, int height, int channels, std::ptrdiff_t stride)
      : data_(data), width_(width), height_(height), channels_(channels), stride_(stride) {}

  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  std::ptrdiff_t stride() const { return stride_; }  // In elements, not bytes.
  T* data() const { return data_; }
  bool empty() const { return width_ == 0 || height_ == 0; }

  T* row(int y) const { return data_ + y * stride_; }
  T& at(int x, int y, int c = 0) const {
    assert(x >= 0 && x < width_ && y >= 0 && y < height_ && c >= 0 && c < channels_);
    return data_[y * stride_ + static_cast<std::ptrdiff_t>(x) * channels_ + c];
  }
  // A rectangular window of this view (no copy).
  ImageView<T> Crop(int x, int y, int w, int h) const {
    assert(x >= 0 && y >= 0 && x + w <= width_ && y + h <= height_);
    return ImageView<T>(data_ + y * stride_ + static_cast<std::ptrdiff_t>(x) * channels_, w, h,
                        channels_, stride_);
  }

 private:
  T* data_ = nullptr;
  int width_ = 0;
  int height_ = 0;
  int channels_ = 0;
  std::ptrdiff_t stride_ = 0;
};

template <typename T>
class Image {
 public:
  Image() = default;
  Image(int width, int height, int channels, T fill = T())
      : width_(width), height_(height), channels_(channels),
        data_(static_cast<size_t>(width) * height * channels, fill) {
    assert(width >= 0 && height >= 0 && channels > 0);
  }

  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  bool empty() const { return data_.empty(); }
  size_t size() const { return data_.size(); }  // Number of elements.
  T* data() { return data_.data(); }
  const T* data() const { return data_.data(); }
  std::vector<T>& vector() { return data_; }
  const std::vector<T>& vector() const { return data_; }

  T& at(int x, int y, int c = 0) {
    assert(x >= 0 && x < width_ && y >= 0 && y < height_ && c >= 0 && c < channels_);
    return data_[(static_cast<size_t>(y) * width_ + x) * channels_ + c];
  }
  const T& at(int x, int y, int c = 0) const {
    assert(x >= 0 && x < width_ && y >= 0 && y < height_ && c >= 0 && c < channels_);
    return data_[(static_cast<size_t>(y) * width_ + x) * channels_ + c];
  }
  T* row(int y) { return data_.data() + static_cast<size_t>(y) * width_ * channels_; }
  const T* row(int y) const { return data_.data() + static_cast<size_t>(y) * width_ * channels_; }

  ImageView<T> view() {
    return ImageView<T>(data_.data(), width_, height_, channels_,
                        static_cast<std::ptrdiff_t>(width_) * channels_);
  }
  ImageView<const T> view() const {
    return ImageView<const T>(data_.data(), width_, height_, channels_,
                              static_cast<std::ptrdiff_t>(width_) * channels_);
  }

  bool operator==(const Image& o) const {
    return width_ == o.width_ && height_ == o.height_ && channels_ == o.channels_ &&
           data_ == o.data_;
  }

 private:
  int width_ = 0;
  int height_ = 0;
  int channels_ = 0;
  std::vector<T> data_;
};

using Image8 = Image<uint8_t>;
using Image16 = Image<uint16_t>;
using ImageF = Image<float>;

}  // namespace casual3d
