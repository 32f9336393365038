#include "format/json.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace casual3d::json {

const char* TypeName(Type type) {
  switch (type) {
    case Type::kNull: return "null";
    case Type::kBool: return "boolean";
    case Type::kNumber: return "number";
    case Type::kString: return "string";
    case Type::kArray: return "array";
    case Type::kObject: return "object";
  }
  return "unknown";
}

Value Value::Bool(bool b) {
  Value v;
  v.type_ = Type::kBool;
  v.bool_ = b;
  return v;
}
Value Value::Number(double n) {
  Value v;
  v.type_ = Type::kNumber;
  v.number_ = n;
  return v;
}
Value Value::String(std::string s) {
  Value v;
  v.type_ = Type::kString;
  v.string_ = std::move(s);
  return v;
}
Value Value::Array() {
  Value v;
  v.type_ = Type::kArray;
  return v;
}
Value Value::Object() {
  Value v;
  v.type_ = Type::kObject;
  return v;
}

const Value* Value::Find(std::string_view key) const {
  if (type_ != Type::kObject) return nullptr;
  for (const auto& [k, v] : object_)
    if (k == key) return &v;
  return nullptr;
}

void Value::Set(std::string key, Value v) {
  for (auto& [k, old] : object_) {
    if (k == key) {
      old = std::move(v);
      return;
    }
  }
  object_.emplace_back(std::move(key), std::move(v));
}

bool Value::operator==(const Value& o) const {
  if (type_ != o.type_) return false;
  switch (type_) {
    case Type::kNull: return true;
    case Type::kBool: return bool_ == o.bool_;
    case Type::kNumber: return number_ == o.number_;
    case Type::kString: return string_ == o.string_;
    case Type::kArray: return array_ == o.array_;
    case Type::kObject: return object_ == o.object_;
  }
  return false;
}

namespace {

class Parser {
 public:
  Parser(std::string_view text, const ParseLimits& limits) : s_(text), limits_(limits) {}

  StatusOr<Value> Run() {
    if (s_.size() > limits_.max_bytes)
      return LimitExceeded("JSON document of " + std::to_string(s_.size()) +
                           " bytes exceeds the limit of " + std::to_string(limits_.max_bytes));
    Value root;
    if (!ParseValue(&root, 0)) return error_;
    SkipSpace();
    if (pos_ != s_.size()) return Fail("unexpected text after the JSON document");
    return root;
  }

 private:
  Status Fail(const std::string& what) {
    error_ = InvalidData("byte " + std::to_string(pos_) + ": " + what);
    return error_;
  }
  bool FailB(const std::string& what) {
    Fail(what);
    return false;
  }

  void SkipSpace() {
    while (pos_ < s_.size() &&
           (s_[pos_] == ' ' || s_[pos_] == '\t' || s_[pos_] == '\n' || s_[pos_] == '\r'))
      ++pos_;
  }

  bool ParseValue(Value* out, int depth) {
    if (++values_ > limits_.max_values) {
      error_ = LimitExceeded("JSON document has more than " + std::to_string(limits_.max_values) +
                             " values");
      return false;
    }
    SkipSpace();
    if (pos_ >= s_.size()) return FailB("unexpected end of input, expected a value");
    const char c = s_[pos_];
    if (c == '{' || c == '[') {
      if (depth >= limits_.max_depth) {
        error_ = LimitExceeded("byte " + std::to_string(pos_) + ": nesting deeper than " +
                               std::to_string(limits_.max_depth));
        return false;
      }
      return c == '{' ? ParseObject(out, depth + 1) : ParseArray(out, depth + 1);
    }
    if (c == '"') {
      std::string str;
      if (!ParseString(&str)) return false;
      *out = Value::String(std::move(str));
      return true;
    }
    if (c == 't') return ParseLiteral("true", Value::Bool(true), out);
    if (c == 'f') return ParseLiteral("false", Value::Bool(false), out);
    if (c == 'n') return ParseLiteral("null", Value(), out);
    if (c == '-' || (c >= '0' && c <= '9')) return ParseNumber(out);
    return FailB(std::string("unexpected character '") + Printable(c) + "', expected a value");
  }

  static std::string Printable(char c) {
    if (c >= 0x20 && c < 0x7f) return std::string(1, c);
    char buf[8];
    std::snprintf(buf, sizeof(buf), "\\x%02x", static_cast<unsigned char>(c));
    return buf;
  }

  bool ParseLiteral(std::string_view word, Value v, Value* out) {
    if (s_.substr(pos_, word.size()) != word)
      return FailB("invalid literal, expected '" + std::string(word) + "'");
    pos_ += word.size();
    *out = std::move(v);
    return true;
  }

  bool ParseNumber(Value* out) {
    const size_t start = pos_;
    if (s_[pos_] == '-') ++pos_;
    auto digits = [&] {
      size_t n = 0;
      while (pos_ < s_.size() && s_[pos_] >= '0' && s_[pos_] <= '9') ++pos_, ++n;
      return n;
    };
    if (pos_ < s_.size() && s_[pos_] == '0') {
      ++pos_;
      if (pos_ < s_.size() && s_[pos_] >= '0' && s_[pos_] <= '9')
        return FailB("numbers must not have leading zeros");
    } else if (digits() == 0) {
      return FailB("expected digits in a number");
    }
    if (pos_ < s_.size() && s_[pos_] == '.') {
      ++pos_;
      if (digits() == 0) return FailB("expected digits after the decimal point");
    }
    if (pos_ < s_.size() && (s_[pos_] == 'e' || s_[pos_] == 'E')) {
      ++pos_;
      if (pos_ < s_.size() && (s_[pos_] == '+' || s_[pos_] == '-')) ++pos_;
      if (digits() == 0) return FailB("expected digits in the exponent");
    }
    if (pos_ - start > 64) {
      pos_ = start;
      return FailB("number longer than 64 characters");
    }
    // The token is validated JSON syntax, which strtod reads the same way in
    // the "C" locale.
    const std::string token(s_.substr(start, pos_ - start));
    const double value = std::strtod(token.c_str(), nullptr);
    if (!std::isfinite(value)) {
      pos_ = start;
      return FailB("number out of range");
    }
    *out = Value::Number(value);
    return true;
  }

  static void AppendUtf8(uint32_t cp, std::string* out) {
    if (cp < 0x80) {
      out->push_back(static_cast<char>(cp));
    } else if (cp < 0x800) {
      out->push_back(static_cast<char>(0xC0 | (cp >> 6)));
      out->push_back(static_cast<char>(0x80 | (cp & 0x3F)));
    } else if (cp < 0x10000) {
      out->push_back(static_cast<char>(0xE0 | (cp >> 12)));
      out->push_back(static_cast<char>(0x80 | ((cp >> 6) & 0x3F)));
      out->push_back(static_cast<char>(0x80 | (cp & 0x3F)));
    } else {
      out->push_back(static_cast<char>(0xF0 | (cp >> 18)));
      out->push_back(static_cast<char>(0x80 | ((cp >> 12) & 0x3F)));
      out->push_back(static_cast<char>(0x80 | ((cp >> 6) & 0x3F)));
      out->push_back(static_cast<char>(0x80 | (cp & 0x3F)));
    }
  }

  bool ParseHex4(uint32_t* out) {
    if (s_.size() - pos_ < 4) return FailB("truncated \\u escape");
    uint32_t v = 0;
    for (int i = 0; i < 4; ++i) {
      const char c = s_[pos_ + i];
      v <<= 4;
      if (c >= '0' && c <= '9') v |= c - '0';
      else if (c >= 'a' && c <= 'f') v |= c - 'a' + 10;
      else if (c >= 'A' && c <= 'F') v |= c - 'A' + 10;
      else return FailB("invalid hex digit in \\u escape");
    }
    pos_ += 4;
    *out = v;
    return true;
  }

  // Checks one UTF-8 sequence starting at pos_ and appends it.
  bool CopyUtf8(std::string* out) {
    const unsigned char c = static_cast<unsigned char>(s_[pos_]);
    int extra;
    uint32_t cp, min;
    if (c < 0x80) { extra = 0; cp = c; min = 0; }
    else if ((c & 0xE0) == 0xC0) { extra = 1; cp = c & 0x1F; min = 0x80; }
    else if ((c & 0xF0) == 0xE0) { extra = 2; cp = c & 0x0F; min = 0x800; }
    else if ((c & 0xF8) == 0xF0) { extra = 3; cp = c & 0x07; min = 0x10000; }
    else return FailB("invalid UTF-8 in a string");
    if (s_.size() - pos_ <= static_cast<size_t>(extra)) return FailB("truncated UTF-8 in a string");
    for (int i = 1; i <= extra; ++i) {
      const unsigned char d = static_cast<unsigned char>(s_[pos_ + i]);
      if ((d & 0xC0) != 0x80) return FailB("invalid UTF-8 in a string");
      cp = (cp << 6) | (d & 0x3F);
    }
    if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF))
      return FailB("invalid UTF-8 in a string");
    out->append(s_.substr(pos_, extra + 1));
    pos_ += extra + 1;
    return true;
  }

  bool ParseString(std::string* out) {
    ++pos_;  // Opening quote.
    while (true) {
      if (out->size() > limits_.max_string_bytes) {
        error_ = LimitExceeded("byte " + std::to_string(pos_) + ": string longer than " +
                               std::to_string(limits_.max_string_bytes) + " bytes");
        return false;
      }
      if (pos_ >= s_.size()) return FailB("unterminated string");
      const char c = s_[pos_];
      if (c == '"') {
        ++pos_;
        return true;
      }
      if (static_cast<unsigned char>(c) < 0x20)
        return FailB("control character in a string must be escaped");
      if (c != '\\') {
        if (!CopyUtf8(out)) return false;
        continue;
      }
      ++pos_;
      if (pos_ >= s_.size()) return FailB("unterminated escape in a string");
      const char e = s_[pos_++];
      switch (e) {
        case '"': out->push_back('"'); break;
        case '\\': out->push_back('\\'); break;
        case '/': out->push_back('/'); break;
        case 'b': out->push_back('\b'); break;
        case 'f': out->push_back('\f'); break;
        case 'n': out->push_back('\n'); break;
        case 'r': out->push_back('\r'); break;
        case 't': out->push_back('\t'); break;
        case 'u': {
          uint32_t cp;
          if (!ParseHex4(&cp)) return false;
          if (cp >= 0xDC00 && cp <= 0xDFFF) return FailB("unpaired low surrogate in \\u escape");
          if (cp >= 0xD800 && cp <= 0xDBFF) {
            uint32_t low;
            if (s_.substr(pos_, 2) != "\\u") return FailB("unpaired high surrogate in \\u escape");
            pos_ += 2;
            if (!ParseHex4(&low)) return false;
            if (low < 0xDC00 || low > 0xDFFF) return FailB("invalid low surrogate in \\u escape");
            cp = 0x10000 + ((cp - 0xD800) << 10) + (low - 0xDC00);
          }
          AppendUtf8(cp, out);
          break;
        }
        default:
          --pos_;
          return FailB(std::string("invalid escape '\\") + Printable(e) + "'");
      }
    }
  }

  bool ParseArray(Value* out, int depth) {
    ++pos_;
    *out = Value::Array();
    SkipSpace();
    if (pos_ < s_.size() && s_[pos_] == ']') {
      ++pos_;
      return true;
    }
    while (true) {
      Value element;
      if (!ParseValue(&element, depth)) return false;
      out->Append(std::move(element));
      SkipSpace();
      if (pos_ >= s_.size()) return FailB("unterminated array, expected ',' or ']'");
      if (s_[pos_] == ',') {
        ++pos_;
        continue;
      }
      if (s_[pos_] == ']') {
        ++pos_;
        return true;
      }
      return FailB("expected ',' or ']' in an array");
    }
  }

  bool ParseObject(Value* out, int depth) {
    ++pos_;
    *out = Value::Object();
    SkipSpace();
    if (pos_ < s_.size() && s_[pos_] == '}') {
      ++pos_;
      return true;
    }
    while (true) {
      SkipSpace();
      if (out->object().size() >= limits_.max_object_members) {
        error_ = LimitExceeded("byte " + std::to_string(pos_) + ": object with more than " +
                               std::to_string(limits_.max_object_members) + " members");
        return false;
      }
      if (pos_ >= s_.size() || s_[pos_] != '"') return FailB("expected a string key in an object");
      const size_t key_pos = pos_;
      std::string key;
      if (!ParseString(&key)) return false;
      if (out->Find(key) != nullptr) {
        pos_ = key_pos;
        return FailB("duplicate key \"" + key + "\"");
      }
      SkipSpace();
      if (pos_ >= s_.size() || s_[pos_] != ':') return FailB("expected ':' after an object key");
      ++pos_;
      Value member;
      if (!ParseValue(&member, depth)) return false;
      out->Set(std::move(key), std::move(member));
      SkipSpace();
      if (pos_ >= s_.size()) return FailB("unterminated object, expected ',' or '}'");
      if (s_[pos_] == ',') {
        ++pos_;
        continue;
      }
      if (s_[pos_] == '}') {
        ++pos_;
        return true;
      }
      return FailB("expected ',' or '}' in an object");
    }
  }

  std::string_view s_;
  ParseLimits limits_;
  size_t pos_ = 0;
  size_t values_ = 0;
  Status error_;
};

void WriteString(const std::string& s, std::string* out) {
  out->push_back('"');
  for (const char c : s) {
    switch (c) {
      case '"': *out += "\\\""; break;
      case '\\': *out += "\\\\"; break;
      case '\n': *out += "\\n"; break;
      case '\r': *out += "\\r"; break;
      case '\t': *out += "\\t"; break;
      case '\b': *out += "\\b"; break;
      case '\f': *out += "\\f"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof(buf), "\\u%04x", static_cast<unsigned>(c));
          *out += buf;
        } else {
          out->push_back(c);
        }
    }
  }
  out->push_back('"');
}

void WriteNumber(double n, std::string* out) {
  if (!std::isfinite(n)) {
    *out += "null";
    return;
  }
  char buf[40];
  if (n == std::floor(n) && std::fabs(n) < 9007199254740992.0) {
    std::snprintf(buf, sizeof(buf), "%.0f", n);
    if (n == 0 && std::signbit(n)) std::snprintf(buf, sizeof(buf), "0");
  } else {
    // Shortest of %.15g..%.17g that reads back exactly.
    for (int precision = 15; precision <= 17; ++precision) {
      std::snprintf(buf, sizeof(buf), "%.*g", precision, n);
      if (std::strtod(buf, nullptr) == n) break;
    }
  }
  *out += buf;
}

void Write(const Value& v, int indent, int level, std::string* out) {
  auto newline = [&](int lvl) {
    if (indent <= 0) return;
    out->push_back('\n');
    out->append(static_cast<size_t>(indent) * lvl, ' ');
  };
  switch (v.type()) {
    case Type::kNull: *out += "null"; break;
    case Type::kBool: *out += v.bool_value() ? "true" : "false"; break;
    case Type::kNumber: WriteNumber(v.number_value(), out); break;
    case Type::kString: WriteString(v.string_value(), out); break;
    case Type::kArray: {
      out->push_back('[');
      bool first = true;
      for (const Value& e : v.array()) {
        if (!first) out->push_back(',');
        first = false;
        newline(level + 1);
        Write(e, indent, level + 1, out);
      }
      if (!v.array().empty()) newline(level);
      out->push_back(']');
      break;
    }
    case Type::kObject: {
      out->push_back('{');
      bool first = true;
      for (const auto& [key, member] : v.object()) {
        if (!first) out->push_back(',');
        first = false;
        newline(level + 1);
        WriteString(key, out);
        *out += indent > 0 ? ": " : ":";
        Write(member, indent, level + 1, out);
      }
      if (!v.object().empty()) newline(level);
      out->push_back('}');
      break;
    }
  }
}

}  // namespace

StatusOr<Value> Parse(std::string_view text, const ParseLimits& limits) {
  return Parser(text, limits).Run();
}

std::string Serialize(const Value& value, int indent) {
  std::string out;
  Write(value, indent, 0, &out);
  return out;
}

}  // namespace casual3d::json
