// Reading a user's input file (model, modal data, STATE.json) before any
// parser sees it, so that every parser gets text it can handle: a regular,
// readable file no larger than a limit; valid UTF-8 without control
// characters (YAML and JSON allow only tab, line feed and carriage return);
// line breaks normalized to LF (CRLF and CR-only files read like LF files,
// with the same line numbers); brackets nested no deeper than a limit (deep
// nesting would exhaust a recursive parser's stack). Every refusal names the
// file and, where it has one, the line.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "model/diagnostics.hpp"

namespace kanegen {

/// Limits of the inputs (docs/limits.md).
/// yaml-cpp holds about 0.6 kB per number it reads: these two bound the
/// memory of a load to about 0.5 GB and 2 GB (docs/limits.md).
inline constexpr std::size_t kMaxModelFileBytes = 4u << 20;   ///< a model file
inline constexpr std::size_t kMaxModalFileBytes = 16u << 20;  ///< a modal data file
inline constexpr std::size_t kMaxStateFileBytes = 1u << 20;   ///< a STATE.json
inline constexpr int kMaxNestingDepth = 32;                   ///< brackets [ { nested

/// The normalized text of `path`, or nullopt with the faults appended to `diags`.
std::optional<std::string> read_input_text(const std::string& path, std::size_t max_bytes,
                                           std::vector<Diagnostic>& diags);

/// The first fault of `text` as read from `path` (UTF-8, control characters,
/// nesting), or nullopt; `text` must already have LF line breaks.
std::optional<Diagnostic> check_input_text(const std::string& text, const std::string& path);

}  // namespace kanegen
