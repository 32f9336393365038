#include "format/view_hints.h"

#include <cmath>
#include <string>

namespace casual3d {
namespace {

bool InRange(double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; }

std::string Text(double v) {
  std::string s = std::to_string(v);
  return s;
}

Status NumberMember(const json::Value& o, const char* key, double* out) {
  const json::Value* m = o.Find(key);
  if (m == nullptr) return InvalidData(std::string(key) + ": missing");
  if (!m->is_number()) return InvalidData(std::string(key) + ": expected a number");
  *out = m->number_value();
  return Status::Ok();
}

Status PairMember(const json::Value& o, const char* key, double* lo, double* hi) {
  const json::Value* m = o.Find(key);
  if (m == nullptr) return InvalidData(std::string(key) + ": missing");
  if (!m->is_array() || m->array().size() != 2 || !m->array()[0].is_number() ||
      !m->array()[1].is_number())
    return InvalidData(std::string(key) + ": expected 2 numbers");
  *lo = m->array()[0].number_value();
  *hi = m->array()[1].number_value();
  return Status::Ok();
}

json::Value Pair(double a, double b) {
  json::Value v = json::Value::Array();
  v.Append(json::Value::Number(a));
  v.Append(json::Value::Number(b));
  return v;
}

}  // namespace

json::Value ViewHintsToJson(const ViewHints& h) {
  json::Value v = json::Value::Object();
  v.Set("yaw_deg", json::Value::Number(h.yaw_deg));
  v.Set("pitch_deg", json::Value::Number(h.pitch_deg));
  v.Set("fov_deg", json::Value::Number(h.fov_deg));
  v.Set("content_yaw_deg", Pair(h.content_yaw_min_deg, h.content_yaw_max_deg));
  v.Set("content_pitch_deg", Pair(h.content_pitch_min_deg, h.content_pitch_max_deg));
  v.Set("volume_radius", json::Value::Number(h.volume_radius));
  v.Set("metric", json::Value::Bool(h.metric));
  return v;
}

Status ViewHintsFromJson(const json::Value& o, ViewHints* out) {
  if (!o.is_object()) return InvalidData("expected an object");
  ViewHints h;
  CASUAL3D_RETURN_IF_ERROR(NumberMember(o, "yaw_deg", &h.yaw_deg));
  CASUAL3D_RETURN_IF_ERROR(NumberMember(o, "pitch_deg", &h.pitch_deg));
  CASUAL3D_RETURN_IF_ERROR(NumberMember(o, "fov_deg", &h.fov_deg));
  CASUAL3D_RETURN_IF_ERROR(PairMember(o, "content_yaw_deg", &h.content_yaw_min_deg, &h.content_yaw_max_deg));
  CASUAL3D_RETURN_IF_ERROR(
      PairMember(o, "content_pitch_deg", &h.content_pitch_min_deg, &h.content_pitch_max_deg));
  CASUAL3D_RETURN_IF_ERROR(NumberMember(o, "volume_radius", &h.volume_radius));
  const json::Value* metric = o.Find("metric");
  if (metric == nullptr) return InvalidData("metric: missing");
  if (!metric->is_bool()) return InvalidData("metric: expected true or false");
  h.metric = metric->bool_value();
  CASUAL3D_RETURN_IF_ERROR(h.Validate());
  *out = h;
  return Status::Ok();
}

std::string SerializeViewHints(const ViewHints& hints) {
  return json::Serialize(ViewHintsToJson(hints), 0);
}

StatusOr<ViewHints> ParseViewHints(std::string_view text) {
  json::ParseLimits limits;
  limits.max_bytes = 4096;
  limits.max_depth = 4;
  limits.max_values = 64;
  StatusOr<json::Value> parsed = json::Parse(text, limits);
  if (!parsed.ok()) return parsed.status();
  ViewHints h;
  CASUAL3D_RETURN_IF_ERROR(ViewHintsFromJson(*parsed, &h));
  return h;
}

Status ViewHints::Validate() const {
  if (!InRange(yaw_deg, -180, 180)) return InvalidData("yaw_deg " + Text(yaw_deg) + " is outside [-180, 180]");
  if (!InRange(pitch_deg, -90, 90)) return InvalidData("pitch_deg " + Text(pitch_deg) + " is outside [-90, 90]");
  if (!InRange(fov_deg, 10, 120)) return InvalidData("fov_deg " + Text(fov_deg) + " is outside [10, 120]");
  if (!InRange(content_yaw_min_deg, -360, 360) || !InRange(content_yaw_max_deg, -360, 360) ||
      content_yaw_min_deg > content_yaw_max_deg || content_yaw_max_deg - content_yaw_min_deg > 360)
    return InvalidData("content_yaw_deg [" + Text(content_yaw_min_deg) + ", " + Text(content_yaw_max_deg) +
                       "] must satisfy -360 <= min <= max <= 360 and max - min <= 360");
  if (!InRange(content_pitch_min_deg, -90, 90) || !InRange(content_pitch_max_deg, -90, 90) ||
      content_pitch_min_deg > content_pitch_max_deg)
    return InvalidData("content_pitch_deg [" + Text(content_pitch_min_deg) + ", " + Text(content_pitch_max_deg) +
                       "] must satisfy -90 <= min <= max <= 90");
  if (!(std::isfinite(volume_radius) && volume_radius > 0))
    return InvalidData("volume_radius " + Text(volume_radius) + " must be finite and > 0");
  return Status::Ok();
}

bool ViewHints::operator==(const ViewHints& o) const {
  return yaw_deg == o.yaw_deg && pitch_deg == o.pitch_deg && fov_deg == o.fov_deg &&
         content_yaw_min_deg == o.content_yaw_min_deg && content_yaw_max_deg == o.content_yaw_max_deg &&
         content_pitch_min_deg == o.content_pitch_min_deg && content_pitch_max_deg == o.content_pitch_max_deg &&
         volume_radius == o.volume_radius && metric == o.metric;
}

}  // namespace casual3d
