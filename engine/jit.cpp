#include "engine/jit.hpp"

#include <dlfcn.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <functional>
#include <sstream>
#include <optional>
#include <thread>
#include <vector>

#include "engine/jit_cache.hpp"
#include "engine/manifest.hpp"
#include "engine/resources.hpp"
#include "engine/udot_candidates.hpp"
#include "model/model_hash.hpp"
#include "model/parameters.hpp"
#include "model/signal_cleanup.hpp"

#ifndef KANEGEN_VERSION
#define KANEGEN_VERSION "unknown"
#endif

extern char** environ;

namespace kanegen {

namespace fs = std::filesystem;

namespace {

std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v ? std::string(v) : std::string();
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

void write_file(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
  out.close();
  if (!out) throw std::runtime_error(fmt::format("kanegen: cannot write {}", p.string()));
}

/// Compiles and cache hits are said on stderr, one line each, terminal or not
/// (a first run waits for the compiler: the user is told what and for how long).
bool announce(const JitOptions& o) { return o.verbose || !o.quiet; }

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

/// One compiler invocation of a JIT build (a part compiled to an object, or the link).
struct CompileStep {
  std::vector<std::string> argv;
  double cost = 0;  ///< estimated effort, to start the largest parts first
};

/// Past this many u-dot operations the dual-number functions are compiled at
/// -O0 (at -O1 they take minutes to compile) and serve linearize only (exact
/// derivatives): the dual-number Jacobian costs about 3 u-dot per column, and
/// at -O0 it is slower than SUNDIALS' finite differences of the -O2 u-dot
/// (deep_chain: 5.3 s against 0.7 s at -O1), so the implicit integrators
/// difference the right-hand side instead (LibraryRecord::jacobian_for_integration).
constexpr long kMaxJacobianUdotOps = 6000;

/// Changes whenever plan_compile() chooses differently or the record holds more (part of the cache key).
/// 5: the record names the u-dot form (LibraryRecord::udot_form).
/// 6: u-dot candidates may be built beside the library (udot_candidates.hpp).
constexpr int kCompilePlanVersion = 6;

/// The generated functions are compiled one per translation unit, in
/// parallel, and linked. With the default flags each part gets an
/// optimization level suited to its size (from the manifest's operation
/// counts): GCC's time on one huge straight-line function grows faster than
/// linearly (a 64-body chain's Jacobian took 174 s at -O2, 67 s at -O1 and
/// 6 s at -O0 for that part alone). A quick build (-O0 throughout) compiles
/// the parts in as many translation units as there are cores, balanced by
/// operation count: at -O0 a small part costs mostly the compiler's start and
/// the headers (a small model's 9 parts took 4 s, its 2 groups 1 s).
std::vector<CompileStep> plan_compile(const fs::path& entry, const fs::path& out, const Manifest& manifest,
                                      const JitOptions& o) {
  const bool default_flags = o.flags == default_jit_flags();
  std::vector<std::string> base = split_words(o.compiler);
  std::vector<std::string> flags;
  for (auto& f : split_words(o.flags))
    if (f != "-shared" && !(default_flags && f.rfind("-O", 0) == 0)) flags.push_back(f);
  if (o.native) flags.push_back("-march=native");
  if (o.quick || !o.dispatch) flags.push_back("-DKANEGEN_NO_DISPATCH");
  const std::string include = "-I" + o.include_dir;
  const ManifestFunction* udot = manifest.find("udot");
  const long udot_ops = udot ? udot->ops : 0;
  const bool jacobian_left_out = !o.derivatives;
  std::vector<CompileStep> steps;
  std::vector<std::string> objects;
  auto add = [&](const std::string& part, long ops, const std::string& opt, const std::vector<std::string>& extra) {
    CompileStep st;
    st.argv = base;
    st.argv.insert(st.argv.end(), flags.begin(), flags.end());
    if (default_flags) st.argv.push_back(o.quick ? "-O0" : opt);
    const std::string obj = (out.parent_path() / ("part_" + part + ".o")).string();
    st.argv.insert(st.argv.end(), {"-DKANEGEN_PART_" + part, include, "-c", entry.string(), "-o", obj});
    st.argv.insert(st.argv.end(), extra.begin(), extra.end());
    st.cost = static_cast<double>(ops);
    steps.push_back(std::move(st));
    objects.push_back(obj);
  };
  auto wanted = [&](const std::string& name) {
    if (!o.only_set) return true;
    for (const char* required : {"qdot", "mass_matrix", "forcing", "udot"})
      if (name == required) return true;
    return std::find(o.only.begin(), o.only.end(), name) != o.only.end();
  };
  // the functions that run u_dot (or the outputs) once per direction in dual numbers
  auto is_dual = [](const std::string& name) {
    return name == "jacobian" || name == "input_jacobian" || name == "output_jacobian";
  };
  std::vector<std::string> omitted;
  for (const ManifestFunction& f : manifest.functions)
    if (!wanted(f.name) || (is_dual(f.name) && jacobian_left_out)) omitted.push_back("-DKANEGEN_OMIT_" + f.name);
  add("table", 0, "-O2", omitted);
  for (const ManifestFunction& f : manifest.functions) {
    if (!wanted(f.name)) continue;
    if (is_dual(f.name)) {
      if (jacobian_left_out) continue;
      add(f.name, f.ops, udot_ops <= 1500 ? "-O2" : udot_ops <= kMaxJacobianUdotOps ? "-O1" : "-O0", {});
    } else {
      // u-dot is the hot path: -O2 always (large ones come in parts of a few
      // thousand operations, which -O2 compiles in linear time); the others
      // at -O1 when large
      add(f.name, f.ops, f.name == "udot" || f.ops <= 8000 ? "-O2" : "-O1", {});
    }
  }
  std::stable_sort(steps.begin(), steps.end(), [](const CompileStep& a, const CompileStep& b) { return a.cost > b.cost; });
  if (o.quick && default_flags) {
    // groups: each part, largest first, to the group with the least work so far;
    // a group is the first part's command with the other parts' -DKANEGEN_PART_
    // (and the table's -DKANEGEN_OMIT_) added, writing one object
    const std::size_t groups = std::min<std::size_t>(steps.size(), std::max(1u, std::thread::hardware_concurrency()));
    std::vector<CompileStep> grouped(groups);
    std::vector<double> work(groups, 0.0);
    std::vector<std::vector<std::string>> defines(groups);
    for (const CompileStep& st : steps) {
      const std::size_t g = static_cast<std::size_t>(std::min_element(work.begin(), work.end()) - work.begin());
      work[g] += st.cost + 1.0;
      if (grouped[g].argv.empty()) {
        grouped[g] = st;
      } else {
        for (const auto& a : st.argv)
          if (a.rfind("-DKANEGEN_PART_", 0) == 0 || a.rfind("-DKANEGEN_OMIT_", 0) == 0) defines[g].push_back(a);
      }
    }
    objects.clear();
    for (std::size_t g = 0; g < groups; ++g) {
      auto& argv = grouped[g].argv;
      argv.insert(argv.end(), defines[g].begin(), defines[g].end());
      // its object: after the last -o (the compiler's own words may hold one: "/usr/bin/time -o log c++")
      const auto o_at = std::find(argv.rbegin(), argv.rend(), std::string("-o"));
      objects.push_back(*o_at.base());
      grouped[g].cost = work[g];
    }
    steps = std::move(grouped);
  }
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

/// Compiles `sources` in a private temp dir beside so_path and publishes the
/// library and its record (jit_cache.hpp), and the u-dot candidates beside
/// it (udot_candidates.hpp; `other`: the sources with u-dot in the other code, if any)
/// that build.
void build_library(const GeneratedSources& sources, const Manifest& manifest, const fs::path& so_path,
                   const JitOptions& o, const std::optional<GeneratedSources>& other = std::nullopt) {
  const fs::path dir = so_path.parent_path().empty() ? fs::path(".") : so_path.parent_path();
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error(fmt::format("kanegen: cannot create cache directory {}: {}", dir.string(), ec.message()));
  jit_cache::remove_stale_temps(dir.string());
  const fs::path tmp = jit_cache::make_temp_dir(dir.string());
  // Removed on every exit path, and by the signal handler on SIGINT/SIGTERM/SIGHUP
  // (a SIGKILL leaves it to the next build's remove_stale_temps).
  struct Cleanup {
    fs::path p;
    int slot;
    bool keep = false;
    ~Cleanup() {
      unregister_cleanup(slot);
      std::error_code e;
      if (!keep) fs::remove_all(p, e);
    }
  } cleanup{tmp, register_cleanup(tmp.string())};

  write_file(tmp / "model.hpp", sources.header);
  write_file(tmp / "manifest.json", sources.manifest);
  const fs::path entry_path = tmp / "entry.cpp";
  write_file(entry_path, sources.entry);
  const fs::path out_path = tmp / "lib.so";
  const fs::path log_path = tmp / "compiler.log";
  const std::vector<CompileStep> steps = plan_compile(entry_path, out_path, manifest, o);
  const std::string label = manifest.model;

  const bool talk = announce(o);
  if (talk) {
    const ManifestFunction* ud = manifest.find("udot");
    fmt::print(stderr, "kanegen: compiling generated code for {} ({} functions, u-dot {} operations; {} compile steps "
                       "on {} cores) ...\n",
               label, manifest.functions.size(), ud ? ud->ops : 0, steps.size(),
               std::max(1u, std::thread::hardware_concurrency()));
    if (o.verbose)
      for (const auto& st : steps) fmt::print(stderr, "  {}\n", join_quoted(st.argv));
    std::fflush(stderr);
  }
  const auto t0 = std::chrono::steady_clock::now();
  // the u-dot candidates are built alongside; one that fails is left out
  fs::path other_entry;
  if (other) {
    fs::create_directories(tmp / "other");
    write_file(tmp / "other" / "model.hpp", other->header);
    write_file(tmp / "other" / "entry.cpp", other->entry);
    other_entry = tmp / "other" / "entry.cpp";
  }
  const std::vector<UdotCandidate> candidates = plan_udot_candidates(
      manifest, o, tmp, entry_path, other_entry,
      other ? parse_manifest(other->manifest, "other code's manifest of " + manifest.model).udot_form : std::string());
  std::vector<int> candidate_status(candidates.size(), -1);
  std::vector<std::string> candidate_error(candidates.size());
  std::vector<std::jthread> candidate_builds;  // joined on every way out, before `cleanup` removes tmp
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    if (o.verbose) fmt::print(stderr, "  {}\n", join_quoted(candidates[k].argv));
    candidate_builds.emplace_back([&, k] {
      candidate_status[k] = run_logged(candidates[k].argv, (tmp / ("udot-" + candidates[k].tag + ".log")).string(),
                                       candidate_error[k]);
    });
  }
  std::string run_error;
  std::size_t failed_step = steps.size() - 1;
  const int status = run_steps(steps, log_path.string(), run_error, failed_step);
  for (auto& t : candidate_builds) t.join();
  const std::string command = join_quoted(steps[failed_step].argv);  // for messages
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  if (status != 0 || !fs::exists(out_path)) {
    if (talk) fmt::print(stderr, "kanegen: compiling {} failed after {:.1f} s\n", label, seconds);
    fs::remove(out_path, ec);  // never keep a half-written library
    // Keep sources and log for inspection, outside the library namespace of the cache.
    fs::path kept = dir / "failed" / so_path.stem();
    fs::create_directories(kept.parent_path(), ec);
    fs::remove_all(kept, ec);
    fs::rename(tmp, kept, ec);
    if (ec) kept = tmp;  // raced with another failure: keep the temp dir itself
    cleanup.keep = true;
    const std::string log = (kept / "compiler.log").string();
    int total = 0;
    const std::string head = first_lines(log, 20, &total);
    std::string what =
        status < 0 ? fmt::format("kanegen: compiling generated code for model '{}' failed: {}\n", label, run_error)
                   : fmt::format("kanegen: compiling generated code for model '{}' failed (compiler exit status {})\n",
                                 label, status);
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

  // Publish: the library, then its record (a library without a matching
  // record is rebuilt, never loaded). A concurrent process publishing its own
  // copy at the same time is harmless.
  jit_cache::LibraryRecord record = jit_cache::make_record(out_path.string(), manifest.api_symbol);
  const ManifestFunction* udot_fn = manifest.find("udot");
  record.jacobian_for_integration = !(udot_fn && udot_fn->ops > kMaxJacobianUdotOps);
  record.udot_form = manifest.udot_form;
  remove_udot_candidates(so_path.string());  // those of a library this one replaces
  fs::rename(out_path, so_path, ec);
  if (ec)
    throw std::runtime_error(fmt::format("kanegen: cannot move the compiled library to {}: {}", so_path.string(),
                                         ec.message()));
  jit_cache::write_record(so_path.string(), record);
  if (talk) fmt::print(stderr, "kanegen: compiled {} in {:.1f} s; cached as {}\n", label, seconds, fs::path(so_path).string());
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    if (candidate_status[k] == 0 && fs::exists(candidates[k].out)) {
      jit_cache::LibraryRecord r = jit_cache::make_record(candidates[k].out.string(), manifest.api_symbol);
      r.compiler = candidates[k].name;
      r.udot_form = candidates[k].udot_form;
      r.main_checksum = record.checksum;
      const std::string path = udot_candidate_path(so_path.string(), candidates[k].tag);
      fs::rename(candidates[k].out, path, ec);
      if (!ec) jit_cache::write_record(path, r);
    } else if (o.verbose) {
      fmt::print(stderr, "kanegen: the u-dot candidate {} did not build ({}); left out\n", candidates[k].name,
                 candidate_error[k].empty() ? fmt::format("exit status {}", candidate_status[k]) : candidate_error[k]);
    }
  }
}

/// dlopen + dlsym of a verified library; throws std::runtime_error.
std::unique_ptr<GeneratedEngine> open_library(const Model& model, const std::string& path,
                                              const jit_cache::LibraryRecord& record,
                                              const std::string& generator_hash,
                                              const std::vector<RuntimeParameter>& implicit) {
  const std::string& api_symbol = record.api_symbol;
  void* h = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!h) {
    const char* e = dlerror();
    throw std::runtime_error(fmt::format("kanegen: cannot load generated code {}: {}", path, e ? e : "dlopen failed"));
  }
  std::shared_ptr<void> handle(h, [](void* p) { dlclose(p); });
  dlerror();
  auto fn = reinterpret_cast<KanegenGeneratedApiFn>(dlsym(h, api_symbol.c_str()));
  if (!fn) throw std::runtime_error(fmt::format("kanegen: {}: no symbol {}", path, api_symbol));
  auto e = std::make_unique<GeneratedEngine>(model, fn(), std::move(handle), generator_hash, implicit);
  e->set_library_path(path);
  e->set_jacobian_for_integration(record.jacobian_for_integration);
  e->set_udot_form(record.udot_form);
  return e;
}

/// Loads so_path when its record verifies; otherwise builds it from the sources
/// `make_sources()` gives (called only then), with the u-dot candidates
/// (`make_other(code)`: the sources with u-dot in `code`, "compact" or "straight-line", or null), and loads
/// the result.
template <class MakeSources>
std::unique_ptr<GeneratedEngine> load_or_build(const Model& model, const std::string& so_path,
                                               const std::string& generator_hash, const JitOptions& o,
                                               MakeSources make_sources,
                                               const std::vector<RuntimeParameter>& implicit = {},
                                               const std::function<GeneratedSources(const std::string&)>& make_other = {}) {
  if (const auto record = jit_cache::verified_record(so_path)) {
    if (announce(o)) fmt::print(stderr, "kanegen: generated code for {} from the cache ({})\n", model.name, so_path);
    auto e = open_library(model, so_path, *record, generator_hash, implicit);
    attach_udot_candidates(*e, model, so_path, record->checksum, o, false, announce(o));
    return e;
  }
  const auto t_gen = std::chrono::steady_clock::now();
  const GeneratedSources sources = make_sources();
  if (announce(o))
    fmt::print(stderr, "kanegen: generated the equations of {} in {:.1f} s\n", model.name,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - t_gen).count());
  const Manifest manifest = parse_manifest(sources.manifest, "generated manifest of " + model.name);
  std::optional<GeneratedSources> other;
  if (const std::string code = other_udot_code(manifest, o); make_other && !code.empty()) {
    const auto t_other = std::chrono::steady_clock::now();
    try {
      other = make_other(code);
    } catch (const std::exception& ex) {  // a candidate, not the library: left out
      if (o.verbose) fmt::print(stderr, "kanegen: {} u-dot of {} not generated ({}); left out\n", code, model.name, ex.what());
    }
    if (other && announce(o))
      fmt::print(stderr, "kanegen: generated {}'s u-dot as {} code too, to race it, in {:.1f} s\n", model.name, code,
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - t_other).count());
  }
  build_library(sources, manifest, so_path, o, other);
  const auto record = jit_cache::verified_record(so_path);
  if (!record) throw std::runtime_error(fmt::format("kanegen: the library just built at {} does not verify", so_path));
  auto e = open_library(model, so_path, *record, generator_hash, implicit);
  attach_udot_candidates(*e, model, so_path, record->checksum, o, true, announce(o));
  return e;
}

}  // namespace

std::string default_cache_dir() {
  if (auto d = env("KANEGEN_CACHE_DIR"); !d.empty()) return d;
  if (auto d = env("XDG_CACHE_HOME"); !d.empty()) return (fs::path(d) / "kanegen").string();
  if (auto d = env("HOME"); !d.empty()) return (fs::path(d) / ".cache" / "kanegen").string();
  return (fs::temp_directory_path() / "kanegen-cache").string();
}

std::vector<std::string> split_words(const std::string& s) {
  std::vector<std::string> out;
  std::istringstream in(s);
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

std::string default_jit_flags() { return "-O2 -std=c++20 -fPIC -shared"; }

JitOptions resolved(const JitOptions& opts) {
  JitOptions o = opts;
  if (o.cache_dir.empty()) o.cache_dir = default_cache_dir();
  if (o.compiler.empty()) o.compiler = env("CXX");
  if (o.compiler.empty()) o.compiler = "c++";
  if (o.flags.empty()) o.flags = default_jit_flags();
  if (o.include_dir.empty()) o.include_dir = include_dir();
  if (env("KANEGEN_JIT_QUICK") == "1") o.quick = true;
  return o;
}

std::string jit_cache_key(const Model& model, const std::string& generator_hash, const JitOptions& opts) {
  const JitOptions o = resolved(opts);
  if (o.implicit_parameters) {
    if (const Model m = with_implicit_parameters(model); m.parameters.size() != model.parameters.size()) {
      JitOptions plain = o;
      plain.implicit_parameters = false;
      return jit_cache_key(m, generator_hash, plain);
    }
  }
  std::string flags = join_quoted(split_words(o.compiler)) + "\n" + join_quoted(split_words(o.flags));
  if (o.only_set) {
    std::vector<std::string> only = o.only;
    std::sort(only.begin(), only.end());
    flags += "\nonly " + join_quoted(only);
  }
  if (o.native) flags += "\nnative";
  if (!o.derivatives) flags += "\nno derivatives";
  if (o.quick) flags += "\nquick";
  if (!o.dispatch) flags += "\nno dispatch";
  return fnv1a64_hex(fmt::format("{}\n{}\n{}\n{}\n{}\nplan {}", model_hash(model), KANEGEN_VERSION,
                                 KANEGEN_GENERATED_API_VERSION, generator_hash, flags, kCompilePlanVersion));
}

std::string jit_library_path(const Model& model, const std::string& generator_hash, const JitOptions& opts) {
  const JitOptions o = resolved(opts);
  return (fs::path(o.cache_dir) /
          (jit_cache::file_stem(model.name) + "-" + jit_cache_key(model, generator_hash, o) + ".so"))
      .string();
}

std::unique_ptr<GeneratedEngine> compile_and_load(const Model& model, const GeneratedSources& sources,
                                                  const std::string& so_path, const JitOptions& opts) {
  const JitOptions o = resolved(opts);
  return load_or_build(model, so_path, "", o, [&] { return sources; });
}

namespace {

/// The options of a library already cached that does at least as much as `o`
/// asks: optimized before quick, with derivatives before without.
std::optional<JitOptions> serving_options(const Model& model, const std::string& generator_hash, const JitOptions& o) {
  auto cached = [&](bool quick, bool derivatives) {
    JitOptions c = o;
    c.quick = quick;
    c.derivatives = derivatives;
    return jit_cache::verified_record(jit_library_path(model, generator_hash, c)) ? std::optional<JitOptions>(c)
                                                                                  : std::nullopt;
  };
  std::optional<JitOptions> serving;
  for (const bool quick : {false, o.quick})
    for (const bool derivatives : {true, o.derivatives})
      if (!serving) serving = cached(quick, derivatives);
  return serving;
}

}  // namespace

bool jit_cached(const Model& model, const CodeGenerator& generator, const JitOptions& opts) {
  return serving_options(model, generator.hash, resolved(opts)).has_value();
}

std::unique_ptr<GeneratedEngine> jit_load(const Model& model, const CodeGenerator& generator,
                                          const JitOptions& opts) {
  JitOptions o = resolved(opts);
  if (const auto serving = serving_options(model, generator.hash, o)) o = *serving;
  const std::string so_path = jit_library_path(model, generator.hash, o);
  // the code is generated from the model with its implicit parameters appended
  // (a value edited in the model file then reuses the cached library)
  const std::vector<RuntimeParameter> implicit =
      o.implicit_parameters ? implicit_parameters(model) : std::vector<RuntimeParameter>{};
  const Model& m = implicit.empty() ? model : with_parameters(model, implicit);
  std::function<GeneratedSources(const std::string&)> other;
  if (generator.generate_compact_udot || generator.generate_straight_udot)
    other = [&](const std::string& code) {
      const auto& make = code == "compact" ? generator.generate_compact_udot : generator.generate_straight_udot;
      if (!make) throw std::runtime_error("the generator has no " + code + " u-dot");
      return make(m);
    };
  return load_or_build(model, so_path, generator.hash, o, [&] { return generator.generate(m); }, implicit, other);
}

}  // namespace kanegen
