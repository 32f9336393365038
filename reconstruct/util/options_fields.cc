#include "reconstruct/util/options_fields.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <system_error>

namespace casual3d::util {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// A bound as people write it: 0.5, 100, 1e+06; an integer %g would round
// (2147483648) in full.
std::string BoundText(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", v);
  if (std::strtod(buf, nullptr) != v && v == std::floor(v) && std::fabs(v) < 1e15)
    std::snprintf(buf, sizeof(buf), "%.0f", v);
  return buf;
}

}  // namespace

Rule Rule::AtLeast(double lo) { return Rule(lo, kInf, false, true); }

Rule Rule::Above(double lo) { return Rule(lo, kInf, true, true); }

Rule Rule::ZeroOr(Rule rule) {
  rule.zero_ = true;
  return rule;
}

Rule Rule::OneOf(std::vector<std::string> choices) {
  Rule r;
  r.kind_ = Kind::kOneOf;
  r.choices_ = std::move(choices);
  return r;
}

bool Rule::Admits(double value) const {
  switch (kind_) {
    case Kind::kAny:
      return true;
    case Kind::kOneOf:
      return false;
    case Kind::kRange:
      break;
  }
  if (zero_ && value == 0) return true;
  const bool above = lo_open_ ? value > lo_ : value >= lo_;
  const bool below = hi_ == kInf ? value == value && value != kInf : (hi_open_ ? value < hi_ : value <= hi_);
  return above && below;
}

bool Rule::Admits(const std::string& value) const {
  switch (kind_) {
    case Kind::kAny:
      return true;
    case Kind::kRange:
      return false;
    case Kind::kOneOf:
      break;
  }
  return std::find(choices_.begin(), choices_.end(), value) != choices_.end();
}

std::string Rule::Text() const {
  switch (kind_) {
    case Kind::kAny:
      return "";
    case Kind::kOneOf: {
      std::string s = "one of ";
      for (size_t i = 0; i < choices_.size(); ++i) s += (i ? ", " : "") + choices_[i];
      return s;
    }
    case Kind::kRange:
      break;
  }
  std::string s;
  if (hi_ == kInf) {
    s = (lo_open_ ? "> " : ">= ") + BoundText(lo_);
  } else {
    s = (lo_open_ ? "(" : "[") + BoundText(lo_) + ", " + BoundText(hi_) + (hi_open_ ? ")" : "]");
  }
  return zero_ ? "0 or " + s : s;
}

std::string FormatFieldValue(double value) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof(buf), value);  // Shortest round trip.
  return std::string(buf, r.ptr);
}

std::string FormatFieldValue(long long value) { return std::to_string(value); }

std::string FormatFieldValue(bool value) { return value ? "true" : "false"; }

std::string FormatFieldValue(const std::string& value) {
  std::string s = "\"";
  for (const char c : value) {
    if (c == '"' || c == '\\') {
      s += '\\';
      s += c;
    } else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\x%02x", static_cast<unsigned char>(c));
      s += buf;
    } else {
      s += c;
    }
  }
  return s + "\"";
}

}  // namespace casual3d::util
