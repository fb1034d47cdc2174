// Internal helpers shared by the YAML readers (model_loader.cpp,
// modal_data.cpp): typed access to yaml-cpp nodes that records a Diagnostic
// (file, line, field, message) for every fault instead of throwing.
// Not part of the public API.
#pragma once

#include <fmt/format.h>
#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

#include "model/diagnostics.hpp"
#include "model/input_text.hpp"

namespace kanegen::yamlcheck {

/// 1-based line of a node, 0 if the node has no mark (e.g. undefined).
inline int line_of(const YAML::Node& n) {
  if (!n.IsDefined()) return 0;
  const YAML::Mark m = n.Mark();
  return m.is_null() ? 0 : m.line + 1;
}

/// Line of `key` in mapping `map` (where a block value's field is written);
/// the value's own line, else 0, if the key is not found.
inline int key_line(const YAML::Node& map, const std::string& key) {
  if (map.IsMap())
    for (auto it = map.begin(); it != map.end(); ++it)
      if (it->first.IsScalar() && it->first.Scalar() == key) {
        const int l = line_of(it->first);
        return l ? l : line_of(it->second);
      }
  return 0;
}

inline std::string describe(const YAML::Node& n) {
  if (!n.IsDefined() || n.IsNull()) return "nothing";
  if (n.IsScalar()) return fmt::format("'{}'", n.Scalar());
  if (n.IsSequence()) return fmt::format("a list of {}", n.size());
  if (n.IsMap()) return "a mapping";
  return "?";
}

inline int edit_distance(const std::string& a, const std::string& b) {
  std::vector<int> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = static_cast<int>(j);
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = static_cast<int>(i);
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const int sub = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, sub});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

/// "; did you mean 'x'?" when a candidate is within edit distance 2, else "".
inline std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates) {
  int best = 3;
  std::string hit;
  for (const auto& c : candidates) {
    const int d = edit_distance(word, c);
    if (d < best) {
      best = d;
      hit = c;
    }
  }
  return hit.empty() ? std::string() : fmt::format("; did you mean '{}'?", hit);
}

/// A name of a port, sensor or event: [a-z][a-z0-9_]*, at most 64 characters.
inline bool valid_identifier(const std::string& s) {
  return !s.empty() && s.size() <= 64 && s[0] >= 'a' && s[0] <= 'z' &&
         std::all_of(s.begin(), s.end(), [](char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_'; });
}

inline std::string join(const std::vector<std::string>& v, const char* sep = ", ") {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? sep : "") + v[i];
  return s;
}

inline std::string num(double x) { return fmt::format("{:.9g}", x); }

/// Collects diagnostics for one file.
class Checker {
 public:
  Checker(std::string file, std::vector<Diagnostic>& diags) : file_(std::move(file)), diags_(diags) {}
  const std::string& file() const { return file_; }
  std::vector<Diagnostic>& diags() { return diags_; }

  void error(int line, const std::string& field, const std::string& message) {
    diags_.push_back(Diagnostic{file_, line, field, message});
  }
  /// Error at node n, or at `fallback` line when n has no position.
  void error(const YAML::Node& n, int fallback, const std::string& field, const std::string& message) {
    const int l = line_of(n);
    error(l > 0 ? l : fallback, field, message);
  }

  /// True if n is a mapping; otherwise records a fault.
  bool expect_map(const YAML::Node& n, int fallback, const std::string& field) {
    if (n.IsMap()) return true;
    error(n, fallback, field, fmt::format("got {}; expected a mapping (key: value)", describe(n)));
    return false;
  }
  bool expect_seq(const YAML::Node& n, int fallback, const std::string& field) {
    if (n.IsSequence()) return true;
    error(n, fallback, field, fmt::format("got {}; expected a list", describe(n)));
    return false;
  }

  /// Every key of map n must be one of `allowed` (and appear once).
  void check_keys(const YAML::Node& n, const std::string& field, const std::vector<std::string>& allowed) {
    if (!n.IsMap()) return;
    std::vector<std::string> seen;
    for (auto it = n.begin(); it != n.end(); ++it) {
      const YAML::Node& k = it->first;
      if (!k.IsScalar()) {
        error(k, line_of(n), field.empty() ? "(document)" : field, "a key must be a plain name");
        continue;
      }
      const std::string key = k.Scalar();
      const std::string f = field.empty() ? (key.empty() ? std::string("''") : key) : field + "." + key;
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
        std::string msg = fmt::format("unknown key '{}'", key);
        const std::string hint = did_you_mean(key, allowed);
        msg += hint.empty() ? fmt::format("; expected one of: {}", join(allowed)) : hint;
        error(k, line_of(n), f, msg);
      } else if (std::find(seen.begin(), seen.end(), key) != seen.end()) {
        error(k, line_of(n), f, fmt::format("key '{}' given twice; expected it once", key));
      }
      seen.push_back(key);
    }
  }

  std::optional<double> number(const YAML::Node& n, int fallback, const std::string& field) {
    if (!n.IsScalar()) {
      error(n, fallback, field, fmt::format("got {}; expected a number", describe(n)));
      return std::nullopt;
    }
    double x = 0;
    try {
      x = n.as<double>();
    } catch (const YAML::Exception&) {
      // yaml-cpp refuses a decimal that overflows double as "not a number";
      // say which it is
      char* end = nullptr;
      const std::string& text = n.Scalar();
      const double y = std::strtod(text.c_str(), &end);
      const bool overflows = end && end != text.c_str() && *end == '\0' && std::isinf(y) &&
                             text.find_first_of("iI") == std::string::npos;
      error(n, fallback, field,
            overflows ? fmt::format("'{}' is beyond double precision (|x| > 1.8e308); expected a finite number", text)
                      : fmt::format("'{}' is not a number; expected a number", text));
      return std::nullopt;
    }
    if (!std::isfinite(x)) {
      error(n, fallback, field, fmt::format("'{}' is not finite; expected a finite number", n.Scalar()));
      return std::nullopt;
    }
    return x;
  }

  std::optional<double> nonneg(const YAML::Node& n, int fallback, const std::string& field, const char* what) {
    auto x = number(n, fallback, field);
    if (x && *x < 0) {
      error(n, fallback, field, fmt::format("{} is negative; expected {} >= 0", num(*x), what));
      return std::nullopt;
    }
    return x;
  }

  std::optional<double> positive(const YAML::Node& n, int fallback, const std::string& field, const char* what) {
    auto x = number(n, fallback, field);
    if (x && !(*x > 0)) {
      error(n, fallback, field, fmt::format("{} is not positive; expected {} > 0", num(*x), what));
      return std::nullopt;
    }
    return x;
  }

  /// A decimal integer (one rule everywhere: "010" is ten, as in YAML 1.2;
  /// hex, octal and other forms are refused).
  std::optional<long long> integer(const YAML::Node& n, int fallback, const std::string& field) {
    if (!n.IsScalar()) {
      error(n, fallback, field, fmt::format("got {}; expected an integer", describe(n)));
      return std::nullopt;
    }
    const std::string& v = n.Scalar();
    long long x = 0;
    const char* b = v.data() + (v.size() > 1 && v[0] == '+' ? 1 : 0);
    const auto r = std::from_chars(b, v.data() + v.size(), x, 10);
    if (v.empty() || r.ptr != v.data() + v.size() || r.ec != std::errc()) {
      error(n, fallback, field,
            fmt::format("'{}' is not an integer{}; expected a decimal integer", v,
                        r.ec == std::errc::result_out_of_range ? " in range" : ""));
      return std::nullopt;
    }
    return x;
  }

  std::optional<bool> boolean(const YAML::Node& n, int fallback, const std::string& field) {
    if (n.IsScalar()) {
      const std::string& v = n.Scalar();
      if (v == "true" || v == "True" || v == "TRUE") return true;
      if (v == "false" || v == "False" || v == "FALSE") return false;
    }
    error(n, fallback, field, fmt::format("got {}; expected true or false", describe(n)));
    return std::nullopt;
  }

  std::optional<std::string> string(const YAML::Node& n, int fallback, const std::string& field) {
    if (!n.IsScalar()) {
      error(n, fallback, field, fmt::format("got {}; expected a string", describe(n)));
      return std::nullopt;
    }
    return n.Scalar();
  }

  /// A list of exactly `size` numbers.
  std::optional<Eigen::VectorXd> vector(const YAML::Node& n, int fallback, const std::string& field, int size) {
    if (!n.IsSequence() || static_cast<int>(n.size()) != size) {
      error(n, fallback, field, fmt::format("got {}; expected a list of {} numbers", describe(n), size));
      return std::nullopt;
    }
    Eigen::VectorXd v(size);
    bool ok = true;
    for (int i = 0; i < size; ++i) {
      auto x = number(n[i], line_of(n), fmt::format("{}[{}]", field, i));
      if (x)
        v(i) = *x;
      else
        ok = false;
    }
    if (!ok) return std::nullopt;
    return v;
  }

  std::optional<Eigen::Vector3d> vec3(const YAML::Node& n, int fallback, const std::string& field) {
    auto v = vector(n, fallback, field, 3);
    if (!v) return std::nullopt;
    return Eigen::Vector3d(*v);
  }

  /// A 3x3 matrix as a list of three rows of three numbers.
  std::optional<Eigen::Matrix3d> mat3(const YAML::Node& n, int fallback, const std::string& field) {
    const char* expected = "expected a 3x3 matrix as a list of 3 rows of 3 numbers";
    if (!n.IsSequence() || n.size() != 3) {
      error(n, fallback, field, fmt::format("got {}; {}", describe(n), expected));
      return std::nullopt;
    }
    Eigen::Matrix3d M;
    bool ok = true;
    for (int i = 0; i < 3; ++i) {
      auto row = vector(n[i], line_of(n), fmt::format("{}[{}]", field, i), 3);
      if (row)
        M.row(i) = row->transpose();
      else
        ok = false;
    }
    if (!ok) return std::nullopt;
    return M;
  }

  /// A vector whose norm must be within 1e-6 of 1 (then normalized).
  std::optional<Eigen::VectorXd> unit(const YAML::Node& n, int fallback, const std::string& field, int size,
                                      const char* expected) {
    auto v = vector(n, fallback, field, size);
    if (!v) return std::nullopt;
    const double nrm = v->norm();
    if (nrm == 0.0) {
      error(n, fallback, field, fmt::format("zero vector; expected {}", expected));
      return std::nullopt;
    }
    if (std::abs(nrm - 1.0) > 1e-6) {
      std::string unit;  // the normalized vector, to paste
      for (Eigen::Index i = 0; i < v->size(); ++i) unit += (i ? ", " : "") + fmt::format("{:.17g}", (*v)(i) / nrm);
      error(n, fallback, field,
            fmt::format("norm {} is not 1 (to within 1e-6); expected {} (normalized: [{}])", num(nrm), expected, unit));
      return std::nullopt;
    }
    return Eigen::VectorXd(*v / nrm);
  }

  /// Inertia matrix: 6 numbers [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] or a 3x3 list;
  /// symmetric, positive semi-definite, triangle inequalities on the principal
  /// moments (tolerance 1e-9 of the largest entry).
  /// `rigid_body` false (a modal node's lumped rotary inertia, model-format.md): positive semi-definite only,
  /// no triangle inequality (a finite-element lumping may put inertia about one axis only).
  std::optional<Eigen::Matrix3d> inertia(const YAML::Node& n, int fallback, const std::string& field,
                                         bool rigid_body = true) {
    Eigen::Matrix3d I;
    if (n.IsSequence() && n.size() == 6) {
      auto v = vector(n, fallback, field, 6);
      if (!v) return std::nullopt;
      const auto& a = *v;
      I << a(0), a(3), a(4), a(3), a(1), a(5), a(4), a(5), a(2);
    } else if (n.IsSequence() && n.size() == 3 && n[0].IsScalar() && n[1].IsScalar() && n[2].IsScalar()) {
      error(n, fallback, field,
            "got a list of 3 numbers; expected [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] (a diagonal inertia is "
            "[Ixx, Iyy, Izz, 0, 0, 0]) or a 3x3 list");
      return std::nullopt;
    } else if (n.IsSequence() && n.size() == 3) {
      auto M = mat3(n, fallback, field);
      if (!M) return std::nullopt;
      I = *M;
      const double scale = I.cwiseAbs().maxCoeff();
      const double asym = (I - I.transpose()).cwiseAbs().maxCoeff();
      if (asym > 1e-9 * scale) {
        error(n, fallback, field,
              fmt::format("not symmetric (largest |I - I^T| entry {}); expected a symmetric inertia matrix",
                          num(asym)));
        return std::nullopt;
      }
      I = 0.5 * (I + I.transpose());
    } else {
      error(n, fallback, field,
            fmt::format("got {}; expected [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] or a 3x3 list", describe(n)));
      return std::nullopt;
    }
    const double scale = I.cwiseAbs().maxCoeff();
    const double tol = 1e-9 * scale;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(I, Eigen::EigenvaluesOnly);
    const Eigen::Vector3d l = es.eigenvalues();
    const std::string moments = fmt::format("{}, {}, {}", num(l(0)), num(l(1)), num(l(2)));
    if (l.minCoeff() < -tol) {
      error(n, fallback, field,
            fmt::format("not positive semi-definite (principal moments {}); expected principal moments >= 0",
                        moments));
      return std::nullopt;
    }
    for (int i = 0; rigid_body && i < 3; ++i) {
      if (l(i) > l((i + 1) % 3) + l((i + 2) % 3) + tol) {
        error(n, fallback, field,
              fmt::format("principal moments {} violate the triangle inequality; expected each to be at most "
                          "the sum of the other two",
                          moments));
        return std::nullopt;
      }
    }
    return I;
  }

 private:
  std::string file_;
  std::vector<Diagnostic>& diags_;
};

/// Orders diagnostics by file (in order of first appearance), then line.
inline void sort_diagnostics(std::vector<Diagnostic>& ds) {
  std::vector<std::string> files;
  for (const auto& d : ds)
    if (std::find(files.begin(), files.end(), d.file) == files.end()) files.push_back(d.file);
  auto rank = [&](const Diagnostic& d) { return std::find(files.begin(), files.end(), d.file) - files.begin(); };
  std::stable_sort(ds.begin(), ds.end(), [&](const Diagnostic& a, const Diagnostic& b) {
    return rank(a) != rank(b) ? rank(a) < rank(b) : a.line < b.line;
  });
}

/// Line of the first line at column 0 that starts a second document ("---"
/// after content, or content after "..."), or 0.
inline int second_document_line(const std::string& text) {
  bool content = false, ended = false;
  int line = 0;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    const std::string l = text.substr(pos, end - pos);
    ++line;
    const std::size_t first = l.find_first_not_of(" \t");
    const bool blank = first == std::string::npos || l[first] == '#';
    if (l.rfind("---", 0) == 0 && (l.size() == 3 || l[3] == ' ' || l[3] == '\t')) {
      if (content || ended) return line;
      // "--- x": content on the marker's line
      const std::size_t c = l.find_first_not_of(" \t", 3);
      if (c != std::string::npos && l[c] != '#') content = true;
    } else if (l.rfind("...", 0) == 0 && (l.size() == 3 || l[3] == ' ' || l[3] == '\t')) {
      ended = true;
    } else if (!blank && l[0] != '%') {
      if (ended) return line;
      content = true;
    }
    pos = end + 1;
  }
  return 0;
}

/// "column N" of a parser mark, or "(document)" when it has none.
inline std::string mark_column(const YAML::Mark& m) {
  return m.is_null() ? std::string("(document)") : fmt::format("column {}", m.column + 1);
}

/// Parses a YAML file (read and checked by read_input_text: size, UTF-8,
/// control characters, nesting, line breaks); a missing file, a syntax error,
/// or a second document is recorded and an undefined node returned.
inline YAML::Node parse_file(const std::string& path, std::size_t max_bytes, std::vector<Diagnostic>& diags,
                             bool& ok) {
  ok = false;
  const std::optional<std::string> text = read_input_text(path, max_bytes, diags);
  if (!text) return YAML::Node();
  if (const int l = second_document_line(*text)) {
    diags.push_back(Diagnostic{path, l, "(document)",
                               "a second YAML document (after '---' or '...'); expected one document per file"});
    return YAML::Node();
  }
  try {
    std::vector<YAML::Node> docs = YAML::LoadAll(*text);
    if (docs.size() > 1) {
      diags.push_back(Diagnostic{path, 1, "(document)", "more than one YAML document; expected one document per file"});
      return YAML::Node();
    }
    ok = true;
    return docs.empty() ? YAML::Node() : docs[0];
  } catch (const YAML::DeepRecursion& e) {
    diags.push_back(Diagnostic{path, e.mark.is_null() ? 1 : e.mark.line + 1, mark_column(e.mark),
                               "nested too deeply; expected a flatter document"});
  } catch (const YAML::ParserException& e) {
    diags.push_back(Diagnostic{path, e.mark.is_null() ? 1 : e.mark.line + 1, mark_column(e.mark),
                               fmt::format("YAML syntax error: {}", e.msg)});
  } catch (const YAML::Exception& e) {
    diags.push_back(Diagnostic{path, e.mark.is_null() ? 1 : e.mark.line + 1, mark_column(e.mark),
                               fmt::format("cannot read YAML: {}", e.msg)});
  }
  return YAML::Node();
}

}  // namespace kanegen::yamlcheck
