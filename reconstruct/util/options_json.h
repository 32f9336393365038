#pragma once

// The report of an options struct (options_fields.h): every described field,
// nested structs as nested objects, enums as their integer value.

#include <nlohmann/json.hpp>

#include "reconstruct/util/options_fields.h"

namespace casual3d::util {

class JsonVisitor {
 public:
  template <typename T>
  void Field(const char* name, const T& value, const Rule&, const char*, Keyed = Keyed::kYes) {
    if constexpr (std::is_enum_v<T>) {
      json_[name] = static_cast<long long>(value);
    } else {
      json_[name] = value;
    }
  }
  template <typename S>
  void Struct(const char* name, S& sub) {
    JsonVisitor v;
    std::remove_const_t<S>::DescribeFields(sub, v);
    json_[name] = std::move(v.json_);
  }
  void Require(bool, const char*, const std::string&) {}
  nlohmann::json& json() { return json_; }

 private:
  nlohmann::json json_ = nlohmann::json::object();
};

template <typename Options>
nlohmann::json FieldsJson(const Options& options) {
  JsonVisitor v;
  Options::DescribeFields(options, v);
  return std::move(v.json());
}

}  // namespace casual3d::util
