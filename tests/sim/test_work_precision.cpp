// Tests for sim/work_precision.{hpp,cpp} (`kanegen bench`): the attitude
// error metric, the interpolation of the time to reach a target, the choice
// of invariants, and a small end-to-end sweep on the pendulum.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <unistd.h>

#include "engine/load_model.hpp"
#include "model/state_io.hpp"
#include "tests/support/test_support.hpp"
#include "sim/work_precision.hpp"

using namespace kanegen;
using namespace kanegen::bench;
namespace fs = std::filesystem;

namespace {

/// Unit quaternion [w, x, y, z] of a rotation by `angle` about `axis`.
Eigen::Vector4d quat(double angle, Eigen::Vector3d axis) {
  axis.normalize();
  Eigen::Vector4d q;
  q << std::cos(angle / 2), std::sin(angle / 2) * axis;
  return q;
}

/// Hamilton product a (x) b, scalar first.
Eigen::Vector4d mul(const Eigen::Vector4d& a, const Eigen::Vector4d& b) {
  const Eigen::Vector3d va = a.tail<3>(), vb = b.tail<3>();
  Eigen::Vector4d r;
  r << a(0) * b(0) - va.dot(vb), a(0) * vb + b(0) * va + va.cross(vb);
  return r;
}

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  bool quoted = false;
  for (char c : line) {
    if (c == '"') quoted = !quoted;
    else if (c == ',' && !quoted) out.push_back(cur), cur.clear();
    else cur += c;
  }
  out.push_back(cur);
  return out;
}

}  // namespace

TEST_CASE("rotation angle between quaternions", "[bench]") {
  const Eigen::Vector4d id(1, 0, 0, 0);
  for (double a : {0.3, 1e-9, 2.0, 3.0}) {
    const Eigen::Vector4d q = quat(a, {1, 2, -0.5});
    CHECK(rotation_angle(id, q) == Approx(a).epsilon(1e-12));
    CHECK(rotation_angle(q, id) == Approx(a).epsilon(1e-12));
    CHECK(rotation_angle(id, -q) == Approx(a).epsilon(1e-12));  // q and -q: the same attitude
    CHECK(rotation_angle(2.0 * id, 0.5 * q) == Approx(a).epsilon(1e-12));  // norms do not matter
  }
  // relative: q_b = q_a (x) r(angle) for an arbitrary q_a
  const Eigen::Vector4d qa = quat(1.234, {0.3, -1, 0.7});
  CHECK(rotation_angle(qa, mul(qa, quat(0.25, {0, 0, 1}))) == Approx(0.25).epsilon(1e-12));
  CHECK(rotation_angle(qa, mul(quat(1e-7, {1, 1, 1}), qa)) == Approx(1e-7).epsilon(1e-8));
  // beyond pi the shorter way round is taken: a rotation by 2 pi - 0.5 is one by 0.5
  CHECK(rotation_angle(id, quat(2 * M_PI - 0.5, {0, 1, 0})) == Approx(0.5).epsilon(1e-12));
  CHECK(rotation_angle(qa, qa) == 0.0);
}

TEST_CASE("trajectory error: attitude by angle, other kinds relative to the reference's scale", "[bench]") {
  const Model m = load_model(test::source_path("models/explorer1_rigid.yaml"));
  const State s = initial_state(m);
  Trajectory ref, run;
  for (int k = 0; k <= 2; ++k) {
    VecX x(m.nq + m.nu);
    x << s.q, s.u;
    x(m.nq + m.u_index("bus.wz")) *= 1.0 + 0.1 * k;  // wz scale = 1.2 * 2 pi
    ref.t.push_back(k), ref.x.push_back(x);
  }
  run = ref;
  // 1e-6 rad of attitude error at t = 1
  const int iq = m.q_index("bus.qw");
  run.x[1].segment<4>(iq) = mul(run.x[1].segment<4>(iq), quat(1e-6, {0, 1, 0}));
  ErrorMeasure e = trajectory_error(m, run, ref);
  CHECK(e.error == Approx(1e-6).epsilon(1e-6));
  CHECK(e.worst == "attitude bus");
  CHECK(e.worst_t == 1.0);
  // an angular-rate error, relative to the largest angular rate of the reference
  const double wz_max = 1.2 * 2 * M_PI;
  run.x[2](m.nq + m.u_index("bus.wz")) += 1e-3 * wz_max;
  e = trajectory_error(m, run, ref);
  CHECK(e.error == Approx(1e-3).epsilon(1e-9));
  CHECK(e.worst == "angular rate bus.wz");
  // mismatched output times are refused
  run.t[1] = 1.5;
  CHECK_THROWS_AS(trajectory_error(m, run, ref), std::invalid_argument);
}

TEST_CASE("time to reach a target: log-log interpolation between bracketing sweep points", "[bench]") {
  // (error, wall) in sweep order
  const std::vector<std::pair<double, double>> c{{1e-2, 1.0}, {1e-4, 10.0}, {1e-6, 100.0}};
  CHECK(*time_to_reach(c, 1e-2) == Approx(1.0));
  CHECK(*time_to_reach(c, 1e-3) == Approx(std::sqrt(10.0)));  // halfway in log between 1 and 10
  CHECK(*time_to_reach(c, 1e-5) == Approx(std::sqrt(1000.0)));
  CHECK(*time_to_reach(c, 1e-1) == Approx(1.0));  // the first point already reaches it: not extrapolated
  CHECK_FALSE(time_to_reach(c, 1e-8));
  // timing noise: a tighter point measured cheaper than the interpolation wins
  const std::vector<std::pair<double, double>> noisy{{1e-2, 1.0}, {1e-4, 10.0}, {1e-6, 2.0}};
  CHECK(*time_to_reach(noisy, 1e-3) == Approx(2.0));
}

TEST_CASE("invariants are judged from the model, default t_end from comments", "[bench]") {
  const Model pend = load_model(test::source_path("models/pendulum.yaml"));
  InvariantSet s = invariants_of(pend, VecX::Zero(pend.nu));
  CHECK(s.energy);
  CHECK_FALSE(s.momentum);  // gravity, grounded revolute
  CHECK_FALSE(invariants_of(pend, VecX::Constant(pend.nu, 0.1)).energy);  // an input
  const Model e1 = load_model(test::source_path("models/explorer1_rigid.yaml"));
  s = invariants_of(e1, VecX::Zero(e1.nu));
  CHECK_FALSE(s.energy);  // hinge dampers
  CHECK(s.momentum);      // free-floating, zero gravity

  CHECK(default_t_end(test::source_path("models/explorer1_rigid.yaml")) == 3000.0);  // "--t-end 3000" in a comment
  CHECK(default_t_end(test::write_temp("a.yaml", "# bench-t-end: 25\n# t_end: 7\nname: a\n")) == 25.0);
  CHECK(default_t_end(test::write_temp("b.yaml", "name: b  # t-end = 2.5e1\n")) == 25.0);
  CHECK(default_t_end(test::write_temp("c.yaml", "name: c\n")) == 10.0);
  CHECK(default_t_end(test::write_temp("d.yaml", "# run: --t-end 300\n# bench: t_end = 20\nname: d\n")) == 20.0);
}

TEST_CASE("bench on the pendulum: CSV, errors converge, summary names a configuration", "[bench]") {
  const fs::path out = fs::temp_directory_path() / ("kanegen_bench_" + std::to_string(::getpid()));
  fs::remove_all(out);
  BenchOptions opt;
  opt.engines = {"generated", "generic"};
  opt.integrators = {"cvode-bdf", "arkode-erk"};
  opt.tolerances = {1e-5, 1e-8};
  opt.t_end = 5.0;
  opt.repeats = 1;
  opt.out_dir = out.string();
  opt.make_engine = [](const Model& m, const std::string&) -> std::unique_ptr<Engine> {
    return test::generated_engine(m);
  };
  opt.plot = std::system("/usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1") == 0;
  if (!opt.plot) WARN("no python3 with matplotlib: the PNG is not checked");
  REQUIRE(run_bench({test::source_path("models/pendulum.yaml")}, opt, "") == 0);

  // CSV: the columns of the contract, one row per engine x integrator x tolerance
  std::ifstream csv(out / "pendulum_work_precision.csv");
  REQUIRE(csv);
  std::string line;
  std::getline(csv, line);
  const std::vector<std::string> header = split_csv_line(line);
  const std::vector<std::string> expected{"model",     "engine", "integrator",   "tolerance_or_step",
                                          "wall_s",    "steps",  "rhs_evals",    "jac_evals",
                                          "error",     "energy_drift", "H_drift", "status"};
  REQUIRE(header.size() >= expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) CHECK(header[i] == expected[i]);
  std::map<std::string, int> col;
  for (std::size_t i = 0; i < header.size(); ++i) col[header[i]] = static_cast<int>(i);
  std::map<std::string, std::map<double, double>> error_by_curve;  // engine/integrator -> tol -> error
  int rows = 0;
  while (std::getline(csv, line)) {
    const auto f = split_csv_line(line);
    REQUIRE(f.size() == header.size());
    ++rows;
    CHECK(f[col["model"]] == "pendulum");
    CHECK(f[col["status"]] == "ok");
    const double err = std::stod(f[col["error"]]);
    CHECK(std::isfinite(err));
    CHECK(err > 0);
    CHECK(std::stod(f[col["wall_s"]]) > 0);
    CHECK(std::stol(f[col["steps"]]) > 0);
    CHECK(std::stol(f[col["rhs_evals"]]) > 0);
    CHECK(!f[col["energy_drift"]].empty());  // the pendulum conserves energy
    CHECK(f[col["H_drift"]].empty());        // ... not momentum (gravity, hinge to ground)
    error_by_curve[f[col["engine"]] + "/" + f[col["integrator"]]][std::stod(f[col["tolerance_or_step"]])] = err;
  }
  // generated: cvode-bdf (exact Jacobian), arkode-erk; generic: cvode-bdf-fd (no exact Jacobian), arkode-erk
  CHECK(rows == 8);
  REQUIRE(error_by_curve.count("generated/cvode-bdf"));
  REQUIRE(error_by_curve.count("generic/cvode-bdf-fd"));
  for (const auto& [curve, errs] : error_by_curve) {
    INFO(curve);
    REQUIRE(errs.size() == 2);
    CHECK(errs.at(1e-8) < errs.at(1e-5));  // tighter tolerance, smaller error
    CHECK(errs.at(1e-8) < 1e-5);
  }
  // both engines integrate the same equations: same error to a small fraction
  CHECK(error_by_curve["generated/arkode-erk"][1e-8] == Approx(error_by_curve["generic/arkode-erk"][1e-8]).epsilon(1e-3));

  std::ifstream md(out / "summary.md");
  REQUIRE(md);
  std::stringstream ss;
  ss << md.rdbuf();
  const std::string summary = ss.str();
  CHECK(summary.find("## pendulum") != std::string::npos);
  // the 1e-4 target is reached: a configuration is named for it
  const auto row = summary.find("| 1e-04 | ");
  REQUIRE(row != std::string::npos);
  const std::string target_row = summary.substr(row, summary.find('\n', row) - row);
  CHECK((target_row.find("generated / ") != std::string::npos || target_row.find("generic / ") != std::string::npos));
  CHECK(summary.find("generated / generic") != std::string::npos);  // the ratio table
  if (opt.plot) CHECK(fs::file_size(out / "pendulum_work_precision.png") > 1000);
  fs::remove_all(out);
}
