#pragma once

// An options struct describes each of its fields once: name, the field
// itself, its valid values and a one-line meaning. The range checks
// (CheckFields), the cache key (FieldsKeyText), the report (options_json.h)
// and the command line's help (cli/described_option.h) all read that one
// description, so a new option is added in two places: the struct and its
// description beside it.
//
// The struct declares, next to its fields and in their order:
//
//   template <typename Self, typename Visitor>
//   static void DescribeFields(Self& o, Visitor& v) {
//     v.Field("radius", o.radius, Rule::Closed(0, 32), "Window radius, working pixels; 0 = off");
//     v.Struct("sweep", o.sweep);  // A nested options struct with its own description.
//     v.Require(o.coarse_step <= o.search_labels, "coarse_step", "must not exceed search_labels");
//   }
//   Status Check() const { return util::CheckFields(*this); }
//
// Self is the struct or its const (visitors that only read get a const one).
// Field types: bool, integers, floating point, enums (keyed and reported as
// their integer value) and std::string. A field that cannot change what a
// stage writes (a thread count) is described with Keyed::kNo and left out of
// the cache key; every other field is in it.
//
// The rule: every field is described. ExpectEveryFieldDescribed
// (options_fields_testing.h) compares DescribedFieldCount with the number of
// members the compiler counts (AggregateFieldCount) for a struct and all
// the structs nested in it; each keyed struct's test calls it.

#include <cstddef>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "format/status.h"

namespace casual3d::util {

// The valid values of a field. A NaN is outside every range.
class Rule {
 public:
  static Rule Any() { return Rule(); }
  static Rule Closed(double lo, double hi) { return Rule(lo, hi, false, false); }      // [lo, hi]
  static Rule OpenClosed(double lo, double hi) { return Rule(lo, hi, true, false); }  // (lo, hi]
  static Rule ClosedOpen(double lo, double hi) { return Rule(lo, hi, false, true); }  // [lo, hi)
  static Rule Open(double lo, double hi) { return Rule(lo, hi, true, true); }         // (lo, hi)
  static Rule AtLeast(double lo);                                                     // [lo, inf)
  static Rule Above(double lo);                                                       // (lo, inf)
  // 0, or a value of `rule`.
  static Rule ZeroOr(Rule rule);
  // One of the strings (a string field).
  static Rule OneOf(std::vector<std::string> choices);

  bool IsAny() const { return kind_ == Kind::kAny; }
  bool Admits(double value) const;
  bool Admits(const std::string& value) const;
  // "[0, 1]", "(0, 10]", ">= 1", "0 or [1, 1e+06]", "one of A, B"; "" for Any.
  std::string Text() const;

  // For tests: the bounds of a range (lo = -inf, hi = +inf when open-ended).
  double lo() const { return lo_; }
  double hi() const { return hi_; }
  bool zero_allowed() const { return zero_; }
  const std::vector<std::string>& choices() const { return choices_; }

 private:
  enum class Kind { kAny, kRange, kOneOf };
  Rule() = default;
  Rule(double lo, double hi, bool lo_open, bool hi_open)
      : kind_(Kind::kRange), lo_(lo), hi_(hi), lo_open_(lo_open), hi_open_(hi_open) {}

  Kind kind_ = Kind::kAny;
  double lo_ = 0, hi_ = 0;
  bool lo_open_ = false, hi_open_ = false;
  bool zero_ = false;
  std::vector<std::string> choices_;
};

// Whether a field goes into the cache key.
enum class Keyed { kYes, kNo };

// A field's value as the cache key writes it: integers and enums in decimal,
// bools as true/false, floating point in the shortest form that reads back
// to the same value, strings quoted with \" \\ and control characters escaped.
std::string FormatFieldValue(double value);
std::string FormatFieldValue(long long value);
std::string FormatFieldValue(bool value);
std::string FormatFieldValue(const std::string& value);

template <typename T>
std::string FormatAnyFieldValue(const T& value) {
  if constexpr (std::is_same_v<T, bool>) {
    return FormatFieldValue(value);
  } else if constexpr (std::is_enum_v<T>) {
    return FormatFieldValue(static_cast<long long>(value));
  } else if constexpr (std::is_integral_v<T>) {
    return FormatFieldValue(static_cast<long long>(value));
  } else if constexpr (std::is_floating_point_v<T>) {
    return FormatFieldValue(static_cast<double>(value));
  } else {
    static_assert(std::is_same_v<T, std::string>, "options fields are bool, numbers, enums or strings");
    return FormatFieldValue(value);
  }
}

// A field's value against its rule.
template <typename T>
bool RuleAdmits(const Rule& rule, const T& value) {
  if constexpr (std::is_same_v<T, std::string>) {
    return rule.Admits(value);
  } else if constexpr (std::is_enum_v<T>) {
    return rule.Admits(static_cast<double>(static_cast<long long>(value)));
  } else {
    return rule.Admits(static_cast<double>(value));
  }
}

// Base of the visitors below: the dotted path of the field being visited.
class FieldPath {
 public:
  std::string Path(const char* name) const { return prefix_ + name; }

 protected:
  template <typename S, typename V>
  void Nested(const char* name, S& sub, V& visitor) {
    const size_t size = prefix_.size();
    prefix_ += name;
    prefix_ += '.';
    std::remove_const_t<S>::DescribeFields(sub, visitor);
    prefix_.resize(size);
  }

 private:
  std::string prefix_;
};

// Finds the first field outside its rule, or the first unmet requirement.
class CheckVisitor : public FieldPath {
 public:
  template <typename T>
  void Field(const char* name, const T& value, const Rule& rule, const char* meaning,
             Keyed keyed = Keyed::kYes) {
    if (!status_.ok() || RuleAdmits(rule, value)) return;
    std::string shown = FormatAnyFieldValue(value);
    status_ = InvalidArgument(Path(name) + " " + shown + " outside " + rule.Text());
  }
  template <typename S>
  void Struct(const char* name, S& sub) {
    Nested(name, sub, *this);
  }
  void Require(bool ok, const char* name, const std::string& what) {
    if (status_.ok() && !ok) status_ = InvalidArgument(Path(name) + " " + what);
  }
  const Status& status() const { return status_; }

 private:
  Status status_;
};

// Every field's range and every requirement, nested structs included; the
// message names the field's path ("mrf.max_iterations 0 outside [1, 1000]").
template <typename Options>
Status CheckFields(const Options& options) {
  CheckVisitor v;
  Options::DescribeFields(options, v);
  return v.status();
}

// "path=value\n" for every keyed field, nested structs included
// ("mrf.max_iterations=6"), in the order of the description.
class KeyVisitor : public FieldPath {
 public:
  template <typename T>
  void Field(const char* name, const T& value, const Rule&, const char*, Keyed keyed = Keyed::kYes) {
    if (keyed == Keyed::kNo) return;
    text_ += Path(name);
    text_ += '=';
    text_ += FormatAnyFieldValue(value);
    text_ += '\n';
  }
  template <typename S>
  void Struct(const char* name, S& sub) {
    Nested(name, sub, *this);
  }
  void Require(bool, const char*, const std::string&) {}
  const std::string& text() const { return text_; }

 private:
  std::string text_;
};

// The cache key's text of `options` (reconstruct/pipeline/pipeline.h, "Cache key").
template <typename Options>
std::string FieldsKeyText(const Options& options) {
  KeyVisitor v;
  Options::DescribeFields(options, v);
  return v.text();
}

// What the description says of one field.
struct FieldInfo {
  bool found = false;
  std::string path;     // "mrf.lambda_smooth".
  Rule rule = Rule::Any();
  std::string meaning;  // One line.
};

// Finds the field at `address` (a member of the struct visited, or of one
// nested in it).
class FindVisitor : public FieldPath {
 public:
  explicit FindVisitor(const void* address) : address_(address) {}
  template <typename T>
  void Field(const char* name, const T& value, const Rule& rule, const char* meaning,
             Keyed keyed = Keyed::kYes) {
    if (info_.found || static_cast<const void*>(&value) != address_) return;
    info_.found = true;
    info_.path = Path(name);
    info_.rule = rule;
    info_.meaning = meaning;
  }
  template <typename S>
  void Struct(const char* name, S& sub) {
    Nested(name, sub, *this);
  }
  void Require(bool, const char*, const std::string&) {}
  const FieldInfo& info() const { return info_; }

 private:
  const void* address_;
  FieldInfo info_;
};

// The description of `field`, a member of `options` (or of a struct nested in
// it); found is false if the description leaves it out.
template <typename Options, typename T>
FieldInfo DescribeField(const Options& options, const T& field) {
  FindVisitor v(&field);
  Options::DescribeFields(options, v);
  return v.info();
}

// Fields and nested structs the description of Options names (not recursing).
class CountVisitor {
 public:
  template <typename T>
  void Field(const char*, const T&, const Rule&, const char*, Keyed = Keyed::kYes) {
    ++count_;
  }
  template <typename S>
  void Struct(const char*, S&) {
    ++count_;
  }
  void Require(bool, const char*, const std::string&) {}
  size_t count() const { return count_; }

 private:
  size_t count_ = 0;
};

template <typename Options>
size_t DescribedFieldCount() {
  const Options options{};
  CountVisitor v;
  Options::DescribeFields(options, v);
  return v.count();
}

namespace internal {

// Converts to any member type; only used unevaluated.
struct AnyMember {
  template <typename T>
  operator T() const;  // NOLINT: implicit by design.
};

template <typename T, typename Seq, typename = void>
struct BraceInitializable : std::false_type {};
template <typename T, size_t... I>
struct BraceInitializable<T, std::index_sequence<I...>,
                          std::void_t<decltype(T{(void(I), AnyMember{})...})>> : std::true_type {};

}  // namespace internal

// The number of members of the aggregate T: the most initialisers T{...}
// accepts (each member takes one, nested structs included).
template <typename T, size_t N = 0>
constexpr size_t AggregateFieldCount() {
  static_assert(std::is_aggregate_v<T>, "options structs are aggregates");
  if constexpr (N < 256 && internal::BraceInitializable<T, std::make_index_sequence<N + 1>>::value) {
    return AggregateFieldCount<T, N + 1>();
  } else {
    return N;
  }
}

}  // namespace casual3d::util
