#include "engine/udot_candidates.hpp"

#include <dlfcn.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <optional>
#include <sstream>

#include "engine/jit_cache.hpp"
#include "engine/udot_race.hpp"
#include "model/state_io.hpp"

namespace kanegen {

namespace fs = std::filesystem;

namespace {

/// Below this many operations straight-line u-dot fits the instruction cache and is faster than compact code
/// (docs/decisions.md): no other code is raced.
constexpr long kCandidateMinOps = 2000;

/// From this many operations the second compiler's build of u-dot is raced too: at the baseline ISA clang++'s
/// straight-line u-dot ran 198 ns against g++'s 239 on bus_4 (1,665 operations) and 137 against 145 on chain_4
/// (900), as fast on chain_2 (187), and 1.5x slower on gravity_gradient_boom: measured per model, not assumed.
constexpr long kSecondCompilerMinOps = 500;

/// Compact u-dot of at most this many operations is raced against straight-line code: near the generator's
/// threshold (codegen/generator.hpp), AVX2 straight-line code can be faster (chain_8's by clang++ 408 ns against
/// compact 480); beyond it compact code won on every model measured (chain_16 1.35x at the baseline ISA).
constexpr long kStraightCandidateMaxOps = 6000;

/// The executable `name` on $PATH, or empty.
std::string on_path(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "");
  for (std::string d; std::getline(dirs, d, ':');) {
    if (d.empty()) continue;
    const fs::path p = fs::path(d) / name;
    if (access(p.c_str(), X_OK) == 0) return p.string();
  }
  return {};
}

bool optimized_default_build(const JitOptions& o) { return !o.quick && o.flags == default_jit_flags(); }

/// Whether the second compiler builds for AVX2 (x86-64-v3): where the main library's u-dot runs its AVX2 clone,
/// i.e. the build dispatches and this CPU has it (clang 14 cannot clone templates).
bool second_at_v3(const JitOptions& o) {
  if (o.native || !o.dispatch) return false;
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
  __builtin_cpu_init();
  return __builtin_cpu_supports("x86-64-v3");
#else
  return false;
#endif
}

/// The file tag of the second compiler's u-dot on this CPU: a library built for AVX2 is never found, and so
/// never served, on a CPU without it (a cache shared between machines).
std::string second_tag(const JitOptions& o) { return second_at_v3(o) ? "second-v3" : "second"; }

/// Whether u-dot has at least `min_ops` operations.
bool udot_of_at_least(const Manifest& manifest, long min_ops) {
  const ManifestFunction* udot = manifest.find("udot");
  return udot && udot->ops >= min_ops;
}

/// Whether u-dot is long enough to race it in the other code (straight-line or compact).
bool long_udot(const Manifest& manifest) { return udot_of_at_least(manifest, kCandidateMinOps); }

/// The other code's candidates, by the main compiler and the second: tags and names.
struct OtherCodeNames {
  std::string tag, name, second_tag, second_name_prefix;
};

OtherCodeNames other_code_names(const std::string& code, bool second_v3) {
  const std::string v3 = second_v3 ? "-v3" : "";
  if (code == "compact") return {"compact", "compact", "compact-second" + v3, "compact by "};
  return {"straight", "straight-line", "straight-second" + v3, "straight-line by "};
}

/// The command's tail that builds a library of u-dot alone from `entry` (its table lists only u-dot).
void udot_alone(std::vector<std::string>& argv, const Manifest& manifest, const JitOptions& o, const fs::path& entry,
                const fs::path& out) {
  argv.insert(argv.end(), {"-DKANEGEN_PART_udot", "-DKANEGEN_PART_table"});
  for (const ManifestFunction& f : manifest.functions)
    if (f.name != "udot") argv.push_back("-DKANEGEN_OMIT_" + f.name);
  argv.insert(argv.end(), {"-I" + o.include_dir, entry.string(), "-o", out.string()});
}

/// A candidate's library loaded, checked against the engine's table, and its u-dot.
struct LoadedCandidate {
  std::shared_ptr<void> handle;
  KanegenFunctionPtr udot = nullptr;
};

std::optional<LoadedCandidate> load_candidate(const GeneratedEngine& e, const std::string& path,
                                              const std::string& api_symbol) {
  void* h = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!h) return std::nullopt;  // the library's own u-dot serves
  LoadedCandidate c{std::shared_ptr<void>(h, [](void* p) { dlclose(p); }), nullptr};
  auto api_fn = reinterpret_cast<KanegenGeneratedApiFn>(dlsym(h, api_symbol.c_str()));
  const KanegenGeneratedApi* api = api_fn ? api_fn() : nullptr;
  if (!api || api->api_version != e.api().api_version || std::string(api->model_hash) != e.api().model_hash ||
      api->nq != e.api().nq || api->nu != e.api().nu || api->np != e.api().np)
    return std::nullopt;
  c.udot = find_function(*api, "udot");
  if (!c.udot) return std::nullopt;
  return c;
}

}  // namespace

std::string second_compiler(const JitOptions& o) {
  if (!optimized_default_build(o)) return {};
  for (const std::string& w : split_words(o.compiler))
    if (fs::path(w).filename().string().find("clang") != std::string::npos) return {};
  const char* chosen = std::getenv("KANEGEN_SECOND_CXX");
  if (chosen && std::string(chosen) == "none") return {};
  if (chosen && *chosen) return chosen;
  return on_path("clang++").empty() ? std::string() : std::string("clang++");
}

std::string other_udot_code(const Manifest& manifest, const JitOptions& o) {
  if (!optimized_default_build(o) || !long_udot(manifest)) return {};
  if (manifest.udot_code == "straight-line") return "compact";
  if (manifest.udot_code == "compact" && manifest.find("udot")->ops <= kStraightCandidateMaxOps) return "straight-line";
  return {};
}

std::vector<UdotCandidate> plan_udot_candidates(const Manifest& manifest, const JitOptions& o, const fs::path& tmp,
                                                const fs::path& entry, const fs::path& other_entry,
                                                const std::string& other_form) {
  std::vector<UdotCandidate> out;
  if (!optimized_default_build(o) || !udot_of_at_least(manifest, kSecondCompilerMinOps)) return out;
  const std::string second = second_compiler(o);
  // the second compiler, for the instruction set the main library's u-dot runs at on this CPU
  auto by_second = [&](std::string name, std::string tag, const std::string& form, const fs::path& from,
                       const fs::path& so) {
    UdotCandidate c{std::move(name), std::move(tag), form, split_words(second), so};
    for (const char* f : {"-O2", "-std=c++20", "-fPIC", "-shared", "-fno-math-errno"}) c.argv.emplace_back(f);
    if (o.native) c.argv.emplace_back("-march=native");
    if (second_at_v3(o)) c.argv.emplace_back("-march=x86-64-v3");
    c.argv.emplace_back("-DKANEGEN_NO_DISPATCH");
    udot_alone(c.argv, manifest, o, from, c.out);
    out.push_back(std::move(c));
  };
  if (!second.empty()) by_second(second, second_tag(o), manifest.udot_form, entry, tmp / "udot-second.so");
  const std::string other = other_udot_code(manifest, o);
  if (!other_entry.empty() && !other.empty()) {
    const OtherCodeNames n = other_code_names(other, second_at_v3(o));
    // the main compiler at the main library's flags (its AVX2 clone too)
    UdotCandidate c{n.name, n.tag, other_form, split_words(o.compiler), tmp / ("udot-" + n.tag + ".so")};
    for (const std::string& f : split_words(o.flags)) c.argv.push_back(f);
    if (o.native) c.argv.emplace_back("-march=native");
    if (!o.dispatch) c.argv.emplace_back("-DKANEGEN_NO_DISPATCH");
    udot_alone(c.argv, manifest, o, other_entry, c.out);
    out.push_back(std::move(c));
    if (!second.empty())
      by_second(n.second_name_prefix + second, n.second_tag, other_form, other_entry,
                tmp / ("udot-" + n.tag + "-second.so"));
  }
  return out;
}

std::string udot_candidate_path(const std::string& so_path, const std::string& tag) {
  fs::path p(so_path);
  p.replace_extension(".udot-" + tag + ".so");
  return p.string();
}

void remove_udot_candidates(const std::string& so_path) {
  std::vector<std::string> tags{"second", "second-v3"};
  for (const char* code : {"compact", "straight-line"})
    for (const bool v3 : {false, true}) {
      const OtherCodeNames n = other_code_names(code, v3);
      if (!v3) tags.push_back(n.tag);
      tags.push_back(n.second_tag);
    }
  for (const std::string& tag : tags) {
    const std::string path = udot_candidate_path(so_path, tag);
    std::error_code ec;
    fs::remove(jit_cache::record_path(path), ec);  // the record first: a library without one is never loaded
    fs::remove(path, ec);
  }
}

void attach_udot_candidates(GeneratedEngine& e, const Model& model, const std::string& so_path,
                            const std::string& main_checksum, const JitOptions& o, bool fresh, bool talk) {
  struct Entry {
    std::string path;
    jit_cache::LibraryRecord record;
    LoadedCandidate loaded;
    UdotRace race;
  };
  std::vector<Entry> entries;
  const std::string second = second_compiler(o);
  std::vector<std::pair<std::string, std::string>> candidates = {{second_tag(o), second}};
  for (const char* code : {"compact", "straight-line"}) {
    const OtherCodeNames n = other_code_names(code, second_at_v3(o));
    candidates.emplace_back(n.tag, n.name);
    candidates.emplace_back(n.second_tag, second.empty() ? "" : n.second_name_prefix + second);
  }
  for (const auto& [tag, name] : candidates) {
    if (name.empty()) continue;
    const std::string path = udot_candidate_path(so_path, tag);
    // (a cached load hashes only the preferred candidate's library)
    const auto record = jit_cache::verified_record(path, [&](const jit_cache::LibraryRecord& r) {
      return r.compiler == name && r.main_checksum == main_checksum && (fresh || r.preferred);
    });
    if (!record) continue;
    auto loaded = load_candidate(e, path, record->api_symbol);
    if (!loaded) continue;
    entries.push_back({path, *record, std::move(*loaded), {}});
  }
  if (entries.empty()) return;
  Entry* served = nullptr;
  if (fresh) {
    // the library's own u-dot and every candidate in one race (engine/udot_race.hpp)
    std::vector<KanegenFunctionPtr> fns{e.udot_function()};
    for (const Entry& en : entries) fns.push_back(en.loaded.udot);
    const std::vector<UdotRace> races = race_udots(e, fns, initial_state(model));
    for (std::size_t k = 0; k < entries.size(); ++k) {
      Entry& en = entries[k];
      en.race = races[k];
      if (second_wins(en.race) && (!served || en.race.second_ns < served->race.second_ns)) served = &en;
    }
    std::string said;
    for (Entry& en : entries) {
      en.record.preferred = &en == served;
      en.record.udot_ns = en.race.second_ns;
      en.record.main_udot_ns = en.race.first_ns;
      jit_cache::write_record(en.path, en.record);
      said += fmt::format("{} {:.0f} ns{}, ", en.record.compiler, en.race.second_ns,
                          en.race.max_rel_diff > 1e-9 ? fmt::format(" (differs by {:.1e})", en.race.max_rel_diff)
                                                      : std::string());
    }
    if (talk)
      fmt::print(stderr, "kanegen: u-dot of {} at the initial state: {}the library's own {:.0f} ns: {} is used\n",
                 model.name, said, entries.front().race.first_ns,
                 served ? served->record.compiler : std::string("the library's own"));
  } else {
    // only preferred ones were loaded (two processes racing at once may each have preferred one)
    for (Entry& en : entries)
      if (!served || en.record.udot_ns < served->record.udot_ns) served = &en;
  }
  if (!served) return;
  if (!fresh && talk)
    fmt::print(stderr, "kanegen: u-dot of {} served by its candidate {} (raced {:.0f} ns against the library's own {:.0f} ns)\n",
               model.name, served->record.compiler, served->record.udot_ns, served->record.main_udot_ns);
  e.use_udot(served->loaded.udot, served->loaded.handle, served->record.compiler);
  if (!served->record.udot_form.empty()) e.set_udot_form(served->record.udot_form);
}

}  // namespace kanegen
