// A strict JSON reader that keeps the line of every value and object key and
// the order and repetition of keys (JSON libraries give neither), for
// STATE.json: every fault can then name its line, and a key given twice is
// refused with both lines. The text comes from read_input_text (nesting
// already bounded), so the recursive descent is safe.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace kanegen {

struct JsonMember;

struct JsonValue {
  enum class Kind { object, array, string, number, boolean, null };
  Kind kind = Kind::null;
  int line = 0;
  std::string text;      ///< string: decoded; number: the literal as written
  double number = 0.0;   ///< number: its value (+-inf when out of range)
  bool boolean = false;
  using Member = JsonMember;
  std::vector<JsonMember> members;  ///< object: in file order, repetitions kept
  std::vector<JsonValue> items;  ///< array
  const char* kind_name() const;
};

struct JsonMember {
  std::string key;
  int key_line = 0;
  JsonValue value;
};

/// Parses `text` (strict JSON: RFC 8259); throws InputError with the file,
/// line and what was expected on a syntax error.
JsonValue parse_json_with_lines(const std::string& text, const std::string& path);

}  // namespace kanegen
