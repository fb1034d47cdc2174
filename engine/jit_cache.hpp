// The JIT's cache of compiled libraries:
//   <dir>/<stem>-<key>.so     the library (stem: the model name, cut to 32
//                             characters: file names stay short whatever the name)
//   <dir>/<stem>-<key>.json   its record: API symbol, size and FNV-1a-64 checksum
// A library is loaded only after its size and checksum match its record, so a
// truncated or overwritten file is rebuilt, never loaded. Builds happen in
// private temporary directories <dir>/.tmp-<pid>-XXXXXX and are published by
// rename(); directories left by a killed process (its pid gone) or older than
// a day are removed at the next build.
#pragma once

#include <functional>
#include <optional>
#include <string>

namespace kanegen::jit_cache {

struct LibraryRecord {
  std::string api_symbol;
  long long size = 0;
  std::string checksum;  ///< fnv1a64 hex of the library's bytes
  /// The compiled Jacobian is fast enough for the implicit integrators (else it serves linearize only).
  bool jacobian_for_integration = true;
  /// The u-dot form the generator chose or was told ("composite", "articulated"; empty in older records).
  std::string udot_form;
  /// A library of u-dot alone built by a second compiler (jit.cpp, "A second compiler for u-dot"): its
  /// compiler, whether it was measured faster than the main library's u-dot, and the two least times (ns).
  std::string compiler;
  bool preferred = false;
  double udot_ns = 0, main_udot_ns = 0;
  std::string main_checksum;  ///< the checksum of the main library it was built and raced beside
};

/// <dir>/<stem>-<key>.json for a library path <dir>/<stem>-<key>.so.
std::string record_path(const std::string& so_path);

/// A file-name stem for a model name: [A-Za-z0-9_-] kept, at most 32 characters.
std::string file_stem(const std::string& model_name);

/// The record of `so_path` if it exists, parses, and the library's size and
/// checksum match it; nullopt otherwise (missing, damaged or stale). `wanted`:
/// nullopt also for a record it refuses, before the library is read and hashed.
std::optional<LibraryRecord> verified_record(const std::string& so_path,
                                             const std::function<bool(const LibraryRecord&)>& wanted = {});

/// The record of a freshly built library file.
LibraryRecord make_record(const std::string& library_file, const std::string& api_symbol);

/// Writes `record` for `so_path` atomically (temporary file + rename).
void write_record(const std::string& so_path, const LibraryRecord& record);

/// Removes temporary build directories of dead processes or older than a day.
void remove_stale_temps(const std::string& dir);

/// Creates a private temporary build directory in `dir`.
std::string make_temp_dir(const std::string& dir);

}  // namespace kanegen::jit_cache
