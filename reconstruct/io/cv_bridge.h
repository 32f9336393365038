#pragma once

// The one place where OpenCV meets casual3d's image type. Conversions wrap the
// same memory (no copies): the cv::Mat or view stays valid only as long as the
// image it was made from, and writes through one are seen through the other.

#include <cstdint>
#include <type_traits>

#include <opencv2/core.hpp>

#include "format/image.h"

namespace casual3d::io {

// The OpenCV depth (CV_8U, CV_16U, CV_32F, ...) of element type T.
template <typename T>
constexpr int CvDepthOf() {
  using U = std::remove_const_t<T>;
  if constexpr (std::is_same_v<U, uint8_t>) return CV_8U;
  else if constexpr (std::is_same_v<U, int8_t>) return CV_8S;
  else if constexpr (std::is_same_v<U, uint16_t>) return CV_16U;
  else if constexpr (std::is_same_v<U, int16_t>) return CV_16S;
  else if constexpr (std::is_same_v<U, int32_t>) return CV_32S;
  else if constexpr (std::is_same_v<U, float>) return CV_32F;
  else if constexpr (std::is_same_v<U, double>) return CV_64F;
  else static_assert(sizeof(U) == 0, "element type without an OpenCV depth");
}

// A cv::Mat header over a view: rows = height, cols = width, channels as the
// view's, step = stride * sizeof(T). Const views give a Mat that must not be
// written to (OpenCV has no const Mat type).
template <typename T>
cv::Mat ToMat(const ImageView<T>& view) {
  using U = std::remove_const_t<T>;
  return cv::Mat(view.height(), view.width(), CV_MAKETYPE(CvDepthOf<T>(), view.channels()),
                 const_cast<U*>(view.data()), static_cast<size_t>(view.stride()) * sizeof(T));
}
template <typename T>
cv::Mat ToMat(Image<T>& image) {
  return ToMat(image.view());
}
template <typename T>
cv::Mat ToMat(const Image<T>& image) {
  return ToMat(image.view());
}

// A view over a cv::Mat's pixels. Precondition: the Mat's depth is T's and each
// row's step is a multiple of sizeof(T) (true for every Mat OpenCV allocates).
template <typename T>
ImageView<T> ToView(const cv::Mat& mat) {
  assert(mat.depth() == CvDepthOf<T>());
  assert(mat.step[0] % sizeof(T) == 0);
  using U = std::remove_const_t<T>;
  return ImageView<T>(reinterpret_cast<U*>(mat.data), mat.cols, mat.rows, mat.channels(),
                      static_cast<std::ptrdiff_t>(mat.step[0] / sizeof(T)));
}

}  // namespace casual3d::io
