#include "model/input_text.hpp"

#include <fmt/format.h>
#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

namespace kanegen {

namespace {

/// Length of the UTF-8 sequence starting at s[i] (1..4), or 0 if invalid.
int utf8_length(const std::string& s, std::size_t i) {
  const auto c = static_cast<unsigned char>(s[i]);
  int n = 0;
  unsigned min = 0;
  if (c < 0x80) return 1;
  if ((c & 0xE0) == 0xC0) n = 2, min = 0x80;
  else if ((c & 0xF0) == 0xE0) n = 3, min = 0x800;
  else if ((c & 0xF8) == 0xF0) n = 4, min = 0x10000;
  else return 0;
  if (i + n > s.size()) return 0;
  unsigned cp = c & (0xFF >> (n + 1));
  for (int k = 1; k < n; ++k) {
    const auto b = static_cast<unsigned char>(s[i + k]);
    if ((b & 0xC0) != 0x80) return 0;
    cp = (cp << 6) | (b & 0x3F);
  }
  if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;  // overlong, out of range, surrogate
  return n;
}

}  // namespace

std::optional<Diagnostic> check_input_text(const std::string& text, const std::string& path) {
  int line = 1, depth = 0;
  std::size_t line_start = 0;  // offset of the current line
  auto column = [&](std::size_t i) { return fmt::format("column {}", i - line_start + 1); };
  char quote = 0;  // inside a quoted scalar/string: its quote character
  bool comment = false;
  for (std::size_t i = 0; i < text.size();) {
    const char c = text[i];
    const auto uc = static_cast<unsigned char>(c);
    const int len = utf8_length(text, i);
    if (len == 0)
      return Diagnostic{path, line, column(i),
                        fmt::format("invalid UTF-8 (byte 0x{:02x}); expected a UTF-8 text file", static_cast<unsigned>(uc))};
    if (len == 1 && ((uc < 0x20 && c != '\t' && c != '\n') || uc == 0x7F))
      return Diagnostic{path, line, column(i),
                        fmt::format("control character 0x{:02x}; expected printable text (tab and line breaks only)",
                                    static_cast<unsigned>(uc))};
    if (c == '\n') {
      ++line;
      line_start = i + 1;
      comment = false;
      if (quote == '\'' || quote == '"') {
        // a multi-line quoted scalar continues; brackets inside do not nest
      }
    } else if (!comment) {
      if (quote) {
        if (c == '\\' && quote == '"' && i + 1 < text.size()) {
          i += 2;
          continue;
        }
        if (c == quote) quote = 0;
      } else if (c == '"' || c == '\'') {
        // a quote opens a string only at the start of a scalar (not in "it's")
        const char prev = i > 0 ? text[i - 1] : ' ';
        if (c == '"' || prev == ' ' || prev == '[' || prev == '{' || prev == ',' || prev == ':' || prev == '\n' ||
            prev == '\t' || prev == '-')
          quote = c;
      } else if (c == '#' && (i == 0 || text[i - 1] == ' ' || text[i - 1] == '\t' || text[i - 1] == '\n')) {
        comment = true;
      } else if (c == '[' || c == '{') {
        if (++depth > kMaxNestingDepth)
          return Diagnostic{path, line, column(i),
                            fmt::format("brackets nested deeper than {} levels; expected a flatter document",
                                        kMaxNestingDepth)};
      } else if ((c == ']' || c == '}') && depth > 0) {
        --depth;
      }
    }
    i += static_cast<std::size_t>(len);
  }
  return std::nullopt;
}

std::optional<std::string> read_input_text(const std::string& path, std::size_t max_bytes,
                                           std::vector<Diagnostic>& diags) {
  struct stat st{};
  if (stat(path.c_str(), &st) != 0) {
    diags.push_back(Diagnostic{path, 0, "", errno == ENOENT ? "cannot open file (no such file)"
                                                            : fmt::format("cannot open file ({})", std::strerror(errno))});
    return std::nullopt;
  }
  if (!S_ISREG(st.st_mode)) {
    diags.push_back(Diagnostic{path, 0, "", "not a regular file; expected a text file"});
    return std::nullopt;
  }
  if (static_cast<std::size_t>(st.st_size) > max_bytes) {
    diags.push_back(Diagnostic{path, 0, "",
                               fmt::format("file of {} bytes is larger than the limit of {} bytes (docs/limits.md)",
                                           st.st_size, max_bytes)});
    return std::nullopt;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    diags.push_back(Diagnostic{path, 0, "", "cannot open file; expected a readable file"});
    return std::nullopt;
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  std::string raw = ss.str();
  if (raw.size() > max_bytes) {  // grew since stat
    diags.push_back(Diagnostic{path, 0, "", fmt::format("file larger than the limit of {} bytes", max_bytes)});
    return std::nullopt;
  }
  // A UTF-8 byte order mark is allowed and dropped.
  if (raw.compare(0, 3, "\xEF\xBB\xBF") == 0) raw.erase(0, 3);
  // CRLF and CR-only line breaks read as LF.
  std::string text;
  text.reserve(raw.size());
  for (std::size_t i = 0; i < raw.size(); ++i) {
    if (raw[i] == '\r') {
      text += '\n';
      if (i + 1 < raw.size() && raw[i + 1] == '\n') ++i;
    } else {
      text += raw[i];
    }
  }
  if (auto d = check_input_text(text, path)) {
    diags.push_back(*d);
    return std::nullopt;
  }
  return text;
}

}  // namespace kanegen
