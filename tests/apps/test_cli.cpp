// The command line as users and outside checks drive it (interface.md):
// exit statuses, messages naming file, line and field, outputs by name.
#include <catch2/catch.hpp>

#include <chrono>
#include <thread>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <cmath>
#include <fmt/format.h>
#include <sys/wait.h>
#include <unistd.h>

#include "engine/load_model.hpp"
#include "tests/support/shell.hpp"
#include "tests/support/test_support.hpp"

namespace fs = std::filesystem;

namespace {

using Run = kanegen::test::ShellRun;  // status, out (stdout and stderr)
using kanegen::test::shell;

Run run(const std::string& args, const std::string& env = "") {
  return shell(env + " " + std::string(kanegen::test::kanegen_binary()) + " " + args);
}

std::string src(const std::string& rel) { return kanegen::test::source_path(rel); }

fs::path temp_dir() {
  const fs::path d = fs::temp_directory_path() / ("kanegen_cli_" + std::to_string(getpid()));
  fs::create_directories(d);
  return d;
}

}  // namespace

TEST_CASE("cli: every subcommand has --help", "[cli]") {
  for (const char* sub : {"check", "eval", "simulate", "generate", "crosscheck", "modes", "linearize", "sweep"}) {
    INFO(sub);
    const Run r = run(std::string(sub) + " --help");
    CHECK(r.status == 0);
    CHECK(r.out.find("Usage") != std::string::npos);
  }
}

TEST_CASE("cli: a refused model exits 2 naming file, line and field", "[cli]") {
  const Run r = run("check " + src("tests/data/bad/axis_zero.yaml"));
  CHECK(r.status == 2);
  CHECK(r.out.find("axis_zero.yaml:") != std::string::npos);
  CHECK(r.out.find(".joint.axis: ") != std::string::npos);
}

TEST_CASE("cli: missing model file, unknown state name, bad option exit 2", "[cli]") {
  CHECK(run("check /nonexistent/model.yaml").status == 2);
  const fs::path d = temp_dir();
  const std::string state = (d / "bad_state.json").string();
  std::ofstream(state) << R"({"q": {"link9.angle": 0.1}})";
  const Run r = run("eval " + src("models/double_pendulum.yaml") + " --engine generic --state " + state);
  CHECK(r.status == 2);
  CHECK(r.out.find("link9.angle") != std::string::npos);
  CHECK(run("simulate " + src("models/pendulum.yaml") + " --t-end 1 -o x.csv --integrator nonsense").status == 2);
  CHECK(run("eval " + src("models/pendulum.yaml") + " --engine nonsense").status == 2);
}

TEST_CASE("cli: eval prints the interface.md document, generated engine by default", "[cli][generated]") {
  const Run r = run("eval " + src("models/double_pendulum.yaml"),
                    "KANEGEN_CACHE_DIR=" + std::string(kanegen::test::jit_cache_dir()));
  REQUIRE(r.status == 0);
  const auto j = nlohmann::json::parse(r.out.substr(r.out.find('{')));
  CHECK(j["engine"] == "generated");
  for (const char* k : {"model", "q_names", "u_names", "q", "u", "qdot", "M", "F", "udot"}) CHECK(j.contains(k));
}

TEST_CASE("cli: simulate writes the CSV columns of interface.md, a failed run leaves no file", "[cli]") {
  const fs::path d = temp_dir();
  const std::string csv = (d / "e1.csv").string();
  const Run r = run("simulate " + src("models/explorer1_rigid.yaml") +
                    " --engine generic --t-end 1 --dt-out 0.5 --no-progress -o " + csv);
  REQUIRE(r.status == 0);
  CHECK(r.out.find("rhs evals") != std::string::npos);  // the summary line
  std::ifstream in(csv);
  std::string header;
  std::getline(in, header);
  CHECK(header.rfind("t,bus.x,bus.y,bus.z,bus.qw,bus.qx,bus.qy,bus.qz,", 0) == 0);
  CHECK(header.find(",T,V,Hx,Hy,Hz,bus.fx,bus.fy,bus.fz,bus.tx,bus.ty,bus.tz") != std::string::npos);
  int rows = 0;
  for (std::string line; std::getline(in, line);) ++rows;
  CHECK(rows == 3);  // t = 0, 0.5, 1

  // A run that cannot finish: a stiff spring (1000 rad/s) under RK4 with a
  // step 10x beyond its stability limit grows until the state overflows.
  const std::string model = (d / "stiff_spring.yaml").string();
  std::ofstream(model) << "name: stiff_spring\nbodies:\n  - name: slider\n    parent: ground\n"
                          "    joint: {type: prismatic, axis: [1, 0, 0], stiffness: 1.0e6}\n    mass: 1.0\n"
                          "initial:\n  q: {slider.disp: 0.1}\n";
  const std::string bad = (d / "bad.csv").string();
  const Run f = run("simulate " + model + " --engine generic --integrator rk4 --h 0.01 --t-end 10 --dt-out 1 --no-progress -o " + bad);
  CHECK(f.status == 1);
  CHECK(f.out.find("t = ") != std::string::npos);
  CHECK_FALSE(fs::exists(bad));
}

TEST_CASE("cli: a compiler failure in the JIT is a clear error with exit 2", "[cli][jit]") {
  const fs::path d = temp_dir() / "empty-cache";
  fs::remove_all(d);
  const Run r = run("eval " + src("models/pendulum.yaml"), "KANEGEN_CACHE_DIR=" + d.string() + " CXX=false");
  CHECK(r.status == 2);
  CHECK(r.out.find("compiling generated code") != std::string::npos);
  CHECK(r.out.find("false") != std::string::npos);  // names the compiler command
}

TEST_CASE("cli: generate writes a header, modes writes a modal file that loads back", "[cli]") {
  const fs::path d = temp_dir();
  const std::string hpp = (d / "dp.hpp").string();
  REQUIRE(run("generate " + src("models/double_pendulum.yaml") + " -o " + hpp).status == 0);
  std::ifstream in(hpp);
  std::string first;
  std::getline(in, first);
  CHECK(first.find("GENERATED") != std::string::npos);
  const std::string modal = (d / "boom.modal.yaml").string();
  CHECK(run("modes " + src("models/spacecraft_arrays.yaml") + " --body boom -o " + modal).status == 0);
  CHECK(fs::exists(modal));
  CHECK(run("modes " + src("models/spacecraft_arrays.yaml") + " --body nosuchbody -o " + modal).status == 2);
}

TEST_CASE("cli: linearize prints A and its modes, writes npz, refuses unknown names", "[cli][linearize]") {
  const fs::path d = temp_dir();
  const std::string state = (d / "hang.json").string();
  std::ofstream(state) << R"({"q": {"bob.angle": 1.5707963267948966}})";
  const Run r = run("linearize " + src("models/pendulum.yaml") + " --state " + state);
  REQUIRE(r.status == 0);
  CHECK(r.out.find("\"equilibrium\": true") != std::string::npos);
  CHECK(r.out.find("-9.81") != std::string::npos);             // A[1][0] = -g/L
  CHECK(r.out.find("0.498488") != std::string::npos);           // sqrt(g/L)/2pi, the modes table
  const std::string npz = (d / "lin.npz").string();
  CHECK(run("linearize " + src("models/pendulum.yaml") + " --state " + state + " --format npz -o " + npz + " --quiet").status == 0);
  const Run py = shell("/usr/bin/python3 -c \"import numpy; z = numpy.load('" + npz +
                       "'); print(z['A'][1][0], list(z['state_names']))\"");
  CHECK(py.out.find("-9.81 ['q.bob.angle', 'u.bob.angle_rate']") != std::string::npos);
  const Run bad = run("linearize " + src("models/pendulum.yaml") + " --inputs nosuch");
  CHECK(bad.status == 2);
  CHECK(bad.out.find("--inputs") != std::string::npos);
  CHECK(run("linearize " + src("models/pendulum.yaml") + " --format mat").status == 2);  // a file format needs -o
  CHECK(!fs::exists(d / "lin.mat"));
}

namespace {

const char* kGimbalPendulum = R"(name: gimbal_pendulum
gravity: [0, 0, -9.81]
bodies:
  - name: bob
    parent: ground
    joint: {type: gimbal, sequence: zyx}
    mass: 1.0
    com: [0, 0, -1.0]
    inertia: [0.01, 0.02, 0.03, 0, 0, 0]
initial:
  q: {bob.angle2: 0.3}
  u: {bob.angle2: 1.0}
)";

}  // namespace

TEST_CASE("cli: gimbal lock is refused at a state and stops a run, naming the joint", "[cli][joints]") {
  const fs::path d = temp_dir();
  const std::string model = kanegen::test::write_temp("gimbal_pendulum.yaml", kGimbalPendulum);
  // zyx locks where the middle angle is +-pi/2
  std::ofstream(d / "locked.json") << R"({"q": {"bob.angle2": 1.5707963267948966}})";
  const Run e = run("eval " + model + " --engine generic --state " + (d / "locked.json").string());
  CHECK(e.status == 2);
  CHECK(e.out.find("locked.json:1: q:") != std::string::npos);
  CHECK(e.out.find("gimbal joint of 'bob' is in gimbal lock") != std::string::npos);
  // a run whose middle angle is driven through pi/2 stops with the time and the state
  std::ofstream(d / "fast.json") << R"({"q": {"bob.angle2": 1.4}, "u": {"bob.angle2_rate": 3.0}})";
  const fs::path csv = d / "gimbal.csv";
  const Run s = run("simulate " + model + " --engine generic --t-end 2 --state " + (d / "fast.json").string() +
                    " -o " + csv.string());
  INFO(s.out);
  CHECK(s.status == 1);
  CHECK(s.out.find("gimbal lock") != std::string::npos);
  CHECK(s.out.find("'bob'") != std::string::npos);
  CHECK(s.out.find("t = ") != std::string::npos);
  CHECK(!fs::exists(csv));
}

TEST_CASE("cli: no CSV header of any model repeats a name, the older speed names are accepted on input", "[cli][joints]") {
  const fs::path d = temp_dir();
  for (const std::string& f : kanegen::test::model_files()) {
    const kanegen::Model m = kanegen::load_model(f);
    std::vector<std::string> names = m.q_names;
    names.insert(names.end(), m.u_names.begin(), m.u_names.end());
    names.insert(names.end(), m.input_names.begin(), m.input_names.end());
    names.insert(names.end(), m.output_names.begin(), m.output_names.end());
    std::sort(names.begin(), names.end());
    INFO(f);
    CHECK(std::adjacent_find(names.begin(), names.end()) == names.end());
  }
  // a short run's header, read back
  const fs::path csv = d / "dp.csv";
  const Run r = run("simulate " + src("models/double_pendulum.yaml") + " --engine generic --t-end 0.01 --dt-out 0.01 -o " +
                    csv.string());
  REQUIRE(r.status == 0);
  std::ifstream in(csv);
  std::string header;
  std::getline(in, header);
  CHECK(header.rfind("t,link1.angle,link2.angle,link1.angle_rate,link2.angle_rate", 0) == 0);
  // STATE.json: the older name means the rate; naming it both ways is refused
  std::ofstream(d / "old.json") << R"({"u": {"link1.angle": 0.5}})";
  std::ofstream(d / "both.json") << R"({"u": {"link1.angle": 0.5, "link1.angle_rate": 0.5}})";
  const Run old = run("eval " + src("models/double_pendulum.yaml") + " --engine generic --state " + (d / "old.json").string());
  REQUIRE(old.status == 0);
  const auto j = nlohmann::json::parse(old.out);
  CHECK(j["u"][0].get<double>() == 0.5);
  CHECK(j["u_names"][0] == "link1.angle_rate");
  const Run both = run("eval " + src("models/double_pendulum.yaml") + " --engine generic --state " + (d / "both.json").string());
  CHECK(both.status == 2);
  CHECK(both.out.find("name the same speed") != std::string::npos);
}

TEST_CASE("cli: a first simulate starts on the generic engine at once, the background build serves the next run",
          "[cli][handover]") {
  const fs::path cache = temp_dir() / "cold-cache";
  fs::remove_all(cache);
  const std::string env = "KANEGEN_CACHE_DIR=" + cache.string();
  const std::string csv = (temp_dir() / "first.csv").string();
  const std::string args = "simulate " + src("models/pendulum.yaml") + " --t-end 1 --no-progress -o " + csv;
  const Run first = run(args, env);
  REQUIRE(first.status == 0);
  CHECK(first.out.find("integrating on the generic engine") != std::string::npos);
  CHECK(first.out.find("[generic engine]") != std::string::npos);
  // the background `kanegen compile` publishes the library (poll up to 5 minutes)
  bool cached = false;
  for (int i = 0; i < 600 && !cached; ++i) {
    if (fs::exists(cache))
      for (const auto& e : fs::directory_iterator(cache))
        if (e.path().extension() == ".json") cached = true;  // the record: written after the library
    if (!cached) std::this_thread::sleep_for(std::chrono::milliseconds(500));
  }
  REQUIRE(cached);
  const Run second = run(args, env);
  REQUIRE(second.status == 0);
  CHECK(second.out.find("integrating on the generic engine") == std::string::npos);
  CHECK(second.out.find("[generated engine]") != std::string::npos);
  // `kanegen compile` of a cached model is a cache hit
  const Run compile = run("compile " + src("models/pendulum.yaml"), env);
  CHECK(compile.status == 0);
  fs::remove_all(cache);
}

TEST_CASE("cli: events: simulate --events writes the events table and two rows at each event, eval takes locked",
          "[cli][locks]") {
  const fs::path d = temp_dir();
  const std::string csv = (d / "sep.csv").string(), events = (d / "sep.events.csv").string();
  const Run r = run("simulate " + src("models/probe_separation.yaml") +
                    " --engine generic --t-end 6 --dt-out 0.5 --no-progress -o " + csv + " --events " + events);
  REQUIRE(r.status == 0);
  CHECK(r.out.find("events (2 fired, 3 segments): eject at t = 5: release plate; separation at t = 5.09") !=
        std::string::npos);
  std::ifstream ev(events);
  std::string line;
  std::getline(ev, line);
  CHECK(line == "t,name,action,bodies,energy_lost");
  std::getline(ev, line);
  CHECK(line == "5,eject,release,plate,0");
  std::getline(ev, line);
  CHECK(line.find(",separation,lock+release,plate probe,") != std::string::npos);
  std::ifstream in(csv);
  int rows = 0;
  for (std::string l; std::getline(in, l);) ++rows;
  CHECK(rows == 1 + 13 + 1 + 2);  // header, the grid 0 ... 6, the second row at 5 s, two at the separation
  // eval at a state with the plate locked: its speed's u-dot is zero, the others the reduced system's
  const std::string state = (d / "locked.json").string();
  std::ofstream(state) << R"({"locked": ["plate", "probe"]})";
  const Run e = run("eval " + src("models/probe_separation.yaml") + " --engine generic --state " + state);
  REQUIRE(e.status == 0);
  const std::size_t at = e.out.find("\"locked\": [");
  REQUIRE(at != std::string::npos);
  CHECK(e.out.find("\"plate\"", at) < e.out.find("]", at));
  CHECK(e.out.find("\"probe\"", at) < e.out.find("]", at));
  // a bad event: exit 2 naming the file, line and field
  const std::string bad = (d / "bad_event.yaml").string();
  std::ofstream(bad) << "name: bad_event\nbodies:\n  - name: a\n    parent: ground\n    mass: 1\n"
                        "    joint: {type: revolute, axis: [0, 0, 1]}\nevents:\n  - {name: e, at: 1, lock: [b]}\n";
  const Run b = run("simulate " + bad + " --t-end 1 -o " + (d / "x.csv").string());
  CHECK(b.status == 2);
  CHECK(b.out.find("bad_event.yaml:8: events[0].lock[0]: no body named 'b'") != std::string::npos);
}

TEST_CASE("cli: every output path is checked before the run, each fault naming its option, nothing written",
          "[cli][outputs]") {
  const fs::path d = temp_dir() / "outputs";
  fs::create_directories(d);
  // a copy of a model with a modal file, so that an overwrite could be seen
  fs::copy_file(src("tests/data/good/flex_hub.yaml"), d / "flex_hub.yaml", fs::copy_options::overwrite_existing);
  fs::copy_file(src("tests/data/good/hub.modal.yaml"), d / "hub.modal.yaml", fs::copy_options::overwrite_existing);
  const std::string model = (d / "flex_hub.yaml").string(), modal = (d / "hub.modal.yaml").string();
  auto slurp = [](const fs::path& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const std::string model_text = slurp(model), modal_text = slurp(modal);
  const std::string csv = (d / "out.csv").string();
  const std::string sim = "simulate " + model + " --engine generic --t-end 2 --dt-out 0.5 --no-progress ";
  struct Case {
    std::string args, option, why;
  };
  const std::vector<Case> cases = {
      {"-o " + csv + " --events " + (d / "no/such/dir/ev.csv").string(), "--events", "does not exist"},
      {"-o " + csv + " --events " + csv, "--events", "-o writes the same file"},
      {"-o " + csv + " --events " + (d / "." / "out.csv").string(), "--events", "-o writes the same file"},
      {"-o " + csv + " --events ''", "--events", "empty output path"},
      {"--events= -o " + csv, "--events", "empty output path"},  // CLI11 alone took -o as --events' value
      {"--output= --events " + (d / "ev.csv").string(), "-o", "empty output path"},
      {"-o " + model, "-o", "it is an input of this command"},
      {"-o " + csv + " --events " + model, "--events", "it is an input of this command"},
      {"-o " + modal, "-o", "it is an input of this command"},
  };
  for (const Case& c : cases) {
    INFO(c.args);
    const Run r = run(sim + c.args);
    INFO(r.out);
    CHECK(r.status == 2);
    CHECK(r.out.find(c.option + ": cannot write") != std::string::npos);
    CHECK(r.out.find(c.why) != std::string::npos);
    CHECK_FALSE(fs::exists(csv));  // refused before the run: nothing written
    CHECK(slurp(model) == model_text);
    CHECK(slurp(modal) == modal_text);
  }
  // linearize -o on its model, and on its state
  const Run lin = run("linearize " + model + " --engine generic -o " + model);
  CHECK(lin.status == 2);
  CHECK(lin.out.find("-o: cannot write") != std::string::npos);
  CHECK(slurp(model) == model_text);
  const Run lin_empty = run("linearize " + model + " --engine generic -o ''");
  CHECK(lin_empty.status == 2);
  CHECK(lin_empty.out.find("-o: cannot write '': empty output path") != std::string::npos);
  // generate's outputs, modes -o on the modal file it reads
  for (const std::string& args :
       {"generate " + model + " -o " + modal, "generate " + model + " -o " + csv + " --entry " + model,
        "generate " + model + " -o " + csv + " --manifest " + csv, "modes " + model + " --body hub -o " + modal}) {
    const Run r = run(args);
    INFO(args << "\n" << r.out);
    CHECK(r.status == 2);
    CHECK(r.out.find("cannot write") != std::string::npos);
    CHECK_FALSE(fs::exists(csv));
    CHECK(slurp(model) == model_text);
    CHECK(slurp(modal) == modal_text);
  }
  // a sweep's output directory and a replayed run's file
  const std::string sweep = (d / "s.yaml").string();
  {
    std::ofstream(sweep) << "model: flex_hub.yaml\nruns: 2\nt_end: 0.5\ndt_out: 0.1\nengine: generic\n"
                            "dispersions:\n  - {parameter: tip.mass, distribution: normal, sigma: 0.01, relative: true}\n"
                            "metrics:\n  - {name: w, column: hub.angle, stat: final}\n";
    std::ofstream(d / "plain.txt") << "x\n";
  }
  struct SweepCase {
    std::string args, why;
  };
  for (const SweepCase& c : std::vector<SweepCase>{
           {"-o " + model, "is not a directory"},
           {"-o " + (d / "plain.txt" / "sub").string(), "is not a directory"},
           {"-o ''", "empty output directory"},
           {"-o " + (d / "out").string() + " --merge " + (d / "out").string(), "shard directory"},
           {"--run 0 -o " + modal, "it is an input of this command"},
           {"--run 0 -o " + sweep, "it is an input of this command"}}) {
    const Run r = run("sweep " + sweep + " --no-progress " + c.args);
    INFO(c.args << "\n" << r.out);
    CHECK(r.status == 2);
    CHECK(r.out.find("-o: cannot write") != std::string::npos);
    CHECK(r.out.find(c.why) != std::string::npos);
    CHECK_FALSE(fs::exists(d / "s.out"));
    CHECK_FALSE(fs::exists(d / "out"));
    CHECK(slurp(model) == model_text);
    CHECK(slurp(modal) == modal_text);
  }
  // the same command with good paths runs and writes both
  const Run ok = run(sim + "-o " + csv + " --events " + (d / "ev.csv").string());
  INFO(ok.out);
  CHECK(ok.status == 0);
  CHECK(fs::exists(csv));
  CHECK(fs::exists(d / "ev.csv"));
  fs::remove_all(d);
}

TEST_CASE("cli: a gimbal oscillating through lock stops at the located crossing, at every --dt-out, in every "
          "integrator and both engines",
          "[cli][joints][events]") {
  // Only the middle angle moves (a principal axis, no coupling): theta(t) =
  // rest + (theta0 - rest) cos(w t), w = sqrt(k / I_yy). det Gamma = cos(theta)
  // reaches 1e-6 at theta* = acos(1e-6), long before the first output row
  // after it (the run used to see lock only as a sign change between rows).
  const double k = 0.5, I_yy = 0.02, rest = 1.67, theta0 = 1.45;
  const std::string model = kanegen::test::write_temp("gimbal_oscillator.yaml", fmt::format(R"(name: gimbal_oscillator
bodies:
  - name: bob
    parent: ground
    joint: {{type: gimbal, sequence: xyz, stiffness: [0, {}, 0], rest: [0, {}, 0]}}
    mass: 1.0
    inertia: [0.01, {}, 0.03, 0, 0, 0]
initial:
  q: {{bob.angle2: {}}}
)", k, rest, I_yy, theta0));
  const double w = std::sqrt(k / I_yy);
  const double t_lock = std::acos((std::acos(1e-6) - rest) / (theta0 - rest)) / w;
  const fs::path csv = temp_dir() / "gimbal_oscillator.csv";
  const std::regex at_re(R"(reached gimbal lock at t = ([0-9.eE+-]+))");
  for (const std::string engine : {"generic", "generated"})
    for (const std::string integrator :
         {"rkf78", "dopri5", "rk4", "cvode-bdf", "cvode-bdf2", "cvode-adams", "arkode-erk", "arkode-dirk"})
      for (const std::string dt_out : {"0.31", "0.01"}) {
        const Run r = run("simulate " + model + " --engine " + engine + " --integrator " + integrator +
                          " --rtol 1e-12 --atol 1e-14 --h 1e-4 --t-end 2 --no-progress --dt-out " + dt_out + " -o " +
                          csv.string());
        INFO(engine << " " << integrator << " --dt-out " << dt_out << "\n" << r.out);
        CHECK(r.status == 1);
        CHECK(r.out.find("gimbal joint of 'bob'") != std::string::npos);
        CHECK(r.out.find("q bob.angle2 = ") != std::string::npos);  // the state there
        std::smatch m;
        REQUIRE(std::regex_search(r.out, m, at_re));
        CHECK(std::abs(std::stod(m[1].str()) - t_lock) < 1e-9);
        CHECK_FALSE(fs::exists(csv));  // nothing written
      }
  // in a sweep, a run that reaches lock is a failed run with its reason (and the time located)
  const fs::path sweep_dir = temp_dir() / "gimbal_sweep";
  fs::remove_all(sweep_dir);
  fs::create_directories(sweep_dir);
  const fs::path sweep = sweep_dir / "s.yaml";
  std::ofstream(sweep) << "model: " << model << "\nruns: 2\nt_end: 2\ndt_out: 0.31\nengine: generic\n"
                       << "integrator: rkf78\nrtol: 1e-12\natol: 1e-14\n"
                       << "dispersions:\n  - {parameter: bob.mass, distribution: normal, sigma: 0.01, relative: true}\n"
                       << "metrics:\n  - {name: a, column: bob.angle2, stat: max}\n";
  const Run sw = run("sweep " + sweep.string() + " --no-progress -o " + (sweep_dir / "out").string());
  INFO(sw.out);
  CHECK(sw.status == 0);
  std::ifstream runs(sweep_dir / "out" / "runs.csv");
  std::string header, line;
  std::getline(runs, header);
  int failed = 0;
  while (std::getline(runs, line)) {
    INFO(line);
    CHECK(line.find("gimbal lock") != std::string::npos);
    std::smatch m;
    REQUIRE(std::regex_search(line, m, at_re));
    CHECK(std::abs(std::stod(m[1].str()) - t_lock) < 1e-9);  // the mass moves neither k nor I_yy
    ++failed;
  }
  CHECK(failed == 2);
  fs::remove_all(sweep_dir);
}

TEST_CASE("cli: check in orbit prints the period, perigee and apogee, locks and events, warns (exit 0) of an angle "
          "in degrees, mu in km^3/s^2, a perigee below the radius, refuses a mass at the attracting centre",
          "[cli][central]") {
  const double mu = 3.986004418e14, a = 6.978137e6, pi = 3.14159265358979323846;
  const Run gg = run("check " + src("models/gravity_gradient_boom.yaml"));
  INFO(gg.out);
  REQUIRE(gg.status == 0);
  CHECK(gg.out.find(fmt::format("period {:.6g} s", 2 * pi * std::sqrt(a * a * a / mu))) != std::string::npos);
  CHECK(gg.out.find(fmt::format("perigee altitude {:.6g} km, apogee altitude {:.6g} km", (a - 6378137.0) / 1e3,
                                (a - 6378137.0) / 1e3)) != std::string::npos);
  CHECK(gg.out.find("warning") == std::string::npos);
  const Run dep = run("check " + src("models/array_deployment.yaml"));
  CHECK(dep.out.find("event release: at t = 10 s, releases wing_a, wing_b") != std::string::npos);
  CHECK(dep.out.find("event latch_a: when wing_a.angle reaches 1.570796327, locks wing_a") != std::string::npos);

  const fs::path d = temp_dir();
  auto model = [&](const std::string& gravity, const std::string& orbit) {
    const fs::path p = d / "orbit_check.yaml";
    std::ofstream(p) << "name: orbit_check\ngravity:\n  central: " << gravity << R"(
bodies:
  - {name: bus, parent: ground, joint: {type: free}, mass: 100.0, inertia: [16, 20, 14, 0, 0, 0]}
)" << (orbit.empty() ? "" : "initial:\n  orbit: " + orbit + "\n");
    return run("check " + p.string());
  };
  struct Case {
    std::string gravity, orbit, field, says;
  };
  for (const Case& c : std::vector<Case>{
           {"{mu: 3.986004418e14}", "{a: 7.0e6, e: 0.0, i: 98.2}", "orbit_check.yaml:7: initial.orbit.i",
            "98.2 rad is outside [0, pi]; angles are in radians (98.2 degrees would be 1.71391 rad)"},
           {"{mu: 3.986004418e14}", "{a: 7.0e6, e: 0.0, raan: 270.0}", "initial.orbit.raan", "outside [-2 pi, 2 pi]"},
           {"{mu: 398600.4418}", "{a: 7.0e6, e: 0.0}", "orbit_check.yaml:7: initial.orbit.a",
            "looks like mixed units: that mu is the GM of the Earth in km^3/s^2"},
           {"{mu: 3.986004418e14, J2: 1.08e-3, radius: 6378137.0}", "{a: 6.6e6, e: 0.1}", "initial.orbit.a",
            "the perigee a (1 - e) = 5.94e+06 m is below the central body's radius 6.37814e+06 m"},
           {"{mu: 3.986004418e14}", "{a: 6978.0, e: 0.0}", "initial.orbit.a", "a looks like kilometres"}}) {
    const Run r = model(c.gravity, c.orbit);
    INFO(c.orbit << "\n" << r.out);
    CHECK(r.status == 0);
    CHECK(r.out.find("warning: ") != std::string::npos);
    CHECK(r.out.find(c.field) != std::string::npos);
    CHECK(r.out.find(c.says) != std::string::npos);
  }
  // in a central field without an orbit the bus starts at N's origin: refused by every command, naming the body
  const Run at_centre = model("{mu: 3.986004418e14}", "");
  INFO(at_centre.out);
  CHECK(at_centre.status == 2);
  CHECK(at_centre.out.find("orbit_check.yaml:5: bodies[0]: the centre of mass of 'bus' is at the attracting centre") !=
        std::string::npos);
  for (const std::string& cmd : std::vector<std::string>{"eval", "simulate --t-end 1 -o " + (d / "never.csv").string()}) {
    const Run r = run(cmd + " " + (d / "orbit_check.yaml").string() + " --engine generic");
    INFO(r.out);
    CHECK(r.status == 2);
    CHECK(r.out.find("is at the attracting centre") != std::string::npos);
  }
  CHECK(!fs::exists(d / "never.csv"));
}
