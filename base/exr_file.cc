#include "base/exr_file.h"

#include <Imath/ImathBox.h>
#include <Imath/ImathMatrix.h>
#include <Imath/ImathVec.h>
#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfMatrixAttribute.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfTestFile.h>
#include <OpenEXR/ImfThreading.h>
#include <OpenEXR/ImfVecAttribute.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <set>
#include <utility>

#include "base/atomic_file.h"

namespace casual3d::base {
namespace {

Imf::Compression ToImf(ExrCompression c) {
  switch (c) {
    case ExrCompression::kNone:
      return Imf::NO_COMPRESSION;
    case ExrCompression::kZip:
      return Imf::ZIP_COMPRESSION;
    case ExrCompression::kPiz:
      return Imf::PIZ_COMPRESSION;
  }
  return Imf::ZIP_COMPRESSION;
}

// Each ExrPixelType with OpenEXR's.
constexpr std::pair<ExrPixelType, Imf::PixelType> kPixelTypes[] = {
    {ExrPixelType::kUint, Imf::UINT},
    {ExrPixelType::kHalf, Imf::HALF},
    {ExrPixelType::kFloat, Imf::FLOAT}};

Imf::PixelType ToImf(ExrPixelType t) {
  for (const auto& [ours, imf] : kPixelTypes)
    if (ours == t) return imf;
  return Imf::FLOAT;
}

ExrPixelType FromImf(Imf::PixelType t) {
  for (const auto& [ours, imf] : kPixelTypes)
    if (imf == t) return ours;
  return ExrPixelType::kFloat;
}

int Threads(int num_threads) { return num_threads > 0 ? num_threads : Imf::globalThreadCount(); }

// An Imf::Slice for rows from `row` (absolute, in the data window's frame)
// on: OpenEXR addresses base + x * xStride + y * yStride with absolute x and y.
Imf::Slice ToImfSlice(ExrPixelType type, char* data, size_t x_stride, size_t y_stride, int min_x,
                      int row) {
  char* base = data - static_cast<ptrdiff_t>(min_x) * static_cast<ptrdiff_t>(x_stride) -
               static_cast<ptrdiff_t>(row) * static_cast<ptrdiff_t>(y_stride);
  return Imf::Slice(ToImf(type), base, x_stride, y_stride);
}

}  // namespace

// --- Writing ------------------------------------------------------------------

struct ExrWriter::Impl {
  std::string path, tmp;
  ExrHeader header;
  std::unique_ptr<Imf::OutputFile> file;
  int rows_written = 0;
  bool committed = false;

  ~Impl() {
    if (committed) return;
    try {
      file.reset();
    } catch (...) {  // Closing a file being abandoned: nothing to report.
    }
    std::remove(tmp.c_str());
  }

  Status Failed(const char* what) const {
    return IoError(path + ": cannot write OpenEXR (" + what + ")");
  }
};

ExrWriter::ExrWriter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ExrWriter::ExrWriter(ExrWriter&&) noexcept = default;
ExrWriter& ExrWriter::operator=(ExrWriter&&) noexcept = default;
ExrWriter::~ExrWriter() = default;

StatusOr<ExrWriter> ExrWriter::Create(const std::string& path, const ExrHeader& header,
                                      int num_threads) {
  if (header.width <= 0 || header.height <= 0)
    return InvalidArgument(path + ": cannot write an empty OpenEXR image");
  if (header.channels.empty()) return InvalidArgument(path + ": no OpenEXR channels to write");
  std::set<std::string> unique;
  for (const ExrChannel& c : header.channels)
    if (c.name.empty() || !unique.insert(c.name).second)
      return InvalidArgument(path + ": OpenEXR channel name '" + c.name + "' is empty or repeated");

  Imf::Header h(header.width, header.height);
  h.compression() = ToImf(header.compression);
  for (const auto& [name, value] : header.string_attributes)
    h.insert(name, Imf::StringAttribute(value));
  for (const auto& [name, v] : header.v3d_attributes)
    h.insert(name, Imf::V3dAttribute(Imath::V3d(v[0], v[1], v[2])));
  for (const auto& [name, m] : header.m33d_attributes)
    h.insert(name,
             Imf::M33dAttribute(Imath::M33d(m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8])));
  for (const ExrChannel& c : header.channels)
    h.channels().insert(c.name, Imf::Channel(ToImf(c.type)));

  auto impl = std::make_unique<Impl>();
  impl->path = path;
  impl->tmp = TemporaryPathFor(path);
  impl->header = header;
  try {
    impl->file = std::make_unique<Imf::OutputFile>(impl->tmp.c_str(), h, Threads(num_threads));
  } catch (const std::exception& e) {
    return impl->Failed(e.what());
  }
  return ExrWriter(std::move(impl));
}

Status ExrWriter::WriteRows(int rows, const std::vector<ExrSlice>& slices) {
  Impl& w = *impl_;
  if (!w.file) return InternalError(w.path + ": OpenEXR rows written after Commit()");
  if (rows <= 0 || rows > w.header.height - w.rows_written)
    return InternalError(w.path + ": " + std::to_string(rows) + " OpenEXR rows written after " +
                         std::to_string(w.rows_written) + " of " + std::to_string(w.header.height));
  const size_t width = static_cast<size_t>(w.header.width);
  Imf::FrameBuffer fb;
  std::vector<std::vector<Imath::half>> half_planes;
  for (const ExrSlice& s : slices) {
    const ExrChannel* channel = nullptr;
    for (const ExrChannel& c : w.header.channels)
      if (c.name == s.channel) channel = &c;
    if (channel == nullptr)
      return InternalError(w.path + ": OpenEXR slice of channel '" + s.channel +
                           "', which the header does not list");
    if (channel->type == ExrPixelType::kHalf && s.type == ExrPixelType::kFloat) {
      std::vector<Imath::half>& plane = half_planes.emplace_back(width * rows);
      for (int y = 0; y < rows; ++y)
        for (size_t x = 0; x < width; ++x)
          plane[y * width + x] = Imath::half(
              *reinterpret_cast<const float*>(s.data + y * s.y_stride + x * s.x_stride));
      fb.insert(s.channel,
                ToImfSlice(ExrPixelType::kHalf, reinterpret_cast<char*>(plane.data()),
                           sizeof(Imath::half), sizeof(Imath::half) * width, 0, w.rows_written));
    } else {
      fb.insert(s.channel, ToImfSlice(s.type, s.data, s.x_stride, s.y_stride, 0, w.rows_written));
    }
  }
  try {
    w.file->setFrameBuffer(fb);
    w.file->writePixels(rows);
  } catch (const std::exception& e) {
    return w.Failed(e.what());
  }
  w.rows_written += rows;
  return Status::Ok();
}

Status ExrWriter::Commit() {
  Impl& w = *impl_;
  if (!w.file) return InternalError(w.path + ": OpenEXR file committed twice");
  if (w.rows_written != w.header.height)
    return InternalError(w.path + ": OpenEXR file committed after " +
                         std::to_string(w.rows_written) + " of " + std::to_string(w.header.height) +
                         " rows");
  try {
    w.file.reset();  // Writes the line offsets and closes the file.
  } catch (const std::exception& e) {
    return w.Failed(e.what());
  }
  w.committed = true;
  return CommitTemporary(w.tmp, w.path);
}

// --- Reading ------------------------------------------------------------------

struct ExrReader::Impl {
  std::string path;
  std::unique_ptr<Imf::InputFile> file;
  int64_t width = 0, height = 0;
  int min_x = 0, min_y = 0;
  std::vector<ExrChannel> channels;
};

ExrReader::ExrReader(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ExrReader::ExrReader(ExrReader&&) noexcept = default;
ExrReader& ExrReader::operator=(ExrReader&&) noexcept = default;
ExrReader::~ExrReader() = default;

StatusOr<ExrReader> ExrReader::Open(const std::string& path, int num_threads) {
  std::FILE* probe = std::fopen(path.c_str(), "rb");
  if (probe == nullptr) {
    const int error = errno;
    const std::string message = path + ": cannot open (" + std::strerror(error) + ")";
    return error == ENOENT ? NotFound(message) : IoError(message);
  }
  std::fclose(probe);
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  try {
    if (!Imf::isOpenExrFile(path.c_str())) return InvalidData(path + ": not an OpenEXR file");
    impl->file = std::make_unique<Imf::InputFile>(path.c_str(), Threads(num_threads));
  } catch (const std::exception& e) {
    return InvalidData(path + ": not a readable OpenEXR file (" + e.what() + ")");
  }
  const Imf::Header& header = impl->file->header();
  const Imath::Box2i dw = header.dataWindow();
  impl->width = static_cast<int64_t>(dw.max.x) - dw.min.x + 1;
  impl->height = static_cast<int64_t>(dw.max.y) - dw.min.y + 1;
  if (impl->width <= 0 || impl->height <= 0)
    return InvalidData(path + ": OpenEXR data window of " + std::to_string(impl->width) + "x" +
                       std::to_string(impl->height) + " is empty");
  impl->min_x = dw.min.x;
  impl->min_y = dw.min.y;
  for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
    const Imf::Channel& c = it.channel();
    impl->channels.push_back({it.name(), FromImf(c.type), c.xSampling == 1 && c.ySampling == 1});
  }
  return ExrReader(std::move(impl));
}

int64_t ExrReader::width() const { return impl_->width; }
int64_t ExrReader::height() const { return impl_->height; }
int ExrReader::min_x() const { return impl_->min_x; }
int ExrReader::min_y() const { return impl_->min_y; }
const std::vector<ExrChannel>& ExrReader::channels() const { return impl_->channels; }

const ExrChannel* ExrReader::FindChannel(const std::string& name) const {
  for (const ExrChannel& c : impl_->channels)
    if (c.name == name) return &c;
  return nullptr;
}

std::optional<std::string> ExrReader::StringAttribute(const std::string& name) const {
  const auto* a = impl_->file->header().findTypedAttribute<Imf::StringAttribute>(name);
  if (a == nullptr) return std::nullopt;
  return a->value();
}

std::optional<std::array<double, 3>> ExrReader::V3dAttribute(const std::string& name) const {
  const auto* a = impl_->file->header().findTypedAttribute<Imf::V3dAttribute>(name);
  if (a == nullptr) return std::nullopt;
  return std::array<double, 3>{a->value().x, a->value().y, a->value().z};
}

std::optional<std::array<double, 9>> ExrReader::M33dAttribute(const std::string& name) const {
  const auto* a = impl_->file->header().findTypedAttribute<Imf::M33dAttribute>(name);
  if (a == nullptr) return std::nullopt;
  std::array<double, 9> m;
  for (int i = 0; i < 9; ++i) m[i] = a->value()[i / 3][i % 3];
  return m;
}

Status ExrReader::ReadRows(int first_row, int rows, const std::vector<ExrSlice>& slices) {
  Impl& r = *impl_;
  if (first_row < 0 || rows <= 0 || first_row + static_cast<int64_t>(rows) > r.height)
    return InternalError(r.path + ": OpenEXR rows " + std::to_string(first_row) + " to " +
                         std::to_string(first_row + static_cast<int64_t>(rows) - 1) + " asked of " +
                         std::to_string(r.height));
  Imf::FrameBuffer fb;
  const int row = r.min_y + first_row;
  for (const ExrSlice& s : slices) {
    const ExrChannel* channel = FindChannel(s.channel);
    if (channel == nullptr)
      return InvalidData(r.path + ": OpenEXR channel '" + s.channel + "' is missing");
    if (!channel->full_resolution)
      return InvalidData(r.path + ": OpenEXR channel '" + s.channel +
                         "' is subsampled (unsupported)");
    fb.insert(s.channel, ToImfSlice(s.type, s.data, s.x_stride, s.y_stride, r.min_x, row));
  }
  try {
    r.file->setFrameBuffer(fb);
    r.file->readPixels(row, row + rows - 1);
  } catch (const std::exception& e) {
    return InvalidData(r.path + ": corrupt OpenEXR pixel data (" + e.what() + ")");
  }
  return Status::Ok();
}

}  // namespace casual3d::base
