#pragma once

// Test helpers for options structs described with options_fields.h.
//
//   ExpectEveryFieldDescribed<Options>():  the description of Options and of
//     every struct nested in it names as many fields as the struct has, so a
//     field added without a description fails the test.
//   ExpectEveryFieldKeyed(options):  changing any keyed field to another value
//     its rule admits (the nearest representable one first, so the key's
//     number formatting is exact) changes FieldsKeyText; changing a
//     Keyed::kNo field does not.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "reconstruct/util/options_fields.h"

namespace casual3d::util::testing {

template <typename Options>
void ExpectEveryFieldDescribed(const std::string& name = "options");

namespace internal {

// Recurses into nested structs for ExpectEveryFieldDescribed.
class NestedDescribedVisitor {
 public:
  template <typename T>
  void Field(const char*, const T&, const Rule&, const char*, Keyed = Keyed::kYes) {}
  template <typename S>
  void Struct(const char* name, S&) {
    ExpectEveryFieldDescribed<std::remove_const_t<S>>(name);
  }
  void Require(bool, const char*, const std::string&) {}
};

// Candidate values for a perturbed field, nearest first.
template <typename T>
std::vector<T> Candidates(const T& v, const Rule& rule) {
  std::vector<T> out;
  if constexpr (std::is_same_v<T, bool>) {
    out = {!v};
  } else if constexpr (std::is_same_v<T, std::string>) {
    for (const std::string& c : rule.choices())
      if (c != v) out.push_back(c);
    out.push_back(v + "x");
  } else if constexpr (std::is_enum_v<T>) {
    const long long i = static_cast<long long>(v);
    out = {static_cast<T>(i + 1), static_cast<T>(i - 1)};
  } else if constexpr (std::is_integral_v<T>) {
    out = {static_cast<T>(v + 1), static_cast<T>(v - 1)};
    if (rule.zero_allowed()) out.push_back(0);
    if (std::isfinite(rule.lo())) out.push_back(static_cast<T>(rule.lo()));
    if (std::isfinite(rule.hi())) out.push_back(static_cast<T>(rule.hi()));
  } else {
    const T inf = std::numeric_limits<T>::infinity();
    out = {std::nextafter(v, inf), std::nextafter(v, -inf), v * 2, v / 2, v + 1, v - 1};
    if (rule.zero_allowed()) out.push_back(0);
    if (std::isfinite(rule.lo())) out.push_back(static_cast<T>(rule.lo()));
    if (std::isfinite(rule.hi())) out.push_back(static_cast<T>(rule.hi()));
  }
  return out;
}

// Sets field number `field` (counting leaf fields, nested ones included) to
// its candidate number `candidate`.
class PerturbVisitor : public FieldPath {
 public:
  PerturbVisitor(size_t field, size_t candidate) : field_(field), candidate_(candidate) {}
  template <typename T>
  void Field(const char* name, T& value, const Rule& rule, const char*, Keyed keyed = Keyed::kYes) {
    if (index_++ != field_) return;
    found_ = true;
    path_ = Path(name);
    keyed_ = keyed == Keyed::kYes;
    const std::vector<T> c = Candidates(value, rule);
    if (candidate_ >= c.size()) return;
    has_candidate_ = true;
    admitted_ = c[candidate_] != value && RuleAdmits(rule, c[candidate_]);
    value = c[candidate_];
  }
  template <typename S>
  void Struct(const char* name, S& sub) {
    Nested(name, sub, *this);
  }
  void Require(bool, const char*, const std::string&) {}

  size_t index_ = 0;
  size_t field_, candidate_;
  bool found_ = false, has_candidate_ = false, admitted_ = false, keyed_ = true;
  std::string path_;
};

}  // namespace internal

template <typename Options>
void ExpectEveryFieldDescribed(const std::string& name) {
  EXPECT_EQ(DescribedFieldCount<Options>(), AggregateFieldCount<Options>())
      << name << ": the struct's fields and its DescribeFields differ; describe every field";
  const Options options{};
  internal::NestedDescribedVisitor v;
  Options::DescribeFields(options, v);
}

template <typename Options>
void ExpectEveryFieldKeyed(const Options& base) {
  ASSERT_TRUE(CheckFields(base).ok()) << CheckFields(base).message();
  const std::string base_key = FieldsKeyText(base);
  size_t keyed = 0;
  for (size_t field = 0;; ++field) {
    // The first candidate the field's rule admits that also keeps the whole
    // struct valid; failing that (a field tied to another, such as a width
    // to its height), the first one the field's rule admits.
    bool found = false, is_keyed = true;
    std::string path;
    Options chosen = base;
    bool have = false;
    for (size_t candidate = 0;; ++candidate) {
      Options o = base;
      internal::PerturbVisitor v(field, candidate);
      Options::DescribeFields(o, v);
      found = v.found_;
      path = v.path_;
      is_keyed = v.keyed_;
      if (!found || !v.has_candidate_) break;
      if (!v.admitted_) continue;
      if (CheckFields(o).ok()) {
        chosen = o;
        have = true;
        break;
      }
      if (!have) {
        chosen = o;
        have = true;
      }
    }
    if (!found) break;
    EXPECT_TRUE(have) << path << ": no valid value to change it to";
    if (have && is_keyed) {
      EXPECT_NE(FieldsKeyText(chosen), base_key) << path << ": a change does not change the key";
    } else if (have) {
      EXPECT_EQ(FieldsKeyText(chosen), base_key) << path << ": Keyed::kNo, yet in the key";
    }
    keyed += is_keyed;
  }
  EXPECT_GT(keyed, 0u);
}

}  // namespace casual3d::util::testing
