#include "reconstruct/geometry/colmap_model.h"

#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

#include "base/atomic_file.h"

namespace casual3d::geometry {
namespace {

namespace fs = std::filesystem;

// Largest image side accepted from a model file, pixels; guards against
// garbage widths that would later size huge buffers.
constexpr uint64_t kMaxImageSide = 1u << 20;

std::string JoinPath(const std::string& dir, const std::string& name) {
  return (fs::path(dir) / name).string();
}

// ---------------------------------------------------------------------------
// Text parsing.

// Reads a text file line by line, skipping comments and empty lines, and
// formats errors as "file:line: ...".
class TextReader {
 public:
  explicit TextReader(const std::string& path) : path_(path), file_(path) {
    if (!file_.is_open()) {
      throw ModelError(path + ": cannot open (" + std::strerror(errno) + ")");
    }
  }

  // Next non-empty, non-comment line, trimmed; false at the end of the file.
  bool NextDataLine(std::string* line) {
    while (NextRawLine(line)) {
      if (!line->empty() && (*line)[0] != '#') return true;
    }
    return false;
  }

  // The very next line, trimmed (may be empty); false at the end of the file.
  bool NextRawLine(std::string* line) {
    if (!std::getline(file_, *line)) return false;
    ++line_number_;
    Trim(line);
    return true;
  }

  [[noreturn]] void Fail(const std::string& what) const {
    throw ModelError(path_ + ":" + std::to_string(line_number_) + ": " + what);
  }

  const std::string& path() const { return path_; }
  int line_number() const { return line_number_; }

 private:
  static void Trim(std::string* s) {
    const char* kSpace = " \t\r\n\f\v";
    const size_t begin = s->find_first_not_of(kSpace);
    if (begin == std::string::npos) {
      s->clear();
      return;
    }
    const size_t end = s->find_last_not_of(kSpace);
    *s = s->substr(begin, end - begin + 1);
  }

  std::string path_;
  std::ifstream file_;
  int line_number_ = 0;
};

// Splits a line into whitespace-separated tokens.
std::vector<std::string> Tokenize(const std::string& line) {
  std::vector<std::string> tokens;
  std::istringstream stream(line);
  std::string token;
  while (stream >> token) tokens.push_back(token);
  return tokens;
}

double ParseDouble(const TextReader& reader, const std::string& token, const char* what) {
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(token.c_str(), &end);
  if (token.empty() || end != token.c_str() + token.size() || errno == ERANGE ||
      !std::isfinite(value)) {
    reader.Fail(std::string("expected ") + what + " (a finite number), got '" + token + "'");
  }
  return value;
}

uint64_t ParseUnsigned(const TextReader& reader, const std::string& token, const char* what,
                       uint64_t max_value) {
  errno = 0;
  char* end = nullptr;
  const unsigned long long value = std::strtoull(token.c_str(), &end, 10);
  if (token.empty() || token[0] == '-' || token[0] == '+' || end != token.c_str() + token.size() ||
      errno == ERANGE || value > max_value) {
    reader.Fail(std::string("expected ") + what + " (an integer from 0 to " +
                std::to_string(max_value) + "), got '" + token + "'");
  }
  return value;
}

int ParseId(const TextReader& reader, const std::string& token, const char* what) {
  return static_cast<int>(ParseUnsigned(reader, token, what, INT_MAX));
}

std::string SupportedModelList() {
  std::string list;
  for (int i = 0; CameraModelName(static_cast<CameraModelId>(i)) != nullptr; ++i) {
    if (!list.empty()) list += ", ";
    list += CameraModelName(static_cast<CameraModelId>(i));
  }
  return list;
}

// ---------------------------------------------------------------------------
// Binary parsing: the whole file is loaded and decoded with bounds checks.

class BinaryReader {
 public:
  explicit BinaryReader(const std::string& path) : path_(path) {
    std::ifstream file(path, std::ios::binary);
    if (!file.is_open()) {
      throw ModelError(path + ": cannot open (" + std::strerror(errno) + ")");
    }
    bytes_.assign(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
    if (file.bad()) throw ModelError(path + ": read error");
  }

  size_t offset() const { return offset_; }
  size_t remaining() const { return bytes_.size() - offset_; }
  bool AtEnd() const { return offset_ == bytes_.size(); }

  uint64_t ReadU64(const char* what) { return ReadUnsigned(8, what); }
  uint32_t ReadU32(const char* what) { return static_cast<uint32_t>(ReadUnsigned(4, what)); }
  int32_t ReadI32(const char* what) { return static_cast<int32_t>(ReadUnsigned(4, what)); }
  uint8_t ReadU8(const char* what) { return static_cast<uint8_t>(ReadUnsigned(1, what)); }
  double ReadF64(const char* what) {
    const uint64_t bits = ReadUnsigned(8, what);
    double value;
    std::memcpy(&value, &bits, sizeof(value));
    return value;
  }

  // A '\0'-terminated string.
  std::string ReadCString(const char* what) {
    const void* nul = std::memchr(bytes_.data() + offset_, '\0', remaining());
    if (nul == nullptr) {
      Fail(std::string("truncated: ") + what +
           " has no terminating NUL before the end of the file");
    }
    const size_t length = static_cast<const char*>(nul) - (bytes_.data() + offset_);
    std::string s(bytes_.data() + offset_, length);
    offset_ += length + 1;
    return s;
  }

  // Reads a 64-bit element count and rejects counts whose records (of at least
  // `min_record_bytes` each) cannot fit in the rest of the file.
  uint64_t ReadCount(const char* what, size_t min_record_bytes) {
    const size_t at = offset_;
    const uint64_t count = ReadU64(what);
    if (min_record_bytes > 0 && count > remaining() / min_record_bytes) {
      FailAt(at, std::string(what) + " " + std::to_string(count) + " needs at least " +
                     std::to_string(min_record_bytes) + " bytes each but only " +
                     std::to_string(remaining()) + " bytes remain");
    }
    return count;
  }

  [[noreturn]] void Fail(const std::string& what) const { FailAt(offset_, what); }
  [[noreturn]] void FailAt(size_t at, const std::string& what) const {
    throw ModelError(path_ + ": offset " + std::to_string(at) + ": " + what);
  }

 private:
  // Little-endian, independent of the host's byte order.
  uint64_t ReadUnsigned(int num_bytes, const char* what) {
    if (remaining() < static_cast<size_t>(num_bytes)) {
      Fail(std::string("truncated: expected ") + what + " (" + std::to_string(num_bytes) +
           " bytes) but the file ends at " + std::to_string(bytes_.size()));
    }
    uint64_t value = 0;
    for (int i = 0; i < num_bytes; ++i) {
      value |= static_cast<uint64_t>(static_cast<uint8_t>(bytes_[offset_ + i])) << (8 * i);
    }
    offset_ += num_bytes;
    return value;
  }

  std::string path_;
  std::vector<char> bytes_;
  size_t offset_ = 0;
};

class BinaryWriter {
 public:
  void U64(uint64_t v) { Unsigned(v, 8); }
  void U32(uint32_t v) { Unsigned(v, 4); }
  void I32(int32_t v) { Unsigned(static_cast<uint32_t>(v), 4); }
  void U8(uint8_t v) { bytes_.push_back(static_cast<char>(v)); }
  void F64(double v) {
    uint64_t bits;
    std::memcpy(&bits, &v, sizeof(bits));
    Unsigned(bits, 8);
  }
  void CString(const std::string& s) {
    bytes_.insert(bytes_.end(), s.begin(), s.end());
    bytes_.push_back('\0');
  }
  const std::string& bytes() const { return bytes_; }

 private:
  void Unsigned(uint64_t v, int num_bytes) {
    for (int i = 0; i < num_bytes; ++i) bytes_.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
  }
  std::string bytes_;
};

// Writes `contents` to `path` atomically (base/atomic_file.h), so that
// readers never see a half-written file.
void WriteFileAtomically(const std::string& path, const std::string& contents) {
  const Status written = base::WriteFileAtomic(path, contents);
  if (!written.ok()) throw ModelError(written.message());
}

void CreateDir(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw ModelError(dir + ": cannot create the model folder (" + ec.message() + ")");
}

// Unit quaternion from file values. Values already unit to within rounding are
// kept bit for bit, so that text -> binary -> text round trips are exact.
Eigen::Quaterniond NormalizedQuaternion(double w, double x, double y, double z, bool* ok) {
  Eigen::Quaterniond q(w, x, y, z);
  const double norm = q.norm();
  *ok = std::isfinite(norm) && norm > 1e-12;
  if (*ok && std::abs(norm - 1.0) > 1e-12) q.coeffs() /= norm;
  return q;
}

Eigen::Quaterniond UnitForWriting(const Eigen::Quaterniond& q) {
  bool ok;
  const Eigen::Quaterniond unit = NormalizedQuaternion(q.w(), q.x(), q.y(), q.z(), &ok);
  return ok ? unit : Eigen::Quaterniond::Identity();
}

// Text output with enough digits that reading it back gives the same doubles
// (COLMAP writes with precision 17 too).
std::ostringstream PreciseStream() {
  std::ostringstream out;
  out.precision(17);
  return out;
}

void CheckCameraReferences(const SparseModel& model, const std::string& images_path) {
  for (const auto& [image_id, image] : model.images) {
    if (model.cameras.count(image.camera_id) == 0) {
      throw ModelError(images_path + ": image " + std::to_string(image_id) + " (" + image.name +
                       ") refers to camera " + std::to_string(image.camera_id) +
                       ", which the cameras file does not define");
    }
  }
}

}  // namespace

const ModelImage* SparseModel::FindImageByName(const std::string& name) const {
  for (const auto& entry : images) {
    if (entry.second.name == name) return &entry.second;
  }
  return nullptr;
}

// ---------------------------------------------------------------------------
// Text readers.

std::map<int, Camera> ReadCamerasText(const std::string& path) {
  TextReader reader(path);
  std::map<int, Camera> cameras;
  std::string line;
  while (reader.NextDataLine(&line)) {
    const std::vector<std::string> tokens = Tokenize(line);
    if (tokens.size() < 4) {
      reader.Fail("expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS[], got " +
                  std::to_string(tokens.size()) + " fields");
    }
    Camera camera;
    camera.camera_id = ParseId(reader, tokens[0], "CAMERA_ID");
    if (!CameraModelFromName(tokens[1], &camera.model)) {
      reader.Fail("expected a camera model (" + SupportedModelList() + "), got '" + tokens[1] +
                  "'");
    }
    camera.width = static_cast<int>(ParseUnsigned(reader, tokens[2], "WIDTH", kMaxImageSide));
    camera.height = static_cast<int>(ParseUnsigned(reader, tokens[3], "HEIGHT", kMaxImageSide));
    const int num_params = CameraModelNumParams(camera.model);
    if (static_cast<int>(tokens.size()) - 4 != num_params) {
      reader.Fail("expected " + std::to_string(num_params) + " parameters for " + tokens[1] +
                  ", got " + std::to_string(tokens.size() - 4));
    }
    for (int i = 0; i < num_params; ++i) {
      camera.params.push_back(ParseDouble(reader, tokens[4 + i], "a camera parameter"));
    }
    std::string why;
    if (!camera.IsValid(&why)) reader.Fail("invalid camera: " + why);
    if (!cameras.emplace(camera.camera_id, camera).second) {
      reader.Fail("duplicate CAMERA_ID " + tokens[0]);
    }
  }
  return cameras;
}

std::map<int, ModelImage> ReadImagesText(const std::string& path) {
  TextReader reader(path);
  std::map<int, ModelImage> images;
  std::string line;
  while (reader.NextDataLine(&line)) {
    std::istringstream stream(line);
    std::vector<std::string> head(9);
    for (std::string& token : head) {
      if (!(stream >> token)) {
        reader.Fail("expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME");
      }
    }
    std::string name;
    std::getline(stream, name);
    const size_t begin = name.find_first_not_of(" \t");
    name = begin == std::string::npos ? std::string() : name.substr(begin);
    if (name.empty()) reader.Fail("expected NAME after CAMERA_ID");

    ModelImage image;
    image.image_id = ParseId(reader, head[0], "IMAGE_ID");
    double q[4], t[3];
    const char* q_names[4] = {"QW", "QX", "QY", "QZ"};
    const char* t_names[3] = {"TX", "TY", "TZ"};
    for (int i = 0; i < 4; ++i) q[i] = ParseDouble(reader, head[1 + i], q_names[i]);
    for (int i = 0; i < 3; ++i) t[i] = ParseDouble(reader, head[5 + i], t_names[i]);
    bool ok;
    image.pose.rotation = NormalizedQuaternion(q[0], q[1], q[2], q[3], &ok);
    if (!ok) reader.Fail("expected a non-zero quaternion QW QX QY QZ");
    image.pose.translation = Eigen::Vector3d(t[0], t[1], t[2]);
    image.camera_id = ParseId(reader, head[8], "CAMERA_ID");
    image.name = name;

    // The line right after the image line holds its observations, possibly
    // none (an empty line); a missing last line means no observations.
    std::string points_line;
    if (reader.NextRawLine(&points_line)) {
      if (!points_line.empty() && points_line[0] == '#') {
        reader.Fail("expected the POINTS2D line of image " + head[0] + ", got a comment");
      }
      const std::vector<std::string> tokens = Tokenize(points_line);
      if (tokens.size() % 3 != 0) {
        reader.Fail("expected POINTS2D as triples (X Y POINT3D_ID), got " +
                    std::to_string(tokens.size()) + " values");
      }
      image.points2d.reserve(tokens.size() / 3);
      for (size_t i = 0; i < tokens.size(); i += 3) {
        Observation2D obs;
        obs.xy = Eigen::Vector2d(ParseDouble(reader, tokens[i], "X"),
                                 ParseDouble(reader, tokens[i + 1], "Y"));
        obs.point3d_id =
            tokens[i + 2] == "-1"
                ? kInvalidPoint3DId
                : ParseUnsigned(reader, tokens[i + 2], "POINT3D_ID or -1", kInvalidPoint3DId - 1);
        image.points2d.push_back(obs);
      }
    }
    if (!images.emplace(image.image_id, std::move(image)).second) {
      reader.Fail("duplicate IMAGE_ID " + head[0]);
    }
  }
  return images;
}

std::map<uint64_t, Point3D> ReadPoints3DText(const std::string& path) {
  TextReader reader(path);
  std::map<uint64_t, Point3D> points;
  std::string line;
  while (reader.NextDataLine(&line)) {
    const std::vector<std::string> tokens = Tokenize(line);
    if (tokens.size() < 8 || (tokens.size() - 8) % 2 != 0) {
      reader.Fail(
          "expected POINT3D_ID X Y Z R G B ERROR followed by (IMAGE_ID POINT2D_IDX) pairs, got " +
          std::to_string(tokens.size()) + " fields");
    }
    Point3D point;
    point.point3d_id = ParseUnsigned(reader, tokens[0], "POINT3D_ID", kInvalidPoint3DId - 1);
    point.xyz =
        Eigen::Vector3d(ParseDouble(reader, tokens[1], "X"), ParseDouble(reader, tokens[2], "Y"),
                        ParseDouble(reader, tokens[3], "Z"));
    for (int c = 0; c < 3; ++c) {
      point.rgb[c] = static_cast<uint8_t>(ParseUnsigned(reader, tokens[4 + c], "R, G or B", 255));
    }
    point.error = ParseDouble(reader, tokens[7], "ERROR");
    point.track.reserve((tokens.size() - 8) / 2);
    for (size_t i = 8; i < tokens.size(); i += 2) {
      TrackElement element;
      element.image_id = ParseId(reader, tokens[i], "IMAGE_ID");
      element.point2d_idx = ParseId(reader, tokens[i + 1], "POINT2D_IDX");
      point.track.push_back(element);
    }
    if (!points.emplace(point.point3d_id, std::move(point)).second) {
      reader.Fail("duplicate POINT3D_ID " + tokens[0]);
    }
  }
  return points;
}

// ---------------------------------------------------------------------------
// Binary readers (COLMAP 3.8 layouts, little-endian).

std::map<int, Camera> ReadCamerasBinary(const std::string& path) {
  BinaryReader reader(path);
  // camera_id u32, model_id i32, width u64, height u64, params f64[n].
  constexpr size_t kMinRecord = 4 + 4 + 8 + 8;
  const uint64_t count = reader.ReadCount("number of cameras", kMinRecord);
  std::map<int, Camera> cameras;
  for (uint64_t i = 0; i < count; ++i) {
    const size_t at = reader.offset();
    Camera camera;
    const uint32_t id = reader.ReadU32("camera_id");
    if (id > INT_MAX) reader.FailAt(at, "camera_id " + std::to_string(id) + " is too large");
    camera.camera_id = static_cast<int>(id);
    const int32_t model_id = reader.ReadI32("model_id");
    if (!CameraModelFromInt(model_id, &camera.model)) {
      reader.FailAt(at + 4, "expected a supported camera model id (0-4: " + SupportedModelList() +
                                "), got " + std::to_string(model_id));
    }
    const uint64_t width = reader.ReadU64("width");
    const uint64_t height = reader.ReadU64("height");
    if (width == 0 || height == 0 || width > kMaxImageSide || height > kMaxImageSide) {
      reader.FailAt(at + 8, "image size " + std::to_string(width) + "x" + std::to_string(height) +
                                " is out of range (1 to " + std::to_string(kMaxImageSide) + ")");
    }
    camera.width = static_cast<int>(width);
    camera.height = static_cast<int>(height);
    const int num_params = CameraModelNumParams(camera.model);
    for (int p = 0; p < num_params; ++p)
      camera.params.push_back(reader.ReadF64("camera parameter"));
    std::string why;
    if (!camera.IsValid(&why)) reader.FailAt(at, "camera " + std::to_string(id) + ": " + why);
    if (!cameras.emplace(camera.camera_id, camera).second) {
      reader.FailAt(at, "duplicate camera_id " + std::to_string(id));
    }
  }
  if (!reader.AtEnd()) reader.Fail("unexpected trailing bytes after the last camera");
  return cameras;
}

std::map<int, ModelImage> ReadImagesBinary(const std::string& path) {
  BinaryReader reader(path);
  // image_id u32, q f64[4], t f64[3], camera_id u32, name (>= 1 byte), count u64.
  constexpr size_t kMinRecord = 4 + 32 + 24 + 4 + 1 + 8;
  const uint64_t count = reader.ReadCount("number of images", kMinRecord);
  std::map<int, ModelImage> images;
  for (uint64_t i = 0; i < count; ++i) {
    const size_t at = reader.offset();
    ModelImage image;
    const uint32_t id = reader.ReadU32("image_id");
    if (id > INT_MAX) reader.FailAt(at, "image_id " + std::to_string(id) + " is too large");
    image.image_id = static_cast<int>(id);
    double q[4], t[3];
    for (double& v : q) v = reader.ReadF64("quaternion");
    for (double& v : t) v = reader.ReadF64("translation");
    bool ok = std::isfinite(t[0]) && std::isfinite(t[1]) && std::isfinite(t[2]);
    bool q_ok;
    image.pose.rotation = NormalizedQuaternion(q[0], q[1], q[2], q[3], &q_ok);
    if (!ok || !q_ok) {
      reader.FailAt(at + 4, "image " + std::to_string(id) +
                                ": expected a finite, non-zero quaternion and translation");
    }
    image.pose.translation = Eigen::Vector3d(t[0], t[1], t[2]);
    const uint32_t camera_id = reader.ReadU32("camera_id");
    if (camera_id > INT_MAX)
      reader.Fail("camera_id " + std::to_string(camera_id) + " is too large");
    image.camera_id = static_cast<int>(camera_id);
    image.name = reader.ReadCString("image name");
    const uint64_t num_points = reader.ReadCount("number of 2D points", 8 + 8 + 8);
    image.points2d.resize(num_points);
    for (Observation2D& obs : image.points2d) {
      const double x = reader.ReadF64("2D point x");
      const double y = reader.ReadF64("2D point y");
      obs.xy = Eigen::Vector2d(x, y);
      obs.point3d_id = reader.ReadU64("point3D_id");
    }
    if (!images.emplace(image.image_id, std::move(image)).second) {
      reader.FailAt(at, "duplicate image_id " + std::to_string(id));
    }
  }
  if (!reader.AtEnd()) reader.Fail("unexpected trailing bytes after the last image");
  return images;
}

std::map<uint64_t, Point3D> ReadPoints3DBinary(const std::string& path) {
  BinaryReader reader(path);
  // id u64, xyz f64[3], rgb u8[3], error f64, track length u64.
  constexpr size_t kMinRecord = 8 + 24 + 3 + 8 + 8;
  const uint64_t count = reader.ReadCount("number of 3D points", kMinRecord);
  std::map<uint64_t, Point3D> points;
  for (uint64_t i = 0; i < count; ++i) {
    const size_t at = reader.offset();
    Point3D point;
    point.point3d_id = reader.ReadU64("point3D_id");
    for (int k = 0; k < 3; ++k) point.xyz[k] = reader.ReadF64("point coordinate");
    for (uint8_t& c : point.rgb) c = reader.ReadU8("colour");
    point.error = reader.ReadF64("reprojection error");
    const uint64_t track_length = reader.ReadCount("track length", 4 + 4);
    point.track.resize(track_length);
    for (TrackElement& element : point.track) {
      const uint32_t image_id = reader.ReadU32("track image_id");
      const uint32_t idx = reader.ReadU32("track point2D_idx");
      if (image_id > INT_MAX || idx > INT_MAX) reader.Fail("track element out of range");
      element.image_id = static_cast<int>(image_id);
      element.point2d_idx = static_cast<int>(idx);
    }
    const uint64_t id = point.point3d_id;
    if (!points.emplace(id, std::move(point)).second) {
      reader.FailAt(at, "duplicate point3D_id " + std::to_string(id));
    }
  }
  if (!reader.AtEnd()) reader.Fail("unexpected trailing bytes after the last 3D point");
  return points;
}

// ---------------------------------------------------------------------------
// Model-level readers.

namespace {

// The three files of a model in one encoding, with the cross-file checks.
SparseModel ReadModelFiles(const std::string& dir, bool binary) {
  const std::string ext = binary ? ".bin" : ".txt";
  const std::string images_path = JoinPath(dir, "images" + ext);
  SparseModel model;
  model.cameras = binary ? ReadCamerasBinary(JoinPath(dir, "cameras" + ext))
                         : ReadCamerasText(JoinPath(dir, "cameras" + ext));
  model.images = binary ? ReadImagesBinary(images_path) : ReadImagesText(images_path);
  model.points = binary ? ReadPoints3DBinary(JoinPath(dir, "points3D" + ext))
                        : ReadPoints3DText(JoinPath(dir, "points3D" + ext));
  CheckCameraReferences(model, images_path);
  return model;
}

}  // namespace

SparseModel ReadModelText(const std::string& dir) { return ReadModelFiles(dir, false); }

SparseModel ReadModelBinary(const std::string& dir) { return ReadModelFiles(dir, true); }

SparseModel ReadModel(const std::string& dir) {
  auto all_exist = [&](const char* ext) {
    for (const char* stem : {"cameras", "images", "points3D"}) {
      if (!fs::is_regular_file(fs::path(dir) / (std::string(stem) + ext))) return false;
    }
    return true;
  };
  if (all_exist(".bin")) return ReadModelBinary(dir);
  if (all_exist(".txt")) return ReadModelText(dir);
  throw ModelError(dir +
                   ": not a COLMAP sparse model (expected cameras, images and points3D as .bin "
                   "or .txt files; pass the folder that holds them, e.g. sparse/0)");
}

// ---------------------------------------------------------------------------
// Writers.

void WriteModelText(const SparseModel& model, const std::string& dir) {
  CreateDir(dir);
  {
    std::ostringstream out = PreciseStream();
    out << "# Camera list with one line of data per camera:\n"
        << "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
        << "# Number of cameras: " << model.cameras.size() << "\n";
    for (const auto& [id, camera] : model.cameras) {
      const char* name = CameraModelName(camera.model);
      if (name == nullptr) {
        throw ModelError(JoinPath(dir, "cameras.txt") + ": camera " + std::to_string(id) +
                         " has an unsupported model");
      }
      out << id << " " << name << " " << camera.width << " " << camera.height;
      for (double p : camera.params) out << " " << p;
      out << "\n";
    }
    WriteFileAtomically(JoinPath(dir, "cameras.txt"), out.str());
  }
  {
    size_t num_observations = 0;
    for (const auto& entry : model.images) {
      for (const Observation2D& obs : entry.second.points2d) {
        if (obs.point3d_id != kInvalidPoint3DId) ++num_observations;
      }
    }
    const double mean_observations =
        model.images.empty() ? 0.0 : static_cast<double>(num_observations) / model.images.size();
    std::ostringstream out = PreciseStream();
    out << "# Image list with two lines of data per image:\n"
        << "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
        << "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
        << "# Number of images: " << model.images.size()
        << ", mean observations per image: " << mean_observations << "\n";
    for (const auto& [id, image] : model.images) {
      const Eigen::Quaterniond q = UnitForWriting(image.pose.rotation);
      const Eigen::Vector3d& t = image.pose.translation;
      out << id << " " << q.w() << " " << q.x() << " " << q.y() << " " << q.z() << " " << t.x()
          << " " << t.y() << " " << t.z() << " " << image.camera_id << " " << image.name << "\n";
      bool first = true;
      for (const Observation2D& obs : image.points2d) {
        if (!first) out << " ";
        first = false;
        out << obs.xy.x() << " " << obs.xy.y() << " ";
        if (obs.point3d_id == kInvalidPoint3DId) {
          out << -1;
        } else {
          out << obs.point3d_id;
        }
      }
      out << "\n";
    }
    WriteFileAtomically(JoinPath(dir, "images.txt"), out.str());
  }
  {
    size_t track_sum = 0;
    for (const auto& entry : model.points) track_sum += entry.second.track.size();
    const double mean_track =
        model.points.empty() ? 0.0 : static_cast<double>(track_sum) / model.points.size();
    std::ostringstream out = PreciseStream();
    out << "# 3D point list with one line of data per point:\n"
        << "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
        << "# Number of points: " << model.points.size() << ", mean track length: " << mean_track
        << "\n";
    for (const auto& [id, point] : model.points) {
      out << id << " " << point.xyz.x() << " " << point.xyz.y() << " " << point.xyz.z() << " "
          << int(point.rgb[0]) << " " << int(point.rgb[1]) << " " << int(point.rgb[2]) << " "
          << point.error;
      for (const TrackElement& element : point.track) {
        out << " " << element.image_id << " " << element.point2d_idx;
      }
      out << "\n";
    }
    WriteFileAtomically(JoinPath(dir, "points3D.txt"), out.str());
  }
}

void WriteModelBinary(const SparseModel& model, const std::string& dir) {
  CreateDir(dir);
  {
    BinaryWriter out;
    out.U64(model.cameras.size());
    for (const auto& [id, camera] : model.cameras) {
      out.U32(static_cast<uint32_t>(id));
      out.I32(static_cast<int32_t>(camera.model));
      out.U64(static_cast<uint64_t>(camera.width));
      out.U64(static_cast<uint64_t>(camera.height));
      for (double p : camera.params) out.F64(p);
    }
    WriteFileAtomically(JoinPath(dir, "cameras.bin"), out.bytes());
  }
  {
    BinaryWriter out;
    out.U64(model.images.size());
    for (const auto& [id, image] : model.images) {
      const Eigen::Quaterniond q = UnitForWriting(image.pose.rotation);
      out.U32(static_cast<uint32_t>(id));
      out.F64(q.w());
      out.F64(q.x());
      out.F64(q.y());
      out.F64(q.z());
      for (int k = 0; k < 3; ++k) out.F64(image.pose.translation[k]);
      out.U32(static_cast<uint32_t>(image.camera_id));
      out.CString(image.name);
      out.U64(image.points2d.size());
      for (const Observation2D& obs : image.points2d) {
        out.F64(obs.xy.x());
        out.F64(obs.xy.y());
        out.U64(obs.point3d_id);
      }
    }
    WriteFileAtomically(JoinPath(dir, "images.bin"), out.bytes());
  }
  {
    BinaryWriter out;
    out.U64(model.points.size());
    for (const auto& [id, point] : model.points) {
      out.U64(id);
      for (int k = 0; k < 3; ++k) out.F64(point.xyz[k]);
      for (uint8_t c : point.rgb) out.U8(c);
      out.F64(point.error);
      out.U64(point.track.size());
      for (const TrackElement& element : point.track) {
        out.U32(static_cast<uint32_t>(element.image_id));
        out.U32(static_cast<uint32_t>(element.point2d_idx));
      }
    }
    WriteFileAtomically(JoinPath(dir, "points3D.bin"), out.bytes());
  }
}

}  // namespace casual3d::geometry
