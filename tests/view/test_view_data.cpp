// `kanegen view`'s data (view/view_data; issue 37): the poses, joint frames and
// node positions in the page's data equal what kanegen's kinematics give at
// the same rows of a run, to 1e-12, for a rigid, a flexible (foreshortening
// on: the nodes checked against rho + Phi eta + 1/2 gamma(eta) written out
// here), a multi-dof-joint and an orbiting model; the frames kept from a long
// run; bad input refused with file and field, nothing written.
#include <catch2/catch.hpp>

#include <fmt/format.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "dynamics/body_terms.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/sensors.hpp"
#include "dynamics/workspace.hpp"
#include "engine/load_model.hpp"
#include "model/diagnostics.hpp"
#include "model/orbit.hpp"
#include "model/rotation.hpp"
#include "model/state_io.hpp"
#include "sim/mass_properties.hpp"
#include "tests/support/shell.hpp"
#include "tests/support/test_support.hpp"
#include "view/run_table.hpp"
#include "view/view_data.hpp"

using namespace kanegen;
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

/// R of a pose's quaternion [.., qw, qx, qy, qz] at `at`.
Mat3 pose_R(const json& p, std::size_t at) {
  return quat_to_R<double>(Eigen::Vector4d(p[at + 3].get<double>(), p[at + 4].get<double>(), p[at + 5].get<double>(),
                                           p[at + 6].get<double>()));
}
Vec3 pose_p(const json& p, std::size_t at) {
  return Vec3(p[at].get<double>(), p[at + 1].get<double>(), p[at + 2].get<double>());
}

/// Every frame of view_data for a short generic run of `model_rel` against the kinematics at its row.
void check_view_against_kinematics(const std::string& model_rel, double t_end, double dt) {
  const fs::path d = test::scratch_dir("view", fs::path(model_rel).stem().string());
  const std::string model_path = test::source_path(model_rel), csv = (d / "run.csv").string();
  const test::ShellRun sim = test::run_kanegen(fmt::format("simulate {} --engine generic --t-end {} --dt-out {} "
                                                           "--no-progress -o {}",
                                                           model_path, t_end, dt, csv));
  INFO(sim.out);
  REQUIRE(sim.status == 0);
  const Model model = load_model(model_path);
  const RunTable run = read_run_table(csv);
  ViewOptions vo;
  vo.frames = 7;  // fewer than the rows: the decimation's row mapping is what is checked
  const json data = view_data(model, &run, vo);
  const std::vector<int> cols = state_columns(run, model);
  const std::vector<int> rows = data["rows"].get<std::vector<int>>();
  REQUIRE(rows.size() == data["t"].size());
  REQUIRE(rows.size() >= 7);
  Workspace<double> ws(model);
  double worst_p = 0, worst_R = 0, worst_node = 0;
  std::size_t orbit_frames = 0;
  for (std::size_t f = 0; f < rows.size(); ++f) {
    const int r = rows[f];
    CHECK(data["t"][f].get<double>() == run.rows(r, 0));
    const State st = run_state(run, model, cols, r);
    compute_kinematics(model, ws, st.t, st.q, st.u);
    if (model.central) {  // the centre of mass and its LVLH frame
      compute_body_terms(model, ws);
      const OrbitState c = system_centre_of_mass(model, ws);
      const json& o = data["orbit"];
      worst_p = std::max(worst_p, (pose_p(o["com_N"][f], 0) - c.r_N).norm() / c.r_N.norm());
      const json& qL = o["quat_NL"][f];
      const Mat3 R_NL = quat_to_R<double>(Eigen::Vector4d(qL[0].get<double>(), qL[1].get<double>(), qL[2].get<double>(),
                                                          qL[3].get<double>()));
      worst_R = std::max(worst_R, (R_NL - lvlh_frame(c)).cwiseAbs().maxCoeff());
      ++orbit_frames;
    }
    const json& P = data["poses"][f];
    const json& J = data["joints"][f];
    for (std::size_t i = 0; i < model.bodies.size(); ++i) {
      const Body& b = model.bodies[i];
      const BodyWorkspace<double>& s = ws.body[i];
      const double scale = std::max(1.0, s.r_NO_N.norm());
      worst_p = std::max(worst_p, (pose_p(P, 7 * i) - s.r_NO_N).norm() / scale);
      worst_R = std::max(worst_R, (pose_R(P, 7 * i) - s.R_NB).cwiseAbs().maxCoeff());
      const Mat3 R_NP = b.parent >= 0 ? ws.body[b.parent].R_NB : Mat3::Identity();
      const Vec3 r_NP = b.parent >= 0 ? ws.body[b.parent].r_NO_N : Vec3::Zero();
      worst_p = std::max(worst_p, (pose_p(J, 7 * i) - (r_NP + R_NP * s.p_PJ_P)).norm() / scale);
      worst_R = std::max(worst_R, (pose_R(J, 7 * i) - R_NP * s.R_PJ).cwiseAbs().maxCoeff());
      if (!b.flex) {
        CHECK(data["nodes"][f][i].empty());
        continue;
      }
      // node k: r_NO + R_NB (rho_k + Phi_k eta + 1/2 [eta^T Gamma_k^a eta]_a), written out here
      const FlexibleData& fl = *b.flex;
      const json& X = data["nodes"][f][i];
      REQUIRE(X.size() == 3 * fl.nodes.size());
      for (std::size_t k = 0; k < fl.nodes.size(); ++k) {
        Vec3 s_k = fl.nodes[k].rho_B + fl.Phi.middleRows<3>(3 * k) * s.eta;
        for (int a = 0; a < 3; ++a)
          if (fl.has_second_order(static_cast<int>(k)) && fl.Gamma[k][a].size())
            s_k(a) += 0.5 * s.eta.dot(fl.Gamma[k][a] * s.eta);
        const Vec3 x = s.r_NO_N + s.R_NB * s_k;
        worst_node = std::max(worst_node, (pose_p(X, 3 * k) - x).norm() / scale);
      }
    }
  }
  INFO(fmt::format("{}: {} frames; worst position {:.2e}, rotation {:.2e}, node {:.2e}", model_rel, rows.size(), worst_p,
                   worst_R, worst_node));
  CHECK(worst_p <= 1e-12);
  CHECK(worst_R <= 1e-12);
  CHECK(worst_node <= 1e-12);
  CHECK(orbit_frames == (model.central ? rows.size() : 0));
  CHECK(data.contains("orbit") == model.central.has_value());
  // the whole spacecraft's mass properties at the first frame, as kanegen check prints them
  {
    const SystemMassProperties mp = system_mass_properties(model, run_state(run, model, cols, rows[0]));
    CHECK(data["mass_properties"]["mass"].get<double>() == mp.mass);
    CHECK((pose_p(data["mass_properties"]["com_N"], 0) - mp.com_N).norm() == 0.0);
  }
  fs::remove_all(d);
}

}  // namespace

TEST_CASE("view: the page's poses, joint frames and nodes are kanegen's kinematics at the same rows, to 1e-12",
          "[view]") {
  SECTION("rigid") { check_view_against_kinematics("models/double_pendulum.yaml", 1.0, 0.05); }
  SECTION("flexible, foreshortening on") { check_view_against_kinematics("models/explorer1.yaml", 0.2, 0.01); }
  SECTION("multi-dof joints") { check_view_against_kinematics("models/gimbaled_spacecraft.yaml", 1.0, 0.05); }
  SECTION("in orbit") { check_view_against_kinematics("models/gravity_gradient_boom.yaml", 60.0, 2.0); }
}

TEST_CASE("view: the frames kept from a long run: evenly in time, the first and last rows, both rows of each event",
          "[view]") {
  RunTable run;
  run.path = "synthetic.csv";
  run.names = {"t"};
  const int n = 1001;
  run.rows.resize(n + 1, 1);
  for (int r = 0, k = 0; r <= n; ++r, ++k) {
    run.rows(r, 0) = 0.01 * k;
    if (r == 300) {  // an event at t = 3.00: a second row at the same time
      ++r;
      run.rows(r, 0) = 0.01 * k;
    }
  }
  const std::vector<int> rows = view_rows(run, 50);
  CHECK(rows.front() == 0);
  CHECK(rows.back() == n);
  CHECK(std::count(rows.begin(), rows.end(), 300) == 1);
  CHECK(std::count(rows.begin(), rows.end(), 301) == 1);
  CHECK(rows.size() <= 52);
  CHECK(rows.size() >= 48);
  for (std::size_t i = 1; i < rows.size(); ++i) CHECK(rows[i] > rows[i - 1]);
  // every kept time within half a spacing of an even grid point, the gaps never more than twice the spacing
  for (std::size_t i = 1; i < rows.size(); ++i) CHECK(run.rows(rows[i], 0) - run.rows(rows[i - 1], 0) <= 2 * 10.0 / 49);
  const std::vector<int> all = view_rows(run, 5000);
  CHECK(all.size() == static_cast<std::size_t>(n + 1));
}

TEST_CASE("view: a run of another model, a missing file, --frames 0 and an unknown column are refused with file and "
          "field, nothing written",
          "[view][refusal]") {
  const fs::path d = test::scratch_dir("view", "refusals");
  const std::string dp = test::source_path("models/double_pendulum.yaml"), sp = test::source_path("models/pendulum.yaml");
  const std::string csv = (d / "dp.csv").string(), out = (d / "v.html").string();
  REQUIRE(test::run_kanegen(fmt::format("simulate {} --engine generic --t-end 0.1 --dt-out 0.05 --no-progress -o {}", dp,
                                        csv))
              .status == 0);
  const test::ShellRun other = test::run_kanegen(fmt::format("view {} {} -o {}", sp, csv, out));
  INFO(other.out);
  CHECK(other.status == 2);
  CHECK(other.out.find("dp.csv:1: header: no column") != std::string::npos);
  const test::ShellRun missing = test::run_kanegen(fmt::format("view {} {} -o {}", dp, (d / "nothing.csv").string(), out));
  CHECK(missing.status == 2);
  CHECK(missing.out.find("nothing.csv") != std::string::npos);
  const test::ShellRun zero = test::run_kanegen(fmt::format("view {} {} --frames 0 -o {}", dp, csv, out));
  CHECK(zero.status == 2);
  CHECK(zero.out.find("--frames") != std::string::npos);
  const test::ShellRun column = test::run_kanegen(fmt::format("view {} {} --columns T,nope -o {}", dp, csv, out));
  CHECK(column.status == 2);
  CHECK(column.out.find("--columns: no column 'nope'") != std::string::npos);
  CHECK(!fs::exists(out));
  // and the good one writes the page, three.js inlined, nothing fetched
  const test::ShellRun ok = test::run_kanegen(fmt::format("view {} {} -o {}", dp, csv, out));
  INFO(ok.out);
  REQUIRE(ok.status == 0);
  std::ifstream in(out);
  const std::string page((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(page.find("REVISION") != std::string::npos);  // three.js itself
  CHECK(page.find("OrbitControls") != std::string::npos);
  CHECK(page.find("<script src") == std::string::npos);  // nothing fetched: every script is inline
  fs::remove_all(d);
}

TEST_CASE("view: with the run's events table, the timeline's events are named and each frame's locked joints follow "
          "the release and the latches",
          "[view]") {
  const fs::path d = test::scratch_dir("view", "events");
  const std::string model_path = test::source_path("models/array_deployment.yaml");
  const std::string csv = (d / "dep.csv").string(), ev = (d / "dep.events.csv").string();
  const test::ShellRun sim = test::run_kanegen(fmt::format(
      "simulate {} --engine generic --t-end 20 --dt-out 0.5 --no-progress -o {} --events {}", model_path, csv, ev));
  INFO(sim.out);
  REQUIRE(sim.status == 0);
  const Model model = load_model(model_path);
  const RunTable run = read_run_table(csv);
  const std::vector<RunEvent> events = read_events_table(ev);
  REQUIRE(events.size() == 3);  // the release of both wings, then each wing's latch
  ViewOptions vo;
  vo.events = &events;
  const json data = view_data(model, &run, vo, ev);
  REQUIRE(data["events"].size() == 3);
  CHECK(data["events"][0]["name"] == "release (release)");
  CHECK(data["events"][1]["name"].get<std::string>().find("(lock)") != std::string::npos);
  const int a = model.body_index("wing_a"), b = model.body_index("wing_b");
  auto locked_at = [&](std::size_t f, int body) {
    for (const auto& i : data["locked"][f])
      if (i.get<int>() == body) return true;
    return false;
  };
  const std::vector<double> t = data["t"].get<std::vector<double>>();
  for (std::size_t f = 0; f < t.size(); ++f) {
    const bool second_row = f > 0 && t[f - 1] == t[f];
    INFO(fmt::format("frame {} at t = {}", f, t[f]));
    // stowed (locked) until the release's second row, free until its latch's second row, then latched
    const bool released = t[f] > events[0].t || (t[f] == events[0].t && second_row);
    const bool latched_a = t[f] > events[1].t || (t[f] == events[1].t && second_row);
    const bool latched_b = t[f] > events[2].t || (t[f] == events[2].t && second_row);
    CHECK(locked_at(f, a) == (!released || latched_a));
    CHECK(locked_at(f, b) == (!released || latched_b));
  }
  fs::remove_all(d);
}
