#include "model/diagnostics.hpp"

#include <fmt/format.h>

namespace kanegen {

namespace {

/// User text echoed in a message stays on one line: control characters are
/// written as \xNN (and, in a field, ':' as well, so "file:line: field:"
/// parses unambiguously).
std::string printable(const std::string& s, bool field) {
  std::string r;
  for (char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7F || (field && c == ':'))
      r += fmt::format("\\x{:02x}", static_cast<unsigned>(u));
    else
      r += c;
  }
  return r;
}

}  // namespace

std::string Diagnostic::str() const {
  std::string s = printable(file, false);
  if (line > 0) s += fmt::format(":{}", line);
  s += ": ";
  if (!field.empty()) s += printable(field, true) + ": ";
  s += printable(message, false);
  return s;
}

static std::string join(const std::vector<Diagnostic>& ds) {
  std::string s;
  for (const auto& d : ds) {
    if (!s.empty()) s += '\n';
    s += d.str();
  }
  return s;
}

InputError::InputError(std::vector<Diagnostic> diagnostics)
    : std::runtime_error(join(diagnostics)), diagnostics_(std::move(diagnostics)) {}

InputError::InputError(Diagnostic diagnostic) : InputError(std::vector<Diagnostic>{std::move(diagnostic)}) {}

}  // namespace kanegen
