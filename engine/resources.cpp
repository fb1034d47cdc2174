#include "engine/resources.hpp"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <stdexcept>

namespace kanegen {

namespace fs = std::filesystem;

namespace {

/// Directory of the file (program or shared library) this code was loaded from.
fs::path own_directory() {
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&own_directory), &info) && info.dli_fname) {
    std::error_code ec;
    const fs::path p = fs::canonical(info.dli_fname, ec);
    if (!ec) return p.parent_path();
  }
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) return exe.parent_path();
  throw std::runtime_error("kanegen: cannot tell where this program is installed; set KANEGEN_DATA_DIR");
}

std::string located(const char* env, const fs::path& relative, const char* what) {
  if (const char* v = std::getenv(env); v && *v) return v;
  const fs::path dir = own_directory();
  for (const fs::path& base : {dir / "..", dir / ".." / ".."}) {
    std::error_code ec;
    const fs::path p = fs::weakly_canonical(base / relative, ec);
    if (!ec && fs::is_directory(p, ec)) return p.string();
  }
  throw std::runtime_error(std::string("kanegen: cannot find its ") + what + " (" + relative.string() + " beside " +
                           dir.string() + "); set " + env);
}

}  // namespace

std::string data_dir() { return located("KANEGEN_DATA_DIR", fs::path("share") / "kanegen", "data directory"); }

std::string template_dir() { return (fs::path(data_dir()) / "templates").string(); }

std::string include_dir() {
  return located("KANEGEN_INCLUDE_DIR", fs::path("include") / "kanegen", "include directory");
}

}  // namespace kanegen
