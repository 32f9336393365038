#pragma once

// Text for the HTML pages the project writes (viewer page, evaluation report).

#include <string>
#include <string_view>

namespace casual3d::util {

// `text` with &, <, > and " replaced by character references, safe inside
// element content and double-quoted attribute values.
std::string HtmlEscape(std::string_view text);

}  // namespace casual3d::util
