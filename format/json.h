#pragma once

// A small, safe JSON (RFC 8259) parser and writer for the package manifest.
// Standard library only, no exceptions. The parser takes untrusted bytes: it
// enforces size and nesting limits and reports the first error with its byte
// offset ("byte 17: expected ':' after an object key"). Objects keep their key
// order; duplicate keys are refused. Numbers are doubles (integers up to 2^53
// are exact).

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "format/status.h"

namespace casual3d::json {

enum class Type { kNull, kBool, kNumber, kString, kArray, kObject };

// Name of a type for messages: "null", "boolean", "number", "string", "array", "object".
const char* TypeName(Type type);

class Value {
 public:
  Value() = default;  // null
  static Value Bool(bool b);
  static Value Number(double n);
  static Value String(std::string s);
  static Value Array();
  static Value Object();

  Type type() const { return type_; }
  bool is_null() const { return type_ == Type::kNull; }
  bool is_bool() const { return type_ == Type::kBool; }
  bool is_number() const { return type_ == Type::kNumber; }
  bool is_string() const { return type_ == Type::kString; }
  bool is_array() const { return type_ == Type::kArray; }
  bool is_object() const { return type_ == Type::kObject; }

  // Accessors; each precondition is the matching is_*() (else a default value).
  bool bool_value() const { return bool_; }
  double number_value() const { return number_; }
  const std::string& string_value() const { return string_; }
  const std::vector<Value>& array() const { return array_; }
  std::vector<Value>& array() { return array_; }
  const std::vector<std::pair<std::string, Value>>& object() const { return object_; }

  // Object member by key, or nullptr (also when this is not an object).
  const Value* Find(std::string_view key) const;
  // Appends an array element (precondition: is_array()).
  void Append(Value v) { array_.push_back(std::move(v)); }
  // Sets an object member, replacing an existing one (precondition: is_object()).
  void Set(std::string key, Value v);

  bool operator==(const Value& o) const;
  bool operator!=(const Value& o) const { return !(*this == o); }

 private:
  Type type_ = Type::kNull;
  bool bool_ = false;
  double number_ = 0.0;
  std::string string_;
  std::vector<Value> array_;
  std::vector<std::pair<std::string, Value>> object_;
};

struct ParseLimits {
  size_t max_bytes = 16u << 20;    // Whole document, bytes.
  int max_depth = 64;              // Nesting of arrays and objects.
  size_t max_string_bytes = 1u << 20;  // One string after unescaping, bytes.
  size_t max_values = 1u << 22;    // Values of all kinds in the document.
  size_t max_object_members = 1024;  // Members of one object (duplicate checks are linear).
};

// Parses one JSON document (surrounding whitespace allowed, nothing else).
// Errors are kInvalidData with the byte offset, or kLimitExceeded.
StatusOr<Value> Parse(std::string_view text, const ParseLimits& limits = ParseLimits());

// Serializes `value`. `indent` > 0 pretty-prints with that many spaces per
// level; 0 writes everything on one line. Non-finite numbers are written as null.
// Strings are written as UTF-8 with the required escapes.
std::string Serialize(const Value& value, int indent = 0);

}  // namespace casual3d::json
