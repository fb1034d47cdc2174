// Just-in-time path of `--engine generated`: generate the model's header,
// compile it with the system C++ compiler into a shared library, cache the
// library by (model hash, generator version, compiler and flags) and load it.
//
// Cache: <cache_dir>/<model_name>-<key>.so, key = 16 hex digits of FNV-1a-64
// over the model hash, KANEGEN_VERSION, the API version, the compiler and the
// flags. A hit is one stat() + dlopen(). A miss builds in a private temp
// directory under the cache dir (<cache_dir>/.tmp-<name>-XXXXXX: model.hpp,
// entry.cpp from templates/entry.cpp.in, compiler.log, lib.so) and rename()s
// the finished library into place, so concurrent processes may both compile
// but only ever load complete files. A failed compile leaves no library; its
// sources and log are moved to <cache_dir>/failed/<model_name>-<key>/.
#pragma once

#include <functional>
#include <memory>
#include <stdexcept>
#include <string>

#include "generated_engine.hpp"
#include "model.hpp"

namespace kanegen {

// The generator (generator/generate.hpp, linked into programs that use
// jit_load()); redeclared here so that the runtime library itself does not
// depend on it: only code calling jit_load() needs it at link time.
namespace gen {
std::string generate_header(const Model& model);
}

struct JitOptions {
  std::string cache_dir;   ///< empty: default_cache_dir()
  std::string compiler;    ///< empty: $CXX, else "c++" (may hold several words, e.g. "ccache g++")
  std::string flags;       ///< empty: default_jit_flags()
  std::string source_dir;  ///< templates/ and runtime/: empty: $KANEGEN_SOURCE_DIR, else the build's source dir
  bool verbose = false;    ///< announce compiles on stderr (also done whenever stderr is a terminal)
};

/// $KANEGEN_CACHE_DIR, else $XDG_CACHE_HOME/kanegen, else ~/.cache/kanegen.
std::string default_cache_dir();
/// "-O2 -std=c++20 -fPIC -shared"
std::string default_jit_flags();

/// JitOptions with every empty field replaced by its default.
JitOptions resolved(const JitOptions& opts);

/// A compile of generated code failed. The CLI maps it to exit status 2.
class JitError : public std::runtime_error {
 public:
  JitError(const std::string& what, std::string command, std::string kept_dir)
      : std::runtime_error(what), command(std::move(command)), kept_dir(std::move(kept_dir)) {}
  std::string command;   ///< the compiler command line, shell-quoted
  std::string kept_dir;  ///< where the sources and compiler.log were kept (may be empty)
};

/// The cache key and library path of a model under `opts`.
std::string jit_cache_key(const Model& model, const JitOptions& opts);
std::string jit_library_path(const Model& model, const JitOptions& opts);

/// Lower level: make sure `so_path` exists (compile `header_path`, whose code
/// is in namespace `namespace_name`, e.g. "kanegen_gen::pendulum", if it does
/// not), then load it and wrap it for `model`. Throws JitError when the
/// compiler fails, std::runtime_error when loading or the checks of
/// GeneratedEngine fail.
std::unique_ptr<GeneratedEngine> compile_and_load(const Model& model, const std::string& header_path,
                                                  const std::string& namespace_name, const std::string& so_path,
                                                  const JitOptions& opts = {});

/// Loads an existing library (no compile) and wraps it for `model`.
std::unique_ptr<GeneratedEngine> load_generated_library(const Model& model, const std::string& so_path);

using HeaderGenerator = std::function<std::string(const Model&)>;

/// jit_load() with the generator given explicitly (tests; programs without the generator).
std::unique_ptr<GeneratedEngine> jit_load_with(const Model& model, const JitOptions& opts,
                                               const HeaderGenerator& generate);

/// The generated engine of `model`: from the cache, else generated, compiled and cached.
inline std::unique_ptr<GeneratedEngine> jit_load(const Model& model, const JitOptions& opts = {}) {
  return jit_load_with(model, opts, &gen::generate_header);
}

}  // namespace kanegen
