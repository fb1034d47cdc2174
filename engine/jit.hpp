// Just-in-time path of `--engine generated`: generate a model's code (header,
// C entry, manifest: codegen/assembler.hpp), compile it with the system C++
// compiler into a shared library, cache it (jit_cache.hpp) and load it.
//
// The engine library does not link the generator: whoever asks for a JIT
// engine passes a CodeGenerator (the kanegen CLI passes codegen's), whose
// hash is part of the cache key, so a changed generator never reuses a
// library written by an older one.
#pragma once

#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/generated_engine.hpp"
#include "model/model.hpp"

namespace kanegen {

/// The three files of one model's generated code; `entry` #includes "model.hpp".
struct GeneratedSources {
  std::string header, entry, manifest;
};

struct CodeGenerator {
  std::function<GeneratedSources(const Model&)> generate;
  std::string hash;  ///< identifies the generator (its sources and templates)
  /// The model's code with u-dot as compact code, which the JIT races against a straight-line u-dot
  /// (udot_candidates.hpp); empty: none.
  std::function<GeneratedSources(const Model&)> generate_compact_udot;
  /// The model's code with u-dot as straight-line code, which the JIT races against a compact u-dot of
  /// at most 6,000 operations; empty: none.
  std::function<GeneratedSources(const Model&)> generate_straight_udot;
};

struct JitOptions {
  std::string cache_dir;    ///< empty: default_cache_dir()
  std::string compiler;     ///< empty: $CXX, else "c++" (may hold several words, e.g. "ccache g++")
  std::string flags;        ///< empty: default_jit_flags()
  std::string include_dir;  ///< where engine/generated_api.h is; empty: resources.hpp's include_dir()
  bool verbose = false;     ///< also print the compile commands
  /// Compile the dual-number derivatives (jacobian, input_jacobian,
  /// output_jacobian): the larger part of a first build. Commands that need
  /// none of them (eval, an explicit simulate) build without them when no
  /// full library is cached yet (cached separately).
  bool derivatives = true;
  /// For a command that evaluates a few times (eval): every part at -O0 and
  /// for the baseline ISA only (no second copy for AVX2), the quickest build;
  /// cached separately, and any optimized library already cached is used instead.
  /// $KANEGEN_JIT_QUICK=1 makes every build of the process quick (a test suite, a
  /// notebook: where the compile costs more than the run).
  bool quick = false;
  bool quiet = false;       ///< say nothing on stderr (by default a compile and a cache hit are one line each)
  /// Compile only these functions of the table besides the four every engine
  /// needs (qdot, mass_matrix, forcing, udot); empty: all of them. E.g. {} vs
  /// {"reactions"}: a build without the Jacobian and the invariants compiles faster.
  std::vector<std::string> only;
  bool only_set = false;    ///< whether `only` restricts the build (an empty list then means the four alone)
  /// Compile for this machine's CPU (-march=native on every part): the
  /// generated code runs 1.2-2x faster (FMA, wider registers), and only on
  /// CPUs with the same instruction sets. Opt-in; part of the cache key.
  bool native = false;
  /// Compile the u-dot family also for AVX2 (x86-64-v3), picked at load time
  /// on a CPU that has it (KANEGEN_DISPATCH, model.hpp.in). false: the
  /// baseline x86-64 code only (what a flight build or a peer's harness gets).
  bool dispatch = true;
  /// Keep the model's non-zero joint springs, dampers and modal damping ratios
  /// as inputs of the code (implicit_parameters(), model/parameters.hpp), so
  /// that editing one in the model file reuses the cached library.
  bool implicit_parameters = true;
};

/// $KANEGEN_CACHE_DIR, else $XDG_CACHE_HOME/kanegen, else ~/.cache/kanegen.
std::string default_cache_dir();
/// "-O2 -std=c++20 -fPIC -shared"
std::string default_jit_flags();

/// The whitespace-separated words of a compiler or flags string ("ccache g++" -> {"ccache", "g++"}).
std::vector<std::string> split_words(const std::string& s);
/// JitOptions with every empty field replaced by its default (and quick set by $KANEGEN_JIT_QUICK=1).
JitOptions resolved(const JitOptions& opts);

/// A compile of generated code failed. The CLI maps it to exit status 2.
class JitError : public std::runtime_error {
 public:
  JitError(const std::string& what, std::string command, std::string kept_dir)
      : std::runtime_error(what), command(std::move(command)), kept_dir(std::move(kept_dir)) {}
  std::string command;   ///< the compiler command line, shell-quoted
  std::string kept_dir;  ///< where the sources and compiler.log were kept (may be empty)
};

/// The cache key (16 hex digits) and library path of a model's code.
std::string jit_cache_key(const Model& model, const std::string& generator_hash, const JitOptions& opts);
std::string jit_library_path(const Model& model, const std::string& generator_hash, const JitOptions& opts);

/// Lower level: makes sure `so_path` holds a verified build of `sources`
/// (compiling them if it is missing or damaged), then loads it for `model`.
/// Throws JitError when the compiler fails, std::runtime_error when loading
/// or the checks of GeneratedEngine fail.
std::unique_ptr<GeneratedEngine> compile_and_load(const Model& model, const GeneratedSources& sources,
                                                  const std::string& so_path, const JitOptions& opts = {});

/// Whether jit_load would find a library of the model in the cache (one that
/// does at least as much as `opts` asks), i.e. load it without compiling.
bool jit_cached(const Model& model, const CodeGenerator& generator, const JitOptions& opts = {});

/// The generated engine of `model`: from the cache, else generated, compiled and cached.
std::unique_ptr<GeneratedEngine> jit_load(const Model& model, const CodeGenerator& generator,
                                          const JitOptions& opts = {});

}  // namespace kanegen
