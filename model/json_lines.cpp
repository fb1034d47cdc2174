#include "model/json_lines.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <limits>
#include <tuple>

#include "model/diagnostics.hpp"

namespace kanegen {

const char* JsonValue::kind_name() const {
  switch (kind) {
    case Kind::object: return "an object";
    case Kind::array: return "an array";
    case Kind::string: return "a string";
    case Kind::number: return "a number";
    case Kind::boolean: return "a boolean";
    case Kind::null: return "null";
  }
  return "?";
}

namespace {

class Parser {
 public:
  Parser(const std::string& text, const std::string& path) : s_(text), path_(path) {}

  JsonValue document() {
    JsonValue v = value();
    skip_ws();
    if (i_ != s_.size()) fail("content after the JSON value; expected the end of the file");
    return v;
  }

 private:
  [[noreturn]] void fail(const std::string& what) {
    throw InputError(Diagnostic{path_, line_, fmt::format("column {}", column()), "malformed JSON: " + what});
  }
  /// 1-based column (in bytes) of the current position.
  std::size_t column() const {
    const std::size_t at = std::min(i_, s_.size());
    const std::size_t nl = at == 0 ? std::string::npos : s_.rfind('\n', at - 1);
    return nl == std::string::npos ? at + 1 : at - nl;
  }
  void skip_ws() {
    while (i_ < s_.size()) {
      const char c = s_[i_];
      if (c == '\n') ++line_;
      else if (c != ' ' && c != '\t' && c != '\r') break;
      ++i_;
    }
  }
  char peek() {
    skip_ws();
    return i_ < s_.size() ? s_[i_] : '\0';
  }
  void expect(char c, const char* what) {
    if (peek() != c) fail(fmt::format("expected {}", what));
    ++i_;
  }

  JsonValue value() {
    const char c = peek();
    JsonValue v;
    v.line = line_;
    if (c == '{') {
      v.kind = JsonValue::Kind::object;
      ++i_;
      if (peek() == '}') {
        ++i_;
        return v;
      }
      for (;;) {
        if (peek() != '"') fail("expected a key in double quotes");
        JsonValue::Member m;
        m.key_line = line_;
        m.key = string_literal();
        expect(':', "':' after the key");
        m.value = value();
        v.members.push_back(std::move(m));
        const char d = peek();
        if (d == ',') {
          ++i_;
          continue;
        }
        if (d == '}') {
          ++i_;
          return v;
        }
        fail("expected ',' or '}' in an object");
      }
    }
    if (c == '[') {
      v.kind = JsonValue::Kind::array;
      ++i_;
      if (peek() == ']') {
        ++i_;
        return v;
      }
      for (;;) {
        v.items.push_back(value());
        const char d = peek();
        if (d == ',') {
          ++i_;
          continue;
        }
        if (d == ']') {
          ++i_;
          return v;
        }
        fail("expected ',' or ']' in an array");
      }
    }
    if (c == '"') {
      v.kind = JsonValue::Kind::string;
      v.text = string_literal();
      return v;
    }
    if (c == '-' || (c >= '0' && c <= '9')) return number(v);
    for (const auto& [word, kind, b] : {std::tuple{"true", JsonValue::Kind::boolean, true},
                                        std::tuple{"false", JsonValue::Kind::boolean, false},
                                        std::tuple{"null", JsonValue::Kind::null, false}}) {
      const std::string w = word;
      if (s_.compare(i_, w.size(), w) == 0) {
        i_ += w.size();
        v.kind = kind;
        v.boolean = b;
        return v;
      }
    }
    if (i_ >= s_.size()) fail("unexpected end of the file; expected a value");
    fail(fmt::format("unexpected '{}'; expected a value (object, array, string, number, true, false, null)",
                     std::string(1, c)));
  }

  JsonValue number(JsonValue& v) {
    const std::size_t start = i_;
    auto digits = [&] {
      const std::size_t b = i_;
      while (i_ < s_.size() && s_[i_] >= '0' && s_[i_] <= '9') ++i_;
      return i_ - b;
    };
    if (s_[i_] == '-') ++i_;
    if (i_ < s_.size() && s_[i_] == '0') {
      ++i_;
      if (i_ < s_.size() && s_[i_] >= '0' && s_[i_] <= '9') fail("a number with a leading zero; expected JSON numbers");
    } else if (digits() == 0) {
      fail("expected digits in a number");
    }
    if (i_ < s_.size() && s_[i_] == '.') {
      ++i_;
      if (digits() == 0) fail("expected digits after the decimal point");
    }
    if (i_ < s_.size() && (s_[i_] == 'e' || s_[i_] == 'E')) {
      ++i_;
      if (i_ < s_.size() && (s_[i_] == '+' || s_[i_] == '-')) ++i_;
      if (digits() == 0) fail("expected digits in the exponent");
    }
    v.kind = JsonValue::Kind::number;
    v.text = s_.substr(start, i_ - start);
    const auto r = std::from_chars(v.text.data(), v.text.data() + v.text.size(), v.number);
    if (r.ec == std::errc::result_out_of_range) {
      // huge magnitudes become inf (refused by the caller); tiny ones underflow to 0
      const bool tiny = v.text.find("e-") != std::string::npos || v.text.find("E-") != std::string::npos;
      const bool neg = v.text[0] == '-';
      v.number = tiny ? (neg ? -0.0 : 0.0) : (neg ? -1 : 1) * std::numeric_limits<double>::infinity();
    }
    return v;
  }

  std::string string_literal() {
    ++i_;  // opening quote
    std::string out;
    while (i_ < s_.size() && s_[i_] != '"') {
      const char c = s_[i_];
      if (c == '\n' || static_cast<unsigned char>(c) < 0x20) fail("a line break or control character inside a string");
      if (c != '\\') {
        out += c;
        ++i_;
        continue;
      }
      if (++i_ >= s_.size()) break;
      const char e = s_[i_++];
      switch (e) {
        case '"': out += '"'; break;
        case '\\': out += '\\'; break;
        case '/': out += '/'; break;
        case 'b': out += '\b'; break;
        case 'f': out += '\f'; break;
        case 'n': out += '\n'; break;
        case 'r': out += '\r'; break;
        case 't': out += '\t'; break;
        case 'u': {
          if (i_ + 4 > s_.size()) fail("a truncated \\u escape");
          unsigned cp = 0;
          const auto r = std::from_chars(s_.data() + i_, s_.data() + i_ + 4, cp, 16);
          if (r.ptr != s_.data() + i_ + 4) fail("a malformed \\u escape; expected four hex digits");
          i_ += 4;
          // UTF-8 encode (surrogate pairs are kept as two code points; names are ASCII anyway)
          if (cp < 0x80) out += static_cast<char>(cp);
          else if (cp < 0x800) out += static_cast<char>(0xC0 | (cp >> 6)), out += static_cast<char>(0x80 | (cp & 0x3F));
          else
            out += static_cast<char>(0xE0 | (cp >> 12)), out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F)),
                out += static_cast<char>(0x80 | (cp & 0x3F));
          break;
        }
        default: fail(fmt::format("unknown escape '\\{}' in a string", std::string(1, e)));
      }
    }
    if (i_ >= s_.size()) fail("unterminated string; expected a closing '\"'");
    ++i_;
    return out;
  }

  const std::string& s_;
  const std::string& path_;
  std::size_t i_ = 0;
  int line_ = 1;
};

}  // namespace

JsonValue parse_json_with_lines(const std::string& text, const std::string& path) {
  return Parser(text, path).document();
}

}  // namespace kanegen
