#include "jit.hpp"

#include <dlfcn.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <sstream>
#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

#include "model_hash.hpp"

#ifndef KANEGEN_VERSION
#define KANEGEN_VERSION "unknown"
#endif
#ifndef KANEGEN_SOURCE_DIR
#define KANEGEN_SOURCE_DIR ""
#endif

extern char** environ;

namespace kanegen {

namespace fs = std::filesystem;

namespace {

std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v ? std::string(v) : std::string();
}

std::vector<std::string> split_words(const std::string& s) {
  std::vector<std::string> out;
  std::istringstream in(s);
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

std::string shell_quote(const std::string& s) {
  if (!s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-+=./,:@%") ==
                        std::string::npos)
    return s;
  std::string r = "'";
  for (char c : s) r += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return r + "'";
}

std::string join_quoted(const std::vector<std::string>& argv) {
  std::string r;
  for (const auto& a : argv) {
    if (!r.empty()) r += ' ';
    r += shell_quote(a);
  }
  return r;
}

/// A model name as a file-name component.
std::string file_stem(const std::string& name) {
  std::string r;
  for (char c : name) r += (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-') ? c : '_';
  return r.empty() ? std::string("model") : r;
}

/// A model name as a C++ identifier (must agree with the generator's rule).
std::string identifier(const std::string& name) {
  std::string r;
  for (char c : name) r += (std::isalnum(static_cast<unsigned char>(c)) || c == '_') ? c : '_';
  if (r.empty() || std::isdigit(static_cast<unsigned char>(r[0]))) r = "_" + r;
  return r;
}

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw std::runtime_error(fmt::format("kanegen: cannot read {}", p.string()));
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_file(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
  out.close();
  if (!out) throw std::runtime_error(fmt::format("kanegen: cannot write {}", p.string()));
}

void replace_all(std::string& s, const std::string& from, const std::string& to) {
  for (std::size_t pos = 0; (pos = s.find(from, pos)) != std::string::npos; pos += to.size())
    s.replace(pos, from.size(), to);
}

std::string c_string_literal_body(const std::string& s) {
  std::string r;
  for (char c : s) {
    if (c == '\\' || c == '"') r += '\\';
    r += c;
  }
  return r;
}

bool announce(const JitOptions& o) { return o.verbose || isatty(STDERR_FILENO); }

/// Runs argv with stdout and stderr to `log_path`; returns the exit status,
/// or -1 with `error` set when it could not be started or was killed.
int run_logged(const std::vector<std::string>& argv, const std::string& log_path, std::string& error) {
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_addopen(&fa, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, args[0], &fa, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) {
    error = fmt::format("cannot run '{}': {}", argv[0], std::strerror(rc));
    return -1;
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) {
      error = fmt::format("waiting for '{}': {}", argv[0], std::strerror(errno));
      return -1;
    }
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  error = fmt::format("'{}' killed by signal {}", argv[0], WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  return -1;
}

std::string first_lines(const std::string& path, int n, int* total) {
  std::ifstream in(path);
  std::string line, out;
  int count = 0;
  while (std::getline(in, line)) {
    if (count < n) {
      out += "  | ";
      out += line;
      out += '\n';
    }
    ++count;
  }
  if (total) *total = count;
  return out;
}

/// Removes temp build dirs left by killed processes (older than a day).
void remove_stale_temps(const fs::path& dir) {
  std::error_code ec;
  const auto now = fs::file_time_type::clock::now();
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind(".tmp-", 0) != 0) continue;
    std::error_code ec2;
    const auto t = fs::last_write_time(it->path(), ec2);
    if (!ec2 && now - t > std::chrono::hours(24)) fs::remove_all(it->path(), ec2);
  }
}

/// Models whose u-dot takes more operations get no compiled Jacobian.
constexpr long kMaxJacobianUdotOps = 6000;

/// One compiler invocation of a JIT build (a part compiled to an object, or the link).
struct CompileStep {
  std::vector<std::string> argv;
  double cost = 0;  ///< estimated effort, to start the largest parts first
};

/// Operation count of `function` from the header's "Operation counts" comment (0 if absent).
long header_ops(const std::string& header, const std::string& function) {
  const std::string key = "//   " + function + " ";
  const auto pos = header.find(key);
  if (pos == std::string::npos) return 0;
  return std::strtol(header.c_str() + pos + key.size(), nullptr, 10);
}

/// The generated functions are compiled one per translation unit, in
/// parallel, and linked. With the default flags each part gets an
/// optimization level suited to its size: GCC's time on one huge
/// straight-line function grows faster than linearly, and the dual-number
/// Jacobian instantiates u_dot with a struct scalar (a 64-body chain took
/// 174 s at -O2, 67 s at -O1 and 6 s at -O0 for that part alone).
std::vector<CompileStep> plan_compile(const fs::path& entry, const fs::path& out, const std::string* header,
                                      const JitOptions& o) {
  const bool default_flags = o.flags == default_jit_flags();
  std::vector<std::string> base = split_words(o.compiler);
  std::vector<std::string> flags;
  for (auto& f : split_words(o.flags))
    if (f != "-shared" && !(default_flags && f.rfind("-O", 0) == 0)) flags.push_back(f);
  const std::string include = "-I" + (fs::path(o.source_dir) / "runtime").string();
  struct Part {
    int id;
    const char* name;
    const char* macro;  // present only when the header defines it (nullptr: always)
  };
  const Part parts[] = {{1, "table", nullptr},          {2, "qdot", nullptr},
                        {3, "mass_matrix", nullptr},    {4, "forcing", nullptr},
                        {5, "udot", nullptr},           {6, "jacobian", nullptr},
                        {7, "energy", "KANEGEN_HAS_ENERGY"}, {8, "momentum", "KANEGEN_HAS_MOMENTUM"},
                        {9, "reactions", "KANEGEN_HAS_REACTIONS"}};
  std::vector<CompileStep> steps;
  std::vector<std::string> objects;
  for (const Part& p : parts) {
    if (p.macro && header && header->find(std::string("#define ") + p.macro) == std::string::npos) continue;
    const long udot_ops = header ? header_ops(*header, "udot") : 0;
    long ops = header ? header_ops(*header, p.id == 6 ? "udot" : p.name) : 0;
    if (p.id == 6) ops *= 3;
    // The dual-number Jacobian costs about 3 u-dot per column; compiled below
    // -O1 it is slower than SUNDIALS' finite differences of the -O2 u-dot
    // (deep_chain: 5.3 s against 0.7 s), and at -O1 past ~6000 u-dot
    // operations it takes minutes to compile: left out there.
    const bool jacobian_left_out = udot_ops > kMaxJacobianUdotOps;
    if (p.id == 6 && jacobian_left_out) continue;
    std::string opt = "-O2";
    if (p.id == 6) opt = udot_ops <= 1500 ? "-O2" : "-O1";
    else if (ops > 8000) opt = "-O1";
    CompileStep st;
    st.argv = base;
    st.argv.insert(st.argv.end(), flags.begin(), flags.end());
    if (default_flags) st.argv.push_back(opt);
    const std::string obj = (out.parent_path() / (std::string("part_") + p.name + ".o")).string();
    st.argv.insert(st.argv.end(), {fmt::format("-DKANEGEN_PART={}", p.id), include, "-c", entry.string(), "-o", obj});
    if (p.id == 1 && jacobian_left_out) st.argv.push_back("-DKANEGEN_NO_JACOBIAN");
    st.cost = static_cast<double>(ops);
    steps.push_back(std::move(st));
    objects.push_back(obj);
  }
  std::stable_sort(steps.begin(), steps.end(), [](const CompileStep& a, const CompileStep& b) { return a.cost > b.cost; });
  CompileStep link;
  link.argv = base;
  for (auto& f : split_words(o.flags))
    if (f.rfind("-O", 0) != 0) link.argv.push_back(f);
  if (std::find(link.argv.begin(), link.argv.end(), "-shared") == link.argv.end()) link.argv.push_back("-shared");
  link.argv.insert(link.argv.end(), objects.begin(), objects.end());
  link.argv.insert(link.argv.end(), {"-o", out.string()});
  steps.push_back(std::move(link));
  return steps;
}

/// Runs all but the last step concurrently (as many at once as there are
/// cores), then the last (the link). Logs go to log_path (concatenated).
/// Returns the first non-zero status; `failed` is the index of that step.
int run_steps(const std::vector<CompileStep>& steps, const std::string& log_path, std::string& error,
              std::size_t& failed) {
  const std::size_t n = steps.size() - 1;
  const unsigned jobs = std::max(1u, std::thread::hardware_concurrency());
  std::vector<int> status(n, 0);
  std::vector<std::string> errors(n);
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t i; (i = next++) < n;)
      status[i] = run_logged(steps[i].argv, log_path + "." + std::to_string(i), errors[i]);
  };
  std::vector<std::thread> pool;
  for (unsigned t = 0; t < std::min<std::size_t>(jobs, n); ++t) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
  std::ofstream log(log_path);
  int first = 0;
  for (std::size_t i = 0; i < n; ++i) {
    std::ifstream part(log_path + "." + std::to_string(i));
    log << part.rdbuf();
    std::error_code ec;
    fs::remove(log_path + "." + std::to_string(i), ec);
    if (status[i] != 0 && first == 0) {
      first = status[i];
      error = errors[i];
      failed = i;
    }
  }
  log.close();
  if (first != 0) return first;
  std::string link_error;
  const int s = run_logged(steps.back().argv, log_path + ".link", link_error);
  std::ifstream part(log_path + ".link");
  std::ofstream(log_path, std::ios::app) << part.rdbuf();
  if (s != 0) {
    error = link_error;
    failed = n;
  }
  return s;
}

struct BuildInput {
  std::string include;         ///< what entry.cpp #includes
  std::string namespace_name;  ///< e.g. kanegen_gen::pendulum
  const std::string* header_text = nullptr;  ///< written as model.hpp in the temp dir when given
  std::string label;           ///< model name, for messages
};

/// Compiles into a private temp dir beside so_path and renames the result onto so_path.
void build_library(const BuildInput& in, const fs::path& so_path, const JitOptions& o) {
  const fs::path dir = so_path.parent_path().empty() ? fs::path(".") : so_path.parent_path();
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error(fmt::format("kanegen: cannot create cache directory {}: {}", dir.string(), ec.message()));
  remove_stale_temps(dir);

  const std::string stem = so_path.stem().string();
  std::string tmpl = (dir / (".tmp-" + stem + "-XXXXXX")).string();
  if (!mkdtemp(tmpl.data()))
    throw std::runtime_error(fmt::format("kanegen: cannot create a temporary directory in {}: {}", dir.string(),
                                         std::strerror(errno)));
  const fs::path tmp(tmpl);
  struct Cleanup {
    fs::path p;
    bool keep = false;
    ~Cleanup() {
      std::error_code e;
      if (!keep) fs::remove_all(p, e);
    }
  } cleanup{tmp};

  const fs::path src_dir = o.source_dir;
  std::string include = in.include;
  if (in.header_text) {
    write_file(tmp / "model.hpp", *in.header_text);
    include = "model.hpp";
  }
  std::string entry = read_file(src_dir / "templates" / "entry.cpp.in");
  replace_all(entry, "@HEADER@", c_string_literal_body(include));
  replace_all(entry, "@NAMESPACE@", in.namespace_name);
  const fs::path entry_path = tmp / "entry.cpp";
  write_file(entry_path, entry);

  const fs::path out_path = tmp / "lib.so";
  const fs::path log_path = tmp / "compiler.log";
  const std::vector<CompileStep> steps = plan_compile(entry_path, out_path, in.header_text, o);

  const bool talk = announce(o);
  if (talk) {
    fmt::print(stderr, "kanegen: compiling generated code for {} ...", in.label);
    if (o.verbose)
      for (const auto& st : steps) fmt::print(stderr, "\n  {}", join_quoted(st.argv));
    if (o.verbose) fmt::print(stderr, "\n");
    std::fflush(stderr);
  }
  const auto t0 = std::chrono::steady_clock::now();
  std::string run_error;
  std::size_t failed_step = steps.size() - 1;
  const int status = run_steps(steps, log_path.string(), run_error, failed_step);
  const std::string command = join_quoted(steps[failed_step].argv);  // for messages
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  if (status != 0 || !fs::exists(out_path)) {
    if (talk) fmt::print(stderr, " failed\n");
    fs::remove(out_path, ec);  // never keep a half-written library
    // Keep sources and log for inspection, outside the library namespace of the cache.
    fs::path kept = dir / "failed" / stem;
    fs::create_directories(kept.parent_path(), ec);
    fs::remove_all(kept, ec);
    fs::rename(tmp, kept, ec);
    if (ec) kept = tmp;  // raced with another failure: keep the temp dir itself
    cleanup.keep = true;
    const std::string log = (kept / "compiler.log").string();
    int total = 0;
    const std::string head = first_lines(log, 20, &total);
    std::string what =
        status < 0 ? fmt::format("kanegen: compiling generated code for {} failed: {}\n", in.label, run_error)
                   : fmt::format("kanegen: compiling generated code for {} failed (compiler exit status {})\n",
                                 in.label, status);
    what += fmt::format("  command: {}\n", command);
    what += fmt::format("  sources kept in: {}\n", kept.string());
    if (!head.empty()) {
      what += fmt::format("  compiler output ({}):\n", total > 20 ? fmt::format("first 20 of {} lines; all in {}", total, log)
                                                                  : log);
      what += head;
    }
    if (!what.empty() && what.back() == '\n') what.pop_back();
    throw JitError(what, command, kept.string());
  }

  // Publish atomically: a concurrent process renaming its own copy is harmless.
  fs::rename(out_path, so_path, ec);
  if (ec)
    throw std::runtime_error(fmt::format("kanegen: cannot move the compiled library to {}: {}", so_path.string(),
                                         ec.message()));
  if (talk) fmt::print(stderr, " done in {:.1f} s\n", seconds);
}

struct Library {
  std::shared_ptr<void> handle;
  const KanegenGeneratedApi* api = nullptr;
};

/// dlopen + dlsym; on failure returns an empty Library with `error` set.
Library open_library(const std::string& path, std::string& error) {
  void* h = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!h) {
    const char* e = dlerror();
    error = e ? e : "dlopen failed";
    return {};
  }
  Library lib;
  lib.handle = std::shared_ptr<void>(h, [](void* p) { dlclose(p); });
  dlerror();
  auto fn = reinterpret_cast<KanegenGeneratedApiFn>(dlsym(h, "kanegen_generated_api"));
  if (!fn) {
    error = fmt::format("{}: no symbol kanegen_generated_api", path);
    return {};
  }
  lib.api = fn();
  if (!lib.api) error = fmt::format("{}: kanegen_generated_api() returned NULL", path);
  return lib;
}

std::unique_ptr<GeneratedEngine> wrap(const Model& model, Library lib, const std::string& path) {
  auto e = std::make_unique<GeneratedEngine>(model, lib.api, std::move(lib.handle));
  e->set_library_path(path);
  return e;
}

/// Loads so_path if present and loadable; otherwise builds it (once more if
/// the file present cannot be loaded, e.g. truncated by a crash of a tool).
template <class Build>
std::unique_ptr<GeneratedEngine> load_or_build(const Model& model, const std::string& so_path, Build build) {
  std::string error;
  if (fs::exists(so_path)) {
    Library lib = open_library(so_path, error);
    if (lib.api) return wrap(model, std::move(lib), so_path);
    std::error_code ec;
    fs::remove(so_path, ec);  // unusable: rebuild it
  }
  build();
  error.clear();
  Library lib = open_library(so_path, error);
  if (!lib.api) throw std::runtime_error(fmt::format("kanegen: cannot load generated code {}: {}", so_path, error));
  return wrap(model, std::move(lib), so_path);
}

/// The namespace the generated header declares: "namespace kanegen_gen::X".
std::string namespace_of(const std::string& header, const Model& model) {
  const std::string key = "namespace kanegen_gen::";
  const std::size_t p = header.find(key);
  if (p != std::string::npos) {
    std::size_t e = p + key.size();
    while (e < header.size() && (std::isalnum(static_cast<unsigned char>(header[e])) || header[e] == '_')) ++e;
    if (e > p + key.size()) return header.substr(p + 10, e - p - 10);
  }
  return "kanegen_gen::" + identifier(model.name);
}

}  // namespace

std::string default_cache_dir() {
  if (auto d = env("KANEGEN_CACHE_DIR"); !d.empty()) return d;
  if (auto d = env("XDG_CACHE_HOME"); !d.empty()) return (fs::path(d) / "kanegen").string();
  if (auto d = env("HOME"); !d.empty()) return (fs::path(d) / ".cache" / "kanegen").string();
  return (fs::temp_directory_path() / "kanegen-cache").string();
}

std::string default_jit_flags() { return "-O2 -std=c++20 -fPIC -shared"; }

JitOptions resolved(const JitOptions& opts) {
  JitOptions o = opts;
  if (o.cache_dir.empty()) o.cache_dir = default_cache_dir();
  if (o.compiler.empty()) o.compiler = env("CXX");
  if (o.compiler.empty()) o.compiler = "c++";
  if (o.flags.empty()) o.flags = default_jit_flags();
  if (o.source_dir.empty()) o.source_dir = env("KANEGEN_SOURCE_DIR");
  if (o.source_dir.empty()) o.source_dir = KANEGEN_SOURCE_DIR;
  return o;
}

std::string jit_cache_key(const Model& model, const JitOptions& opts) {
  const JitOptions o = resolved(opts);
  const std::string flags_hash = fnv1a64_hex(join_quoted(split_words(o.compiler)) + "\n" + join_quoted(split_words(o.flags)));
  return fnv1a64_hex(fmt::format("{}\n{}\n{}\n{}", model_hash(model), KANEGEN_VERSION, KANEGEN_GENERATED_API_VERSION,
                                 flags_hash));
}

std::string jit_library_path(const Model& model, const JitOptions& opts) {
  const JitOptions o = resolved(opts);
  return (fs::path(o.cache_dir) / (file_stem(model.name) + "-" + jit_cache_key(model, o) + ".so")).string();
}

std::unique_ptr<GeneratedEngine> load_generated_library(const Model& model, const std::string& so_path) {
  std::string error;
  Library lib = open_library(so_path, error);
  if (!lib.api) throw std::runtime_error(fmt::format("kanegen: cannot load generated code {}: {}", so_path, error));
  return wrap(model, std::move(lib), so_path);
}

std::unique_ptr<GeneratedEngine> compile_and_load(const Model& model, const std::string& header_path,
                                                  const std::string& namespace_name, const std::string& so_path,
                                                  const JitOptions& opts) {
  const JitOptions o = resolved(opts);
  return load_or_build(model, so_path, [&] {
    BuildInput in;
    in.include = fs::absolute(header_path).string();
    in.namespace_name = namespace_name;
    in.label = model.name;
    build_library(in, so_path, o);
  });
}

std::unique_ptr<GeneratedEngine> jit_load_with(const Model& model, const JitOptions& opts,
                                               const HeaderGenerator& generate) {
  const JitOptions o = resolved(opts);
  const std::string so_path = jit_library_path(model, o);
  return load_or_build(model, so_path, [&] {
    const std::string header = generate(model);
    BuildInput in;
    in.header_text = &header;
    in.namespace_name = namespace_of(header, model);
    in.label = model.name;
    build_library(in, so_path, o);
  });
}

}  // namespace kanegen
