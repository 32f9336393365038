#pragma once

// Command-line options bound to a field of an options struct that describes
// itself (reconstruct/util/options_fields.h): the help text is the field's
// meaning, the value is checked against the field's rule, and the rule is
// shown beside the type ("FLOAT:[0, 100]").

#include <CLI/CLI.hpp>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "reconstruct/util/options_fields.h"

namespace casual3d::cli {

// Adds option `name` to `cmd` for `field`, a member of `options` or of a
// struct nested in it. Throws std::logic_error if the description leaves the
// field out (a programming error, seen at start-up).
template <typename Options, typename T>
CLI::Option* AddDescribedOption(CLI::App* cmd, const std::string& name, Options& options, T& field) {
  const util::FieldInfo info = util::DescribeField(options, field);
  if (!info.found) throw std::logic_error(name + ": not a described field of its options");
  CLI::Option* option = cmd->add_option(name, field, info.meaning)->capture_default_str();
  if (info.rule.IsAny()) return option;
  const util::Rule rule = info.rule;
  option->check(CLI::Validator(
      [rule](std::string& text) -> std::string {
        if constexpr (std::is_same_v<T, std::string>) {
          return rule.Admits(text) ? "" : text + " is not " + rule.Text();
        } else {
          char* end = nullptr;
          const double value = std::strtod(text.c_str(), &end);
          if (end == text.c_str()) return "";  // Not a number: the conversion says so.
          return rule.Admits(value) ? "" : text + " is outside " + rule.Text();
        }
      },
      rule.Text(), "described range"));
  return option;
}

}  // namespace casual3d::cli
