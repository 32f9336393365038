#include "format/manifest.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "format/json.h"

namespace casual3d {
namespace {

using json::Value;

constexpr const char* kProjection = "equirectangular";
constexpr const char* kAxes = "right-up-back";
constexpr const char* kDepthType = "log";
constexpr const char* kNormalType = "octahedral";
constexpr const char* kNormalLossyType = "octahedral-lossy";  // Version 1.2.
constexpr const char* kColorType = "srgb8";

// Typed member access with messages that name the member's path.
class Reader {
 public:
  Reader(const Value& object, std::string where) : v_(object), where_(std::move(where)) {}

  std::string Name(const char* key) const {
    return where_.empty() ? std::string(key) : where_ + "." + key;
  }

  Status Get(const char* key, json::Type type, const Value** out) const {
    const Value* m = v_.Find(key);
    if (m == nullptr) return InvalidData(Name(key) + ": missing");
    if (m->type() != type)
      return InvalidData(Name(key) + ": expected a " + json::TypeName(type) + ", found a " +
                         json::TypeName(m->type()));
    *out = m;
    return Status::Ok();
  }

  Status Int(const char* key, int64_t min, int64_t max, int64_t* out) const {
    const Value* m;
    CASUAL3D_RETURN_IF_ERROR(Get(key, json::Type::kNumber, &m));
    const double d = m->number_value();
    if (d != std::floor(d)) return InvalidData(Name(key) + ": expected an integer");
    if (d < static_cast<double>(min) || d > static_cast<double>(max))
      return LimitExceeded(Name(key) + ": " + Format(d) + " is outside [" + std::to_string(min) +
                           ", " + std::to_string(max) + "]");
    *out = static_cast<int64_t>(d);
    return Status::Ok();
  }
  Status Int(const char* key, int64_t min, int64_t max, int* out) const {
    int64_t v;
    CASUAL3D_RETURN_IF_ERROR(Int(key, min, max, &v));
    *out = static_cast<int>(v);
    return Status::Ok();
  }

  Status Number(const char* key, double* out) const {
    const Value* m;
    CASUAL3D_RETURN_IF_ERROR(Get(key, json::Type::kNumber, &m));
    *out = m->number_value();
    return Status::Ok();
  }

  Status String(const char* key, std::string* out) const {
    const Value* m;
    CASUAL3D_RETURN_IF_ERROR(Get(key, json::Type::kString, &m));
    *out = m->string_value();
    return Status::Ok();
  }

  Status Constant(const char* key, const char* expected) const {
    std::string s;
    CASUAL3D_RETURN_IF_ERROR(String(key, &s));
    if (s != expected)
      return InvalidData(Name(key) + ": \"" + s + "\" is not supported (expected \"" + expected +
                         "\")");
    return Status::Ok();
  }

  Status NumberArray(const char* key, size_t n, double* out) const {
    const Value* m;
    CASUAL3D_RETURN_IF_ERROR(Get(key, json::Type::kArray, &m));
    if (m->array().size() != n)
      return InvalidData(Name(key) + ": expected " + std::to_string(n) + " numbers");
    for (size_t i = 0; i < n; ++i) {
      if (!m->array()[i].is_number())
        return InvalidData(Name(key) + "[" + std::to_string(i) + "]: expected a number");
      out[i] = m->array()[i].number_value();
    }
    return Status::Ok();
  }

  static std::string Format(double d) {
    char buf[32];
    std::snprintf(buf, sizeof(buf), "%.17g", d);
    return buf;
  }

 private:
  const Value& v_;
  std::string where_;
};

Value NumberArray(const double* v, int n) {
  Value a = Value::Array();
  for (int i = 0; i < n; ++i) a.Append(Value::Number(v[i]));
  return a;
}

bool IsHex64(const std::string& s) {
  if (s.size() != 64) return false;
  for (char c : s)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  return true;
}

constexpr const char* kReadsVersions = " (this reader reads 1.x and 2.x)";

// Level `l` of `m` is (width >> s) x (height >> s), exactly: s = l in 1.x (and
// in a major this reader does not know, read with the unknown-major check
// off, as 1.x); in 2.x s = 0 at level 0 and any shift above the level
// before's (`*shift`, which is updated) further on (spec/package.md Sec. 2).
Status CheckLevelSize(const Manifest& m, int l, const std::string& where, int* shift) {
  const LevelEntry& L = m.levels[l];
  auto exact = [&](int s) {
    return L.width >= 1 && L.height >= 1 && (m.width >> s) == L.width &&
           (m.height >> s) == L.height && (L.width << s) == m.width && (L.height << s) == m.height;
  };
  const std::string size = ": size " + std::to_string(L.width) + "x" + std::to_string(L.height) +
                           " is not the full size " + std::to_string(m.width) + "x" +
                           std::to_string(m.height) + " divided by 2^";
  if (m.version_major != 2 || l == 0) {
    if (!exact(l)) return InvalidData(where + size + std::to_string(l));
    *shift = l;
    return Status::Ok();
  }
  for (int s = *shift + 1; s < 31 && (m.width >> s) >= L.width; ++s) {
    if (exact(s)) {
      *shift = s;
      return Status::Ok();
    }
  }
  return InvalidData(where + size + "s for an s above the level before's " +
                     std::to_string(*shift));
}
}  // namespace

bool IsSafePackagePath(std::string_view path) {
  if (path.empty() || path.size() > kMaxPathBytes) return false;
  size_t start = 0;
  while (start <= path.size()) {
    size_t end = path.find('/', start);
    if (end == std::string_view::npos) end = path.size();
    const std::string_view part = path.substr(start, end - start);
    if (part.empty() || part == "." || part == "..") return false;
    for (char c : part) {
      const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      c == '.' || c == '_' || c == '-';
      if (!ok) return false;
    }
    start = end + 1;
  }
  return true;
}

const FileEntry* Manifest::FindFile(const std::string& path) const {
  auto it = std::lower_bound(files.begin(), files.end(), path,
                             [](const FileEntry& f, const std::string& p) { return f.path < p; });
  if (it == files.end() || it->path != path) return nullptr;
  return &*it;
}

void Manifest::TileRect(int level, int tile, int* x, int* y, int* w, int* h) const {
  const LevelEntry& L = levels[level];
  const int column = tile % L.columns, row = tile / L.columns;
  *x = column * tile_size;
  *y = row * tile_size;
  *w = std::min(tile_size, L.width - *x);
  *h = std::min(tile_size, L.height - *y);
}

uint64_t Manifest::LevelBytes(int level) const {
  uint64_t total = 0;
  for (const TileEntry& t : levels[level].tiles)
    for (const std::string& p : t.files)
      if (const FileEntry* f = FindFile(p)) total += f->bytes;
  return total;
}

Status Manifest::Validate(const ReaderChecks& checks) const {
  if (!IsKnownPackageMajor(version_major) && checks.on(ReaderCheck::kUnknownMajor))
    return UnsupportedVersion("version " + std::to_string(version_major) + "." +
                              std::to_string(version_minor) + " is not supported" +
                              kReadsVersions);
  if (width < 1 || height < 1 || width > kMaxPackageWidth || height > kMaxPackageHeight)
    return LimitExceeded("size " + std::to_string(width) + "x" + std::to_string(height) +
                         " is outside 1x1 .. " + std::to_string(kMaxPackageWidth) + "x" +
                         std::to_string(kMaxPackageHeight));
  for (double c : frame.centre)
    if (!std::isfinite(c)) return InvalidData("frame.centre: not finite");
  for (double r : frame.rotation)
    if (!std::isfinite(r) || std::fabs(r) > 1.000001)
      return InvalidData("frame.rotation: entries must be finite and within [-1, 1]");
  if (view) {
    Status hints = view->Validate();
    if (!hints.ok()) return Status(hints.code(), "view." + hints.message());
  }
  if (tile_size < kMinTileSize || tile_size > kMaxTileSize)
    return LimitExceeded("tile_size " + std::to_string(tile_size) + " is outside [" +
                         std::to_string(kMinTileSize) + ", " + std::to_string(kMaxTileSize) + "]");
  Status depth_ok = depth.Check();
  if (!depth_ok.ok()) return InvalidData("depth_encoding: " + depth_ok.message());
  // The log encoding divides by ln(far_m / near_m) (spec/package.md Sec. 4.2).
  if (!(depth.far_m > depth.near_m) && checks.on(ReaderCheck::kNearEqualsFar))
    return InvalidData("depth_encoding: near_m = far_m = " + Reader::Format(depth.near_m) +
                       "; the log encoding needs far_m > near_m");
  Status normal_ok = normal.Check();
  if (!normal_ok.ok()) return InvalidData("normal_encoding: " + normal_ok.message());
  if (levels.empty() || levels.size() > static_cast<size_t>(kMaxLevels))
    return LimitExceeded("levels: " + std::to_string(levels.size()) + " levels, expected 1.." +
                         std::to_string(kMaxLevels));
  for (size_t i = 0; i < files.size(); ++i) {
    const FileEntry& f = files[i];
    const std::string where = "files[" + std::to_string(i) + "]";
    if (!IsSafePackagePath(f.path) && checks.on(ReaderCheck::kPathEscape))
      return InvalidData(where + ".path: \"" + f.path.substr(0, 80) +
                         "\" is not a safe relative path inside the package");
    if (f.path == kManifestFileName)
      return InvalidData(where + ".path: the manifest cannot list itself");
    if (i > 0 && !(files[i - 1].path < f.path))
      return InvalidData(where + ".path: files must be sorted by path without duplicates (\"" +
                         f.path + "\")");
    if (f.bytes > kMaxFileBytes)
      return LimitExceeded(where + ".bytes: " + std::to_string(f.bytes) +
                           " exceeds the limit of " + std::to_string(kMaxFileBytes));
    if (!IsHex64(f.sha256))
      return InvalidData(where + ".sha256: expected 64 lower-case hexadecimal digits");
  }
  std::vector<uint8_t> used(files.size(), 0);
  int shift = -1;  // Of the level before.
  for (size_t l = 0; l < levels.size(); ++l) {
    const LevelEntry& L = levels[l];
    const std::string where = "levels[" + std::to_string(l) + "]";
    CASUAL3D_RETURN_IF_ERROR(CheckLevelSize(*this, static_cast<int>(l), where, &shift));
    const int columns = (L.width + tile_size - 1) / tile_size;
    const int rows = (L.height + tile_size - 1) / tile_size;
    if (L.columns != columns || L.rows != rows)
      return InvalidData(where + ": tile grid " + std::to_string(L.columns) + "x" +
                         std::to_string(L.rows) + ", expected " + std::to_string(columns) + "x" +
                         std::to_string(rows) + " for tile_size " + std::to_string(tile_size));
    if (static_cast<int64_t>(columns) * rows > kMaxTilesPerLevel)
      return LimitExceeded(where + ": more than " + std::to_string(kMaxTilesPerLevel) + " tiles");
    if (L.tiles.size() != static_cast<size_t>(columns) * rows)
      return InvalidData(where + ".tiles: " + std::to_string(L.tiles.size()) +
                         " tiles, expected " + std::to_string(columns * rows));
    for (size_t t = 0; t < L.tiles.size(); ++t) {
      for (int k = 0; k < kNumTileImageKinds; ++k) {
        const std::string& p = L.tiles[t].files[k];
        if (!IsSafePackagePath(p) && checks.on(ReaderCheck::kPathEscape))
          return InvalidData(where + ".tiles[" + std::to_string(t) + "]." +
                             TileImageKindName(static_cast<TileImageKind>(k)) + ": \"" +
                             p.substr(0, 80) + "\" is not a safe relative path inside the package");
        const FileEntry* f = FindFile(p);
        if (f == nullptr)
          return InvalidData(where + ".tiles[" + std::to_string(t) + "]." +
                             TileImageKindName(static_cast<TileImageKind>(k)) + ": \"" +
                             p.substr(0, 80) + "\" is not listed in files");
        uint8_t& u = used[f - files.data()];
        if (u)
          return InvalidData(where + ".tiles[" + std::to_string(t) + "]: \"" + p +
                             "\" is used by more than one tile image");
        u = 1;
      }
    }
  }
  return Status::Ok();
}

StatusOr<Manifest> ParseManifest(std::string_view bytes, const ReaderChecks& checks) {
  json::ParseLimits limits;
  limits.max_bytes = kMaxManifestBytes;
  // Without the nesting rule, still a bound on the parser's recursion.
  limits.max_depth = checks.on(ReaderCheck::kNestingTooDeep) ? kMaxManifestNesting : 64;
  limits.max_values = 1u << 20;  // Bounds memory (about 100 MB) on hostile input.
  StatusOr<Value> parsed = json::Parse(bytes, limits);
  if (!parsed.ok())
    return Status(parsed.status().code(), "manifest.json: " + parsed.status().message());
  const Value& root = *parsed;
  if (!root.is_object()) return InvalidData("manifest.json: the document must be a JSON object");
  Reader r(root, "");
  Manifest m;
  auto fail = [](const Status& s) { return Status(s.code(), "manifest.json: " + s.message()); };
#define C3D_CHECK(expr)                    \
  do {                                     \
    Status s_ = (expr);                    \
    if (!s_.ok()) return fail(s_);         \
  } while (0)

  C3D_CHECK(r.Constant("format", kPackageFormatName));
  std::string version;
  C3D_CHECK(r.String("version", &version));
  {
    const size_t dot = version.find('.');
    bool ok = dot != std::string::npos && dot > 0 && dot + 1 < version.size() &&
              version.size() <= 11;
    for (size_t i = 0; ok && i < version.size(); ++i)
      ok = i == dot || (version[i] >= '0' && version[i] <= '9');
    if (!ok) return fail(InvalidData("version: \"" + version.substr(0, 20) +
                                     "\" is not \"major.minor\""));
    // At most 11 characters, so each part has at most 9 digits and fits an int.
    auto number = [&](size_t begin, size_t end) {
      int v = 0;
      for (size_t i = begin; i < end; ++i) v = v * 10 + (version[i] - '0');
      return v;
    };
    m.version_major = number(0, dot);
    m.version_minor = number(dot + 1, version.size());
    if (!IsKnownPackageMajor(m.version_major) && checks.on(ReaderCheck::kUnknownMajor))
      return fail(UnsupportedVersion("version " + version + " is not supported" +
                                     kReadsVersions));
  }
  if (const Value* g = root.Find("generator"); g != nullptr && g->is_string())
    m.generator = g->string_value();
  C3D_CHECK(r.Constant("projection", kProjection));
  C3D_CHECK(r.Constant("axes", kAxes));
  C3D_CHECK(r.Int("width", 1, kMaxPackageWidth, &m.width));
  C3D_CHECK(r.Int("height", 1, kMaxPackageHeight, &m.height));
  const Value* layers;
  C3D_CHECK(r.Get("layers", json::Type::kArray, &layers));
  if (layers->array().size() != 2 || !layers->array()[0].is_string() ||
      !layers->array()[1].is_string() || layers->array()[0].string_value() != "front" ||
      layers->array()[1].string_value() != "back")
    return fail(InvalidData("layers: expected [\"front\", \"back\"]"));
  const Value* frame;
  C3D_CHECK(r.Get("frame", json::Type::kObject, &frame));
  Reader fr(*frame, "frame");
  C3D_CHECK(fr.NumberArray("centre", 3, m.frame.centre));
  C3D_CHECK(fr.NumberArray("rotation", 9, m.frame.rotation));
  if (const Value* view = root.Find("view"); view != nullptr) {
    ViewHints h;
    Status ok = ViewHintsFromJson(*view, &h);
    if (!ok.ok()) return fail(Status(ok.code(), "view." + ok.message()));
    m.view = h;
  }
  C3D_CHECK(r.Int("tile_size", kMinTileSize, kMaxTileSize, &m.tile_size));
  const Value* enc;
  C3D_CHECK(r.Get("depth_encoding", json::Type::kObject, &enc));
  Reader dr(*enc, "depth_encoding");
  C3D_CHECK(dr.Constant("type", kDepthType));
  C3D_CHECK(dr.Number("near_m", &m.depth.near_m));
  C3D_CHECK(dr.Number("far_m", &m.depth.far_m));
  C3D_CHECK(dr.Int("bits", 8, 16, &m.depth.bits));
  C3D_CHECK(r.Get("normal_encoding", json::Type::kObject, &enc));
  Reader nr(*enc, "normal_encoding");
  std::string normal_type;
  C3D_CHECK(nr.String("type", &normal_type));
  if (normal_type == kNormalType) {
    C3D_CHECK(nr.Int("bits", 4, 8, &m.normal.bits));
  } else if (normal_type == kNormalLossyType) {
    m.normal.type = NormalEncoding::kOctahedralLossy;
    m.normal.bits = 8;
    C3D_CHECK(nr.Number("mean_error_deg", &m.normal.mean_error_deg));
    C3D_CHECK(nr.Number("p99_error_deg", &m.normal.p99_error_deg));
  } else {
    return fail(InvalidData("normal_encoding.type: \"" + normal_type.substr(0, 40) +
                            "\" is not supported (this reader knows \"" + kNormalType +
                            "\" and \"" + kNormalLossyType + "\")"));
  }
  C3D_CHECK(r.Get("color_encoding", json::Type::kObject, &enc));
  C3D_CHECK(Reader(*enc, "color_encoding").Constant("type", kColorType));

  const Value* files;
  C3D_CHECK(r.Get("files", json::Type::kArray, &files));
  m.files.reserve(files->array().size());
  for (size_t i = 0; i < files->array().size(); ++i) {
    const Value& f = files->array()[i];
    const std::string where = "files[" + std::to_string(i) + "]";
    if (!f.is_object()) return fail(InvalidData(where + ": expected an object"));
    Reader fr2(f, where);
    FileEntry e;
    C3D_CHECK(fr2.String("path", &e.path));
    int64_t size;
    C3D_CHECK(fr2.Int("bytes", 0, static_cast<int64_t>(kMaxFileBytes), &size));
    e.bytes = static_cast<uint64_t>(size);
    C3D_CHECK(fr2.String("sha256", &e.sha256));
    m.files.push_back(std::move(e));
  }

  const Value* levels;
  C3D_CHECK(r.Get("levels", json::Type::kArray, &levels));
  if (levels->array().empty() || levels->array().size() > static_cast<size_t>(kMaxLevels))
    return fail(LimitExceeded("levels: " + std::to_string(levels->array().size()) +
                              " levels, expected 1.." + std::to_string(kMaxLevels)));
  for (size_t l = 0; l < levels->array().size(); ++l) {
    const Value& lv = levels->array()[l];
    const std::string where = "levels[" + std::to_string(l) + "]";
    if (!lv.is_object()) return fail(InvalidData(where + ": expected an object"));
    Reader lr(lv, where);
    LevelEntry L;
    C3D_CHECK(lr.Int("width", 1, kMaxPackageWidth, &L.width));
    C3D_CHECK(lr.Int("height", 1, kMaxPackageHeight, &L.height));
    C3D_CHECK(lr.Int("columns", 1, kMaxTilesPerLevel, &L.columns));
    C3D_CHECK(lr.Int("rows", 1, kMaxTilesPerLevel, &L.rows));
    const Value* tiles;
    C3D_CHECK(lr.Get("tiles", json::Type::kArray, &tiles));
    if (tiles->array().size() > static_cast<size_t>(kMaxTilesPerLevel))
      return fail(LimitExceeded(where + ".tiles: more than " + std::to_string(kMaxTilesPerLevel) +
                                " tiles"));
    L.tiles.resize(tiles->array().size());
    for (size_t t = 0; t < tiles->array().size(); ++t) {
      const Value& tv = tiles->array()[t];
      const std::string twhere = where + ".tiles[" + std::to_string(t) + "]";
      if (!tv.is_object()) return fail(InvalidData(twhere + ": expected an object"));
      Reader tr(tv, twhere);
      for (int k = 0; k < kNumTileImageKinds; ++k)
        C3D_CHECK(tr.String(TileImageKindName(static_cast<TileImageKind>(k)), &L.tiles[t].files[k]));
    }
    m.levels.push_back(std::move(L));
  }
#undef C3D_CHECK
  Status valid = m.Validate(checks);
  if (!valid.ok()) return fail(valid);
  return m;
}

std::string SerializeManifest(const Manifest& m, bool compact) {
  Value root = Value::Object();
  root.Set("format", Value::String(kPackageFormatName));
  root.Set("version", Value::String(std::to_string(m.version_major) + "." +
                                    std::to_string(m.version_minor)));
  if (!m.generator.empty()) root.Set("generator", Value::String(m.generator));
  root.Set("projection", Value::String(kProjection));
  root.Set("axes", Value::String(kAxes));
  root.Set("width", Value::Number(m.width));
  root.Set("height", Value::Number(m.height));
  Value layers = Value::Array();
  layers.Append(Value::String("front"));
  layers.Append(Value::String("back"));
  root.Set("layers", std::move(layers));
  Value frame = Value::Object();
  frame.Set("centre", NumberArray(m.frame.centre, 3));
  frame.Set("rotation", NumberArray(m.frame.rotation, 9));
  root.Set("frame", std::move(frame));
  if (m.view) root.Set("view", ViewHintsToJson(*m.view));
  root.Set("tile_size", Value::Number(m.tile_size));
  Value depth = Value::Object();
  depth.Set("type", Value::String(kDepthType));
  depth.Set("bits", Value::Number(m.depth.bits));
  depth.Set("near_m", Value::Number(m.depth.near_m));
  depth.Set("far_m", Value::Number(m.depth.far_m));
  root.Set("depth_encoding", std::move(depth));
  Value normal = Value::Object();
  if (m.normal.lossy()) {
    normal.Set("type", Value::String(kNormalLossyType));
    normal.Set("mean_error_deg", Value::Number(m.normal.mean_error_deg));
    normal.Set("p99_error_deg", Value::Number(m.normal.p99_error_deg));
  } else {
    normal.Set("type", Value::String(kNormalType));
    normal.Set("bits", Value::Number(m.normal.bits));
  }
  root.Set("normal_encoding", std::move(normal));
  Value color = Value::Object();
  color.Set("type", Value::String(kColorType));
  root.Set("color_encoding", std::move(color));
  Value levels = Value::Array();
  for (const LevelEntry& L : m.levels) {
    Value lv = Value::Object();
    lv.Set("width", Value::Number(L.width));
    lv.Set("height", Value::Number(L.height));
    lv.Set("columns", Value::Number(L.columns));
    lv.Set("rows", Value::Number(L.rows));
    Value tiles = Value::Array();
    for (const TileEntry& t : L.tiles) {
      Value tv = Value::Object();
      for (int k = 0; k < kNumTileImageKinds; ++k)
        tv.Set(TileImageKindName(static_cast<TileImageKind>(k)), Value::String(t.files[k]));
      tiles.Append(std::move(tv));
    }
    lv.Set("tiles", std::move(tiles));
    levels.Append(std::move(lv));
  }
  root.Set("levels", std::move(levels));
  Value files = Value::Array();
  for (const FileEntry& f : m.files) {
    Value fv = Value::Object();
    fv.Set("path", Value::String(f.path));
    fv.Set("bytes", Value::Number(static_cast<double>(f.bytes)));
    fv.Set("sha256", Value::String(f.sha256));
    files.Append(std::move(fv));
  }
  root.Set("files", std::move(files));
  return json::Serialize(root, compact ? 0 : 2) + "\n";
}

}  // namespace casual3d
