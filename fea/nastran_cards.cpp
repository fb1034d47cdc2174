#include "fea/nastran_cards.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <set>

#include "model/diagnostics.hpp"

namespace kanegen::nastran {

namespace {

constexpr int kFieldsPerLine = 8;
constexpr int kMaxIncludeDepth = 32;

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

/// Tabs to the next multiple of 8 columns (fixed-field cards typed with tabs).
std::string expand_tabs(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '\t') {
      do out += ' ';
      while (out.size() % 8 != 0);
    } else {
      out += c;
    }
  }
  return out;
}

/// The columns [from, from + width) of a line, trimmed ("" past its end).
std::string columns(const std::string& line, std::size_t from, std::size_t width) {
  if (from >= line.size()) return "";
  return trim(line.substr(from, width));
}

/// One physical line split into its first field, its data fields and whether it is large-field.
struct Line {
  std::string first;                ///< field 1: the name, a continuation marker or ""
  std::vector<std::string> data;    ///< 8 (small, free) or 4 (large) data fields
  bool large = false;
};

Line split_line(const std::string& raw, const std::string& file, int line_no) {
  Line l;
  if (raw.find(',') != std::string::npos) {  // free field
    std::vector<std::string> tokens;
    std::size_t start = 0;
    for (;;) {
      const auto comma = raw.find(',', start);
      tokens.push_back(trim(raw.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    if (tokens.size() > 10)
      throw InputError(Diagnostic{file, line_no, upper(tokens[0]),
                                  fmt::format("{} fields on one free-field line; expected at most 10 (the name, 8 "
                                              "data fields and a continuation field)",
                                              tokens.size())});
    l.first = tokens[0];
    l.large = !l.first.empty() && (l.first.back() == '*' || l.first.front() == '*');
    const int n = l.large ? 4 : kFieldsPerLine;
    for (int k = 1; k <= n; ++k) l.data.push_back(k < static_cast<int>(tokens.size()) ? tokens[k] : "");
    return l;
  }
  const std::string s = expand_tabs(raw);
  l.first = columns(s, 0, 8);
  l.large = !l.first.empty() && (l.first.back() == '*' || l.first.front() == '*');
  if (l.large) {
    for (int k = 0; k < 4; ++k) l.data.push_back(columns(s, 8 + 16 * k, 16));
  } else {
    for (int k = 0; k < kFieldsPerLine; ++k) l.data.push_back(columns(s, 8 + 8 * k, 8));
  }
  return l;
}

bool is_card_name(const std::string& first) {
  return !first.empty() && std::isalpha(static_cast<unsigned char>(first[0]));
}

class Reader {
 public:
  std::vector<Card> cards;

  void read(const std::string& path, const std::string& from_file, int from_line, int depth, bool whole_file) {
    if (depth > kMaxIncludeDepth)
      throw InputError(Diagnostic{from_file, from_line, "INCLUDE",
                                  fmt::format("'{}': INCLUDE nested deeper than {} files", path, kMaxIncludeDepth)});
    std::error_code ec;
    const std::string canonical = std::filesystem::weakly_canonical(path, ec).string();
    if (open_.count(canonical))
      throw InputError(Diagnostic{from_file, from_line, "INCLUDE", fmt::format("'{}' includes itself", path)});
    std::ifstream in(path, std::ios::binary);
    if (!in)
      throw InputError(Diagnostic{from_file.empty() ? path : from_file, from_line, from_file.empty() ? "" : "INCLUDE",
                                  fmt::format("cannot read '{}'", path)});
    open_.insert(canonical);
    std::vector<std::string> lines;
    for (std::string s; std::getline(in, s);) {
      if (!s.empty() && s.back() == '\r') s.pop_back();
      lines.push_back(s);
    }
    bool in_bulk = whole_file;
    if (!whole_file) {  // a full input file: its bulk section; a file without BEGIN BULK is bulk data throughout
      in_bulk = std::none_of(lines.begin(), lines.end(), [](const std::string& s) {
        return upper(trim(s)).rfind("BEGIN BULK", 0) == 0 || upper(trim(s)).rfind("BEGIN,BULK", 0) == 0;
      });
    }
    for (std::size_t k = 0; k < lines.size(); ++k) {
      const int line_no = static_cast<int>(k) + 1;
      std::string s = lines[k];
      if (const auto dollar = s.find('$'); dollar != std::string::npos) s.erase(dollar);
      const std::string t = upper(trim(s));
      if (t.empty()) continue;
      if (!in_bulk) {
        if (t.rfind("BEGIN BULK", 0) == 0 || t.rfind("BEGIN,BULK", 0) == 0) in_bulk = true;
        continue;
      }
      if (t.rfind("ENDDATA", 0) == 0) {
        ended_ = true;
        break;
      }
      if (t.rfind("INCLUDE", 0) == 0) {
        std::string name = trim(trim(s).substr(7));
        // a quoted name may go on over further lines
        while (!name.empty() && name.front() == '\'' && std::count(name.begin(), name.end(), '\'') < 2 &&
               k + 1 < lines.size())
          name += trim(lines[++k]);
        name.erase(std::remove(name.begin(), name.end(), '\''), name.end());
        name = trim(name);
        if (name.empty()) throw InputError(Diagnostic{path, line_no, "INCLUDE", "no file named; expected INCLUDE 'file'"});
        const std::filesystem::path target = std::filesystem::path(name).is_absolute()
                                                 ? std::filesystem::path(name)
                                                 : std::filesystem::path(path).parent_path() / name;
        read(target.string(), path, line_no, depth + 1, true);
        if (ended_) break;
        continue;
      }
      const Line l = split_line(s, path, line_no);
      const bool continuation = !is_card_name(l.first);
      if (continuation) {
        if (cards.empty() || cards.back().file != path)
          throw InputError(Diagnostic{path, line_no, l.first.empty() ? "(blank field 1)" : l.first,
                                      "a continuation line without a card before it in this file"});
        Card& c = cards.back();
        if (pending_half_ && !l.large) {
          // a large-field card's second half expected; a small-field continuation instead: pad the half line
          c.fields.resize(c.fields.size() + 4);
        }
        c.fields.insert(c.fields.end(), l.data.begin(), l.data.end());
        pending_half_ = l.large ? !pending_half_ : false;
        continue;
      }
      Card c;
      c.name = upper(l.first);
      if (c.name.back() == '*') c.name.pop_back();
      c.fields = l.data;
      c.file = path;
      c.line = line_no;
      pending_half_ = l.large;
      cards.push_back(std::move(c));
    }
    open_.erase(canonical);
  }

 private:
  std::set<std::string> open_;  ///< the files being read (an INCLUDE of one of them is a loop)
  bool ended_ = false;
  bool pending_half_ = false;   ///< the last large-field line left a logical line half full
};

}  // namespace

std::optional<double> parse_real(const std::string& text) {
  std::string s = upper(trim(text));
  if (s.empty()) return std::nullopt;
  std::replace(s.begin(), s.end(), 'D', 'E');
  if (s.find('E') == std::string::npos) {  // 1.5-3 means 1.5E-3: a sign after the first character
    for (std::size_t k = 1; k < s.size(); ++k)
      if ((s[k] == '+' || s[k] == '-') && s[k - 1] != 'E') {
        s.insert(k, "E");
        break;
      }
  }
  const char* begin = s.c_str();
  char* end = nullptr;
  const double v = std::strtod(begin, &end);
  if (end == begin || *end != '\0') return std::nullopt;
  return v;
}

std::string Card::where(int i) const {
  return fmt::format("{} field {} of line {}", name, 2 + i % kFieldsPerLine, 1 + i / kFieldsPerLine);
}

void Card::refuse(int field, const std::string& message) const {
  const std::string id = blank(0) ? name : name + " " + fields[0];
  throw InputError(Diagnostic{file, line, field >= 0 ? fmt::format("{} ({})", id, where(field)) : id, message});
}

int Card::integer(int i, std::optional<int> fallback) const {
  if (blank(i)) {
    if (fallback) return *fallback;
    refuse(i, "blank; expected an integer");
  }
  const auto v = parse_integer(fields[i]);
  if (!v) refuse(i, fmt::format("'{}'; expected an integer", fields[i]));
  return *v;
}

double Card::real(int i, std::optional<double> fallback) const {
  if (blank(i)) {
    if (fallback) return *fallback;
    refuse(i, "blank; expected a real number");
  }
  const auto v = parse_real(fields[i]);
  if (!v || !std::isfinite(*v)) refuse(i, fmt::format("'{}'; expected a real number (1.5, 1.5E-3, 1.5-3)", fields[i]));
  return *v;
}

std::string Card::text(int i) const { return blank(i) ? std::string() : upper(fields[i]); }

std::vector<Card> read_cards(const std::string& path) {
  Reader r;
  r.read(path, "", 0, 0, false);
  return std::move(r.cards);
}

std::optional<int> parse_integer(const std::string& text) {
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (end == text.c_str() || *end != '\0' || errno == ERANGE || v < -2147483647L || v > 2147483647L)
    return std::nullopt;
  return static_cast<int>(v);
}

std::vector<std::string> words(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> w;
  for (std::string x; in >> x;) w.push_back(x);
  return w;
}

}  // namespace kanegen::nastran
