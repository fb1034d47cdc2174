// Hostile input and faults, one class at a time (docs/limits.md): no crash,
// no silent accept, nothing half-written, every refusal located. The fuzz
// test (tests/apps/fuzz_inputs.py) covers the same classes at random.
#include <catch2/catch.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <signal.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>

#include "tests/support/test_support.hpp"

namespace fs = std::filesystem;

namespace {

struct HostileRun {
  int status;       ///< exit status, or 128 + signal
  std::string out;  ///< stdout and stderr
};

HostileRun run_hostile(const std::string& args) {
  const std::string cmd = std::string(kanegen::test::kanegen_binary()) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  char buf[4096];
  for (std::size_t n; (n = fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
  const int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st), out};
}

/// A fresh directory for one test.
std::string write(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
  return p.string();
}

std::string model(const std::string& rel) { return kanegen::test::source_path(rel); }

/// Every line of a refusal is "file:line: field: message" or "option: message"
/// (the field of a fault in the text is its column; of the whole file, "(document)").
bool located(const std::string& out) {
  static const std::regex file_line(R"(^[^:\n]+:[1-9][0-9]*: [^:\n]+: .+)");
  static const std::regex option(R"(^(--[a-z-]+|-o|MODEL): .+)");
  std::istringstream in(out);
  int lines = 0;
  for (std::string l; std::getline(in, l);) {
    if (l.empty()) continue;
    ++lines;
    if (!std::regex_match(l, file_line) && !std::regex_match(l, option)) {
      UNSCOPED_INFO("not located: " << l);
      return false;
    }
  }
  return lines > 0;
}

const char* kDp = "models/double_pendulum.yaml";

}  // namespace

TEST_CASE("hostile: deep nesting in a state or a model is refused, located, without a crash", "[hostile]") {
  const fs::path d = kanegen::test::scratch_dir("hostile", "nesting");
  std::string deep = "{\"q\": " + std::string(100000, '[') + std::string(100000, ']') + "}";
  HostileRun r = run_hostile(fmt::format("eval {} --engine generic --state {}", model(kDp), write(d / "s.json", deep)));
  CHECK(r.status == 2);
  CHECK(located(r.out));
  CHECK(r.out.find("nested deeper") != std::string::npos);
  std::string yaml = "name: x\nbodies: " + std::string(100000, '[') + std::string(100000, ']') + "\n";
  r = run_hostile("check " + write(d / "m.yaml", yaml));
  CHECK(r.status == 2);
  CHECK(located(r.out));
  // block nesting ("- - - - ...") is bounded by the YAML parser's depth guard
  std::string block = "name: x\nbodies:\n  ";
  for (int i = 0; i < 5000; ++i) block += "- ";
  r = run_hostile("check " + write(d / "b.yaml", block + "x\n"));
  CHECK(r.status == 2);
  CHECK(located(r.out));
}

TEST_CASE("hostile: a second YAML document, or content after '...', is refused", "[hostile]") {
  const fs::path d = kanegen::test::scratch_dir("hostile", "documents");
  std::ifstream in(model(kDp));
  std::stringstream ss;
  ss << in.rdbuf();
  for (const std::string tail : {"---\nname: other\n", "...\nname: other\n", "--- {name: other}\n"}) {
    const HostileRun r = run_hostile("check " + write(d / "m.yaml", ss.str() + tail));
    INFO(tail << r.out);
    CHECK(r.status == 2);
    CHECK(r.out.find("second YAML document") != std::string::npos);
    CHECK(located(r.out));
  }
  // a document end with only comments after it is fine
  CHECK(run_hostile("check " + write(d / "ok.yaml", ss.str() + "...\n# the end\n")).status == 0);
}

TEST_CASE("hostile: STATE.json faults name the file, the line and the field", "[hostile]") {
  const fs::path d = kanegen::test::scratch_dir("hostile", "state");
  const std::string m = model("models/explorer1_rigid.yaml");
  struct Case {
    std::string json, field, text;
  };
  const Case cases[] = {
      {"{\n \"q\": {\"ant1.angle\": 0.1,\n  \"ant1.angle\": 0.2}}", ":3: q.ant1.angle:", "given twice (also on line 2)"},
      {"{\n \"q\": {\n  \"bus.qw\": 1, \"bus.qx\": 0}}", ":3: q.bus.qw:", "given in part"},
      {"{\n \"u\": {\"nosuch\": 1}}", ":2: u.nosuch:", "unknown name"},
      {"{\n \"u\": {\"bus.wx\": \"fast\"}}", ":2: u.bus.wx:", "expected a number"},
      {"{\n \"u\": {\"bus.wx\": 1e400}}", ":2: u.bus.wx:", "out of the range"},
      {"{\n \"t\": [1]}", ":2: t:", "expected a number"},
      {"{\n \"speed\": 1}", ":2: speed:", "unknown key"},
      {"[1, 2]", ":1: ", "expected a JSON object"},
      {"{\"q\": {}} trailing", ":1: ", "content after"},
      {"{\n\n \"q\": {\"bus.qw\": 0, \"bus.qx\": 0, \"bus.qy\": 0, \"bus.qz\": 0}}", ":3: q.bus.qw:", "is zero"},
  };
  for (const Case& c : cases) {
    const HostileRun r = run_hostile(fmt::format("eval {} --engine generic --state {}", m, write(d / "s.json", c.json)));
    INFO(c.json << "\n-> " << r.out);
    CHECK(r.status == 2);
    CHECK(r.out.find("s.json" + c.field) != std::string::npos);
    CHECK(r.out.find(c.text) != std::string::npos);
    CHECK(located(r.out));
  }
}

TEST_CASE("hostile: a quaternion of tiny or huge but non-zero norm is normalized", "[hostile]") {
  const fs::path d = kanegen::test::scratch_dir("hostile", "quaternion");
  const std::string m = model("models/explorer1_rigid.yaml");
  for (const char* v : {"5e-324", "1e-160", "1e200", "1.7e308"}) {
    const std::string json = fmt::format("{{\"q\": {{\"bus.qw\": {0}, \"bus.qx\": {0}, \"bus.qy\": 0, \"bus.qz\": 0}}}}", v);
    const HostileRun r = run_hostile(fmt::format("eval {} --engine generic --state {}", m, write(d / "s.json", json)));
    INFO(v << ": " << r.out);
    REQUIRE(r.status == 0);
    const auto q = nlohmann::json::parse(r.out)["q"];
    CHECK(q[3].get<double>() == Approx(std::sqrt(0.5)).epsilon(1e-15));
    CHECK(q[4].get<double>() == Approx(std::sqrt(0.5)).epsilon(1e-15));
  }
}

TEST_CASE("hostile: a non-finite result is a failure naming the quantity, never null", "[hostile]") {
  const fs::path d = kanegen::test::scratch_dir("hostile", "nonfinite");
  HostileRun r = run_hostile(fmt::format("eval {} --engine generic --state {}", model(kDp),
                          write(d / "s.json", "{\"u\": {\"link1.angle\": 1e200}}")));
  CHECK(r.status == 1);
  CHECK(r.out.find("null") == std::string::npos);
  CHECK(r.out.find("link1.angle") != std::string::npos);
  CHECK(r.out.find("at the state") != std::string::npos);
  std::ifstream in(model(kDp));
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  text.replace(text.find("gravity: [0, 0, -9.81]"), 22, "gravity: [0, 0, -1.7e308]");
  r = run_hostile(fmt::format("eval {} --engine generic", write(d / "m.yaml", text)));
  CHECK(r.status == 1);
  CHECK(r.out.find("null") == std::string::npos);
}

TEST_CASE("hostile: integers are decimal everywhere, names printable, CR line breaks read", "[hostile]") {
  const fs::path d = kanegen::test::scratch_dir("hostile", "syntax");
  // node id 010 is ten in the modal file and in the model
  write(d / "h.modal.yaml",
        "nodes:\n  - {id: 0, position: [0, 0, 0], mass: 0}\n  - {id: 010, position: [1, 0, 0], mass: 1}\n"
        "modes:\n  - frequency: 2\n    shapes: {0: [0,0,0,0,0,0], 10: [0,1,0,0,0,0]}\n");
  const std::string m = write(d / "m.yaml",
                              "name: dec\nbodies:\n  - name: hub\n    parent: ground\n    joint: {type: revolute, axis: "
                              "[0, 0, 1]}\n    flexible: {modal: h.modal.yaml}\n  - name: tip\n    parent: hub\n"
                              "    joint: {type: revolute, node: 10, axis: [0, 1, 0]}\n    mass: 0.1\n"
                              "    inertia: [0.001, 0.001, 0.001, 0, 0, 0]\n");
  HostileRun r = run_hostile("check " + m);
  INFO(r.out);
  CHECK(r.status == 0);
  // control characters and invalid UTF-8 in a name are refused with the line
  r = run_hostile("check " + write(d / "c.yaml", "name: a\x01" "b\nbodies: []\n"));
  CHECK(r.status == 2);
  CHECK(r.out.find("c.yaml:1:") != std::string::npos);
  r = run_hostile("check " + write(d / "u.yaml", "name: ok\nbodies:\n  - name: \xff\xfe\n"));
  CHECK(r.status == 2);
  CHECK(r.out.find("u.yaml:3:") != std::string::npos);
  CHECK(r.out.find("UTF-8") != std::string::npos);
  // an escaped line break in the description would end the header's comment line: refused
  r = run_hostile("check " + write(d / "e.yaml", std::string("name: ok\ndescription: \"a\\nb\"\n") +
                                             "bodies:\n  - {name: b, parent: ground, joint: {type: revolute, axis: "
                                             "[0,0,1]}, mass: 1, com: [1,0,0]}\n"));
  CHECK(r.status == 2);
  CHECK(located(r.out));
  // CR-only and CRLF line breaks read like LF
  std::ifstream in(model(kDp));
  std::stringstream ss;
  ss << in.rdbuf();
  std::string cr = ss.str(), crlf;
  for (char& c : cr)
    if (c == '\n') c = '\r';
  for (char c : ss.str()) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  CHECK(run_hostile("check " + write(d / "cr.yaml", cr)).status == 0);
  CHECK(run_hostile("check " + write(d / "crlf.yaml", crlf)).status == 0);
  // a 300-character model name is valid (cache file names stay short)
  std::string text = ss.str();
  text.replace(text.find("name: double_pendulum"), 21, "name: " + std::string(300, 'n'));
  r = run_hostile(fmt::format("eval {}", write(d / "long.yaml", text)));
  INFO(r.out.substr(0, 300));
  CHECK(r.status == 0);
}

TEST_CASE("hostile: every command-line value is checked against its domain up front", "[hostile]") {
  const fs::path d = kanegen::test::scratch_dir("hostile", "options");
  const std::string m = model(kDp), out = (d / "o.csv").string();
  struct Case {
    std::string args, option;
  };
  const Case cases[] = {
      {"--t-end 1 --integrator rk4 --h 0", "--h"},       {"--t-end 1 --rtol -1", "--rtol"},
      {"--t-end 1 --rtol nan", "--rtol"},                {"--t-end 1 --atol 0", "--atol"},
      {"--t-end inf", "--t-end"},                        {"--t-end 1 --dt-out inf", "--dt-out"},
      {"--t-end 1e308 --dt-out 0.01", "--dt-out"},       {"--t-end 1 --integrator euler", "--integrator"},
      {"--t-end 1 --max-steps 0", "--max-steps"},
  };
  for (const Case& c : cases) {
    const HostileRun r = run_hostile(fmt::format("simulate {} --engine generic {} -o {}", m, c.args, out));
    INFO(c.args << " -> " << r.out);
    CHECK(r.status == 2);
    CHECK(r.out.rfind(c.option + ":", 0) == 0);
    CHECK_FALSE(fs::exists(out));
  }
  // the rows a huge horizon would write are said
  const HostileRun rows = run_hostile(fmt::format("simulate {} --engine generic --t-end 1e308 --dt-out 0.01 -o {}", m, out));
  CHECK(rows.out.find("rows") != std::string::npos);
  // an unwritable output: a missing directory, a directory, a FIFO, a symlink, a device
  const fs::path fifo = d / "fifo";
  REQUIRE(mkfifo(fifo.c_str(), 0644) == 0);
  fs::create_symlink(d / "target.csv", d / "link.csv");
  for (const fs::path& bad : {d / "missing" / "o.csv", d, fifo, d / "link.csv", fs::path("/dev/null")}) {
    const HostileRun r = run_hostile(fmt::format("simulate {} --engine generic --t-end 1 -o {}", m, bad.string()));
    INFO(bad << " -> " << r.out);
    CHECK(r.status == 2);
    CHECK(r.out.find(bad.string()) != std::string::npos);
  }
  CHECK(fs::is_fifo(fifo));
  CHECK(fs::is_symlink(d / "link.csv"));
  CHECK_FALSE(fs::exists(d / "target.csv"));
  // generate onto a directory, and next to a user's own x.hpp.tmp
  CHECK(run_hostile(fmt::format("generate {} -o {}", m, d.string())).status == 2);
  // every output option is checked before any work, and named
  const HostileRun dep = run_hostile(fmt::format("generate {} -o {} --depfile {}", m, (d / "p.hpp").string(),
                                  (d / "missing" / "p.d").string()));
  CHECK(dep.status == 2);
  CHECK(dep.out.rfind("--depfile: cannot write", 0) == 0);
  CHECK_FALSE(fs::exists(d / "p.hpp"));
  const HostileRun modes = run_hostile(fmt::format("modes {} --body boom -o {}", model("models/boom_fea.yaml"), d.string()));
  CHECK(modes.status == 2);
  CHECK(modes.out.rfind("-o: cannot write", 0) == 0);
  write(d / "x.hpp.tmp", "mine");
  CHECK(run_hostile(fmt::format("generate {} -o {}", m, (d / "x.hpp").string())).status == 0);
  std::ifstream mine(d / "x.hpp.tmp");
  std::string kept;
  std::getline(mine, kept);
  CHECK(kept == "mine");
}

TEST_CASE("hostile: an interrupted or killed simulate leaves nothing behind", "[hostile][signals]") {
  for (const int sig : {SIGINT, SIGTERM, SIGKILL}) {
    INFO("signal " << sig);
    const fs::path d = kanegen::test::scratch_dir("hostile", fmt::format("signal{}", sig));
    const std::string out = (d / "run.csv").string();
    const pid_t pid = fork();
    REQUIRE(pid >= 0);
    if (pid == 0) {
      const std::string m = model("models/explorer1_rigid.yaml");
      execl(kanegen::test::kanegen_binary(), kanegen::test::kanegen_binary(), "simulate", m.c_str(), "--engine", "generic", "--t-end", "100000",
            "--dt-out", "0.1", "--no-progress", "-o", out.c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    // wait until the run is under way (it writes rows into its unnamed file)
    std::this_thread::sleep_for(std::chrono::milliseconds(700));
    REQUIRE(kill(pid, sig) == 0);
    int status = 0;
    REQUIRE(waitpid(pid, &status, 0) == pid);
    CHECK(WIFSIGNALED(status));
    std::vector<std::string> left;
    for (const auto& e : fs::directory_iterator(d)) left.push_back(e.path().filename().string());
    INFO(left.size() << " files left");
    CHECK(left.empty());
  }
}

TEST_CASE("hostile: a full disk leaves no file and exits 1", "[hostile][disk]") {
  const fs::path d = kanegen::test::scratch_dir("hostile", "fulldisk");
  if (geteuid() != 0 || mount("tmpfs", d.c_str(), "tmpfs", 0, "size=64k") != 0) {
    WARN("cannot mount a small tmpfs here (needs root and mount permission): full-disk test skipped");
    return;
  }
  struct Unmount {
    fs::path p;
    ~Unmount() { umount(p.c_str()); }
  } unmount{d};
  const std::string out = (d / "big.csv").string();
  const HostileRun r = run_hostile(fmt::format("simulate {} --engine generic --t-end 100 --dt-out 0.001 -o {}",
                                model("models/explorer1_rigid.yaml"), out));
  INFO(r.out);
  CHECK(r.status == 1);
  CHECK(r.out.find("write failed") != std::string::npos);
  CHECK(fs::is_empty(d));
  // generate and modes on the full disk too
  const HostileRun g = run_hostile(fmt::format("generate {} -o {}", model("models/spacecraft_arrays.yaml"), (d / "h.hpp").string()));
  CHECK(g.status == 1);
  CHECK(fs::is_empty(d));
  const fs::path w = kanegen::test::scratch_dir("hostile", "fulldisk-model");
  const std::string beam = write(w / "beam.yaml",
                                 "name: beam\nbodies:\n  - name: b\n    parent: ground\n    joint: {type: fixed}\n"
                                 "    flexible:\n      beam: {length: 2, direction: x, mass_per_length: 0.5, "
                                 "EI: [20, 30], elements: 200, modes: 20}\n");
  const HostileRun m = run_hostile(fmt::format("modes {} --body b -o {}", beam, (d / "b.modal.yaml").string()));
  INFO(m.out);
  CHECK(m.status == 1);
  CHECK(fs::is_empty(d));
  // a depfile on a disk with no room left: exit 1, no 0-byte file
  {
    std::ofstream filler(d / "filler", std::ios::binary);
    const std::string block(4096, 'x');
    for (int i = 0; i < 64 && filler.write(block.data(), block.size()); ++i) {
    }
  }
  const HostileRun dep = run_hostile(fmt::format("generate {} -o {} --depfile {}", model("models/pendulum.yaml"),
                                  (w / "p.hpp").string(), (d / "p.d").string()));
  INFO(dep.out);
  CHECK(dep.status == 1);
  CHECK_FALSE(fs::exists(d / "p.d"));
}

TEST_CASE("hostile: the limits are checked before allocating, and what is allowed runs quickly", "[hostile][limits]") {
  const fs::path d = kanegen::test::scratch_dir("hostile", "limits");
  // a 3-node modal file with 20,000 modes
  std::string modal = "nodes:\n  - {id: 1, position: [0,0,0], mass: 0}\n  - {id: 2, position: [1,0,0], mass: 1}\n"
                      "  - {id: 3, position: [2,0,0], mass: 1}\nmodes:\n";
  for (int i = 0; i < 20000; ++i)
    modal += fmt::format("  - {{frequency: {}, shapes: {{1: [0,0,0,0,0,0], 2: [0,0.6,0,0,0,0], 3: [0,0.8,0,0,0,0]}}}}\n",
                         i + 1);
  write(d / "many.modal.yaml", modal);
  const std::string flexible = "name: many\nbodies:\n  - name: b\n    parent: ground\n    joint: {type: revolute, axis: "
                               "[0,0,1]}\n    flexible: {modal: many.modal.yaml}\n";
  HostileRun r = run_hostile("check " + write(d / "many.yaml", flexible));
  CHECK(r.status == 2);
  CHECK(r.out.find("at most 2000 modes") != std::string::npos);
  CHECK(located(r.out));
  // a beam at the 2,000-element maximum is fine, one more is refused
  auto beam = [&](int elements) {
    return write(d / "beam.yaml",
                 fmt::format("name: beam\nbodies:\n  - name: b\n    parent: ground\n    joint: {{type: fixed}}\n"
                             "    flexible:\n      beam: {{length: 2, direction: x, mass_per_length: 0.5, EI: [20, 30], "
                             "elements: {}, modes: 4}}\n",
                             elements));
  };
  r = run_hostile("check " + beam(2000));
  CHECK(r.status == 0);
  r = run_hostile("check " + beam(2001));
  CHECK(r.status == 2);
  CHECK(r.out.find("1..2000") != std::string::npos);
}

TEST_CASE("hostile: a singular mass matrix at the initial state names the speed, the bodies and the line",
          "[hostile]") {
  const fs::path d = kanegen::test::scratch_dir("hostile", "singular");
  const HostileRun r = run_hostile("check " + write(d / "g.yaml", R"(name: gimbal
bodies:
  - name: base
    parent: ground
    joint: {type: revolute, axis: [0, 0, 1]}
    mass: 1
    com: [0.5, 0, 0]
    inertia: [0.01, 0.01, 0.01, 0, 0, 0]
  - name: ring
    parent: base
    joint: {type: revolute, axis: [1, 0, 0], position: [1, 0, 0]}
    mass: 0
  - name: bob
    parent: ring
    joint: {type: revolute, axis: [1, 0, 0]}
    mass: 1
)"));
  INFO(r.out);
  CHECK(r.status == 2);
  CHECK(r.out.find("g.yaml:9: bodies[1] (ring):") != std::string::npos);
  CHECK(r.out.find("'ring.angle_rate'") != std::string::npos);
  CHECK(r.out.find("ring, bob") != std::string::npos);
}

TEST_CASE("hostile: a modal node that is not a mapping is refused, the shapes stay aligned with the nodes",
          "[hostile]") {
  // found by tests/apps/fuzz_inputs.py: the shapes were indexed by the node's
  // place in the file while the faulty node was left out (a heap overflow)
  const fs::path d = kanegen::test::scratch_dir("hostile", "modalnode");
  std::ifstream in(model("models/fea/boom.modal.yaml"));
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  const std::size_t at = text.find("  - {id: 11,");
  REQUIRE(at != std::string::npos);
  text.replace(at, text.find('\n', at) - at, "  - 7");
  fs::create_directories(d / "fea");
  write(d / "fea" / "boom.modal.yaml", text);
  std::ifstream min(model("models/boom_fea.yaml"));
  std::stringstream ms;
  ms << min.rdbuf();
  const HostileRun r = run_hostile("check " + write(d / "boom_fea.yaml", ms.str()));
  INFO(r.out);
  CHECK(r.status == 2);
  CHECK(r.out.find("nodes[10]: got '7'; expected a mapping") != std::string::npos);
  CHECK(located(r.out));
}
