// The Monte Carlo sweep of the command line (docs/sweeps.md), shared by
// `kanegen sweep` and every ahead-of-time simulator's --sweep (closed loop,
// with the controller compiled in): one run replayed (--run K), shards
// merged (--merge), or the runs spread over threads, over MPI ranks when the
// program is built with MPI and started by mpirun (rank 0 hands out run
// indices one at a time to the others: dynamic load balancing), or over
// batch jobs with --shard. The results (DIR/results.tsv, one line per run)
// are appended as runs finish, so an interrupted sweep resumes where it
// stopped; the tables are written sorted by run index: byte-identical for
// any spread. Header-only (the simulators include it; MPI only where
// KANEGEN_HAVE_MPI is defined).
#pragma once

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <thread>

#include "model/diagnostics.hpp"
#include "model/output_file.hpp"
#include "sim/sweep.hpp"

#ifdef KANEGEN_HAVE_MPI
#include <mpi.h>
#endif

namespace kanegen::cli {

namespace fs = std::filesystem;

struct SweepCli {
  std::string sweep, output;
  int threads = 0;
  long run = -1;
  std::string shard;
  std::vector<std::string> merge;
  bool no_progress = false;
  CLI::Option* output_option = nullptr;  ///< to tell -o "" (refused) from no -o (the default place)
  bool output_given() const { return output_option && output_option->count() > 0; }
};

/// Progress on stderr: runs done, runs/s, ETA (a terminal, or --progress under mpirun).
class SweepProgress {
 public:
  SweepProgress(long total, long done, bool enabled) : total_(total), done_(done), start_done_(done), enabled_(enabled) {}
  void add(bool failed) {
    ++done_;
    failed_ += failed;
    const auto now = std::chrono::steady_clock::now();
    if (!enabled_ || (now - last_ < std::chrono::milliseconds(500) && done_ < total_)) return;
    last_ = now;
    const double s = std::chrono::duration<double>(now - start_).count();
    const double rate = s > 0 ? static_cast<double>(done_ - start_done_) / s : 0.0;
    const double eta = rate > 0 ? static_cast<double>(total_ - done_) / rate : 0.0;
    fmt::print(stderr, "\r{}/{} runs, {:.1f} runs/s, ETA {:.0f} s, {} failed   ", done_, total_, rate, eta, failed_);
    if (done_ >= total_) fmt::print(stderr, "\n");
    std::fflush(stderr);
  }
  double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }

 private:
  long total_, done_, start_done_, failed_ = 0;
  bool enabled_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now(), last_{};
};

/// results.tsv: a header naming the sweep, then one serialized result per line.
inline std::map<long, RunResult> read_results(const std::string& path, const std::string& identity, bool must_match) {
  std::map<long, RunResult> out;
  std::ifstream in(path);
  if (!in) return out;
  std::string line;
  std::getline(in, line);
  if (line.rfind("# kanegen sweep " + identity, 0) != 0) {
    if (must_match)
      throw InputError(Diagnostic{path, 1, "", fmt::format("results of another sweep ({}); expected sweep {}", line, identity)});
    return out;
  }
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    try {
      RunResult r = deserialize(line);
      out[r.index] = std::move(r);
    } catch (const std::exception&) {  // a line cut by an interruption: that run is done again
    }
  }
  return out;
}

inline void finish_sweep(const SweepPlan& plan, std::map<long, RunResult>& all, const std::string& dir, const std::string& header,
            double seconds, long ran) {
  std::vector<RunResult> sorted;
  std::string tsv = header + "\n";
  for (auto& [k, r] : all) {
    tsv += serialize(r) + "\n";
    sorted.push_back(r);
  }
  write_file_atomically((fs::path(dir) / "results.tsv").string(), tsv);
  write_sweep_outputs(plan, sorted, dir);
  long failed = 0;
  for (const auto& r : sorted) failed += !r.ok();
  fmt::print(stderr, "sweep {}: {} runs ({} now, {:.2f} s, {:.2f} runs/s), {} failed; {}/runs.csv, summary.md\n",
             sweep_identity(plan), sorted.size(), ran, seconds, seconds > 0 ? ran / seconds : 0.0, failed, dir);
}

/// The sweep of `o` (one run, a merge, or the runs of this shard, resumed
/// from DIR/results.tsv), each run on an engine from `make`, closed-loop
/// when `controller` makes a law.
inline int run_sweep_cli(const SweepCli& o, const std::function<std::unique_ptr<Engine>(const Model&)>& make,
                         const ControllerFactory& controller = {}) {
  const SweepSpec spec = load_sweep_spec(o.sweep);
  const SweepPlan plan = plan_sweep(spec);
  const std::string id = sweep_identity(plan);

  if (o.run >= 0) {  // one run, replayed alone with its full time history
    if (o.run >= spec.runs) throw InputError(Diagnostic{"--run", 0, "", fmt::format("{}; the sweep has runs 0 to {}", o.run, spec.runs - 1)});
    const std::string path = o.output_given() ? o.output : fmt::format("run_{}.csv", o.run);
    check_output_options({{"-o", path}}, sweep_input_files(plan));  // before the run: nothing written on a refusal
    OutputFile out(path);
    auto engine = make(plan.model);
    const RunResult r = run_one(*engine, plan, o.run, &out.stream(), controller);
    if (!r.ok()) {
      fmt::print(stderr, "run {}: {}\n", o.run, r.status);
      return 1;
    }
    out.commit();
    for (std::size_t i = 0; i < spec.dispersions.size(); ++i) fmt::print(stderr, "{} = {:.17g}\n", spec.dispersions[i].target, r.values[i]);
    for (std::size_t i = 0; i < spec.metrics.size(); ++i) fmt::print(stderr, "{} = {:.17g}\n", spec.metrics[i].name, r.metrics[i]);
    fmt::print(stderr, "run {} written to {}\n", o.run, path);
    return 0;
  }

  const std::string dir = o.output_given() ? o.output : fs::path(o.sweep).replace_extension(".out").string();
  check_sweep_output_directory("-o", dir, o.merge);  // before any run
  if (!o.merge.empty()) {  // shards' results into one table
    std::map<long, RunResult> all;
    for (const std::string& d : o.merge) {
      const std::string p = (fs::path(d) / "results.tsv").string();
      if (!fs::exists(p)) throw InputError(Diagnostic{p, 0, "", "missing; expected the results of a shard of this sweep"});
      for (auto& [k, r] : read_results(p, id, true)) all[k] = std::move(r);
    }
    fs::create_directories(dir);
    finish_sweep(plan, all, dir, "# kanegen sweep " + id, 0.0, 0);
    if (static_cast<long>(all.size()) != spec.runs)
      fmt::print(stderr, "note: {} of {} runs present\n", all.size(), spec.runs);
    return 0;
  }

  long shard = 0, shards = 1;
  if (!o.shard.empty()) {
    const auto slash = o.shard.find('/');
    char* e1 = nullptr;
    char* e2 = nullptr;
    if (slash != std::string::npos) {
      shard = std::strtol(o.shard.c_str(), &e1, 10);
      shards = std::strtol(o.shard.c_str() + slash + 1, &e2, 10);
    }
    if (slash == std::string::npos || *e2 || e1 != o.shard.c_str() + slash || shards < 1 || shard < 0 || shard >= shards)
      throw InputError(Diagnostic{"--shard", 0, "", fmt::format("'{}'; expected i/N with 0 <= i < N", o.shard)});
  }
  const std::string header = shards > 1 ? fmt::format("# kanegen sweep {} shard {}/{}", id, shard, shards) : "# kanegen sweep " + id;

  int rank = 0, size = 1;
#ifndef KANEGEN_HAVE_MPI
  if (std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMI_SIZE"))
    throw InputError(Diagnostic{"mpirun", 0, "", "this program was built without MPI: every rank would run the whole "
                                                 "sweep; run it alone (--threads N) or in shards (--shard i/N)"});
#endif
#ifdef KANEGEN_HAVE_MPI
  const bool under_mpirun = std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMI_SIZE");
  if (under_mpirun) {
    MPI_Init(nullptr, nullptr);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
  }
  struct Finalize {
    bool on;
    ~Finalize() {
      if (on) MPI_Finalize();
    }
  } finalize{under_mpirun};
#endif

  std::map<long, RunResult> all;
  std::vector<long> todo;
  std::unique_ptr<std::ofstream> log;
  if (rank == 0) {
    fs::create_directories(dir);
    const std::string tsv = (fs::path(dir) / "results.tsv").string();
    all = read_results(tsv, id, false);  // resume: the runs already done
    for (long k = shard; k < spec.runs; k += shards)
      if (!all.count(k)) todo.push_back(k);
    // rewrite what is kept (a cut line dropped), then append as runs finish
    std::string keep = header + "\n";
    for (auto& [k, r] : all) keep += serialize(r) + "\n";
    write_file_atomically(tsv, keep);
    log = std::make_unique<std::ofstream>(tsv, std::ios::app);
    if (!all.empty()) fmt::print(stderr, "resuming: {} runs already done, {} to go\n", all.size(), todo.size());
  }
  SweepProgress progress(static_cast<long>(todo.size() + all.size()), static_cast<long>(all.size()),
                    !o.no_progress && isatty(2) && rank == 0);
  auto record = [&](RunResult&& r) {
    *log << serialize(r) << '\n' << std::flush;
    progress.add(!r.ok());
    all[r.index] = std::move(r);
  };

  if (size == 1) {
    const int threads = o.threads > 0 ? o.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    if (!todo.empty()) run_on_threads(plan, todo, threads, make, record, controller);
    finish_sweep(plan, all, dir, header, progress.seconds(), static_cast<long>(todo.size()));
    return 0;
  }
#ifdef KANEGEN_HAVE_MPI
  // rank 0 hands out run indices one at a time; every other rank runs them
  constexpr int kTagRequest = 1, kTagWork = 2;
  if (rank == 0) {
    (void)make(plan.model);  // compile once into the JIT cache before the workers load it
    MPI_Barrier(MPI_COMM_WORLD);
    std::size_t next = 0;
    int active = size - 1;
    while (active > 0) {
      MPI_Status st;
      MPI_Probe(MPI_ANY_SOURCE, kTagRequest, MPI_COMM_WORLD, &st);
      int len = 0;
      MPI_Get_count(&st, MPI_CHAR, &len);
      std::string msg(static_cast<std::size_t>(len), '\0');
      MPI_Recv(msg.data(), len, MPI_CHAR, st.MPI_SOURCE, kTagRequest, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      if (!msg.empty()) record(deserialize(msg));
      long k = next < todo.size() ? todo[next++] : -1;
      MPI_Send(&k, 1, MPI_LONG, st.MPI_SOURCE, kTagWork, MPI_COMM_WORLD);
      if (k < 0) --active;
    }
    finish_sweep(plan, all, dir, header, progress.seconds(), static_cast<long>(todo.size()));
  } else {
    MPI_Barrier(MPI_COMM_WORLD);
    auto engine = make(plan.model);
    std::string msg;  // the previous result, with each request for work
    for (;;) {
      MPI_Send(msg.data(), static_cast<int>(msg.size()), MPI_CHAR, 0, kTagRequest, MPI_COMM_WORLD);
      long k = -1;
      MPI_Recv(&k, 1, MPI_LONG, 0, kTagWork, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      if (k < 0) break;
      msg = serialize(run_one(*engine, plan, k, nullptr, controller));
    }
  }
#endif
  return 0;
}

/// The sweep's options: SWEEP.yaml, -o, --threads, --run, --shard, --merge, --no-progress.
inline void add_sweep_options(CLI::App* c, SweepCli& o) {
  c->add_option("sweep", o.sweep, "SWEEP.yaml")->required()->check(CLI::ExistingFile);
  o.output_option = c->add_option("-o,--output", o.output, "output directory (default SWEEP.out/); with --run, the run's CSV");
  c->add_option("--threads", o.threads, "threads (default: every core); under mpirun each rank runs one run at a time");
  c->add_option("--run", o.run, "replay one run alone and write its full time history")->check(CLI::Range(0L, 100000000L));
  c->add_option("--shard", o.shard, "i/N: the runs k with k mod N = i (a batch scheduler's job array)");
  c->add_option("--merge", o.merge, "merge the results of shards (their output directories) into -o")->expected(1, -1);
  c->add_flag("--no-progress", o.no_progress, "no progress line on stderr");
}

}  // namespace kanegen::cli
