#pragma once

// OpenEXR files through the OpenEXR 3 C++ API, for every OpenEXR file
// casual3d reads or writes: the master file (encoder/master_file.h) and the
// float images of reconstruct/ (depth maps, ground-truth panoramas;
// reconstruct/io/exr_io.h). This is the one place that includes OpenEXR's
// headers. One scanline part; errors are a Status naming the file, never an
// exception.
//
// Memory is described per channel by an ExrSlice over a block of rows, so
// interleaved images, planes and strips all go to OpenEXR without copies.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "format/status.h"

namespace casual3d::base {

enum class ExrCompression { kNone, kZip, kPiz };  // All lossless.

// A channel's stored type, and the type of a slice's memory: kUint uint32_t,
// kHalf a 16-bit float (stored from float slices, see ExrWriter::WriteRows),
// kFloat float.
enum class ExrPixelType { kUint, kHalf, kFloat };

struct ExrChannel {
  std::string name;
  ExrPixelType type = ExrPixelType::kFloat;
  bool full_resolution = true;  // Read only: x and y sampling 1.
};

// One channel's memory for a block of `rows` rows starting at row
// `first_row`: its value at (x, first_row + r) is at
// data + x * x_stride + r * y_stride (bytes).
struct ExrSlice {
  std::string channel;
  ExrPixelType type = ExrPixelType::kFloat;
  char* data = nullptr;
  size_t x_stride = 0;
  size_t y_stride = 0;
};

// The header of a file to write. Attribute names are free ("casual3d.view");
// m33d values are row-major.
struct ExrHeader {
  int width = 0;
  int height = 0;
  std::vector<ExrChannel> channels;  // Distinct non-empty names.
  ExrCompression compression = ExrCompression::kZip;
  std::vector<std::pair<std::string, std::string>> string_attributes;
  std::vector<std::pair<std::string, std::array<double, 3>>> v3d_attributes;
  std::vector<std::pair<std::string, std::array<double, 9>>> m33d_attributes;
};

// Writes a file row block by row block, atomically: the rows go to a
// temporary file beside `path` (base/atomic_file.h) that Commit() renames
// over it; a writer destroyed uncommitted removes its temporary file and
// leaves `path` as it was.
class ExrWriter {
 public:
  // kInvalidArgument for an empty image or channel list, an empty or repeated
  // channel name; kIoError "<path>: cannot write OpenEXR (<reason>)" when the
  // file cannot be created. `num_threads` compress blocks of rows (0:
  // OpenEXR's global thread count); the bytes written do not depend on it.
  static StatusOr<ExrWriter> Create(const std::string& path, const ExrHeader& header,
                                    int num_threads = 0);

  ExrWriter(ExrWriter&&) noexcept;
  ExrWriter& operator=(ExrWriter&&) noexcept;
  ~ExrWriter();

  // Writes the next `rows` rows, one slice per channel of the header (any
  // order). A float slice of a kHalf channel is rounded to half here
  // (OpenEXR converts types only when reading).
  Status WriteRows(int rows, const std::vector<ExrSlice>& slices);

  // Closes the file and renames it over `path`; every row must be written.
  Status Commit();

 private:
  struct Impl;
  explicit ExrWriter(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Reads a file's header, then any block of rows of any of its channels.
class ExrReader {
 public:
  // kNotFound "<path>: cannot open (<reason>)" for a missing file (kIoError
  // for one that cannot be read), kInvalidData "<path>: not an OpenEXR file"
  // or "<path>: not a readable OpenEXR file (<reason>)", or for an empty data
  // window. The data window's size is not limited here: callers check it
  // against their own limits before reading. `num_threads` decompress (0:
  // OpenEXR's global thread count).
  static StatusOr<ExrReader> Open(const std::string& path, int num_threads = 0);

  ExrReader(ExrReader&&) noexcept;
  ExrReader& operator=(ExrReader&&) noexcept;
  ~ExrReader();

  // The data window: its size and its top-left corner.
  int64_t width() const;
  int64_t height() const;
  int min_x() const;
  int min_y() const;

  // Every channel, in the file's order (sorted by name).
  const std::vector<ExrChannel>& channels() const;
  const ExrChannel* FindChannel(const std::string& name) const;

  // A header attribute of that type, or nothing when absent or of another type.
  std::optional<std::string> StringAttribute(const std::string& name) const;
  std::optional<std::array<double, 3>> V3dAttribute(const std::string& name) const;
  std::optional<std::array<double, 9>> M33dAttribute(const std::string& name) const;

  // Reads rows [first_row, first_row + rows) of the data window into
  // `slices` (converting a channel's type to the slice's). kInvalidData
  // "<path>: OpenEXR channel '<name>' is missing" (or "is subsampled
  // (unsupported)"), or "<path>: corrupt OpenEXR pixel data (<reason>)".
  Status ReadRows(int first_row, int rows, const std::vector<ExrSlice>& slices);

 private:
  struct Impl;
  explicit ExrReader(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace casual3d::base
