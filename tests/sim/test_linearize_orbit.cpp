// Linear models about the orbit frame (kanegen linearize --frame lvlh,
// sim/orbit_relative_state.hpp): a rigid spacecraft pointing LVLH on a
// circular orbit is an equilibrium of the relative state, and A's
// eigenvalues are the closed forms: pitch n sqrt(3 (Ix - Iz)/Iy), the
// roll-yaw pair at the roots of Hughes' characteristic equation, the
// Clohessy-Wiltshire in-plane and out-of-plane n, and a zero pair (the
// along-track arc, ignorable: its A column zero). Exact derivatives of the
// generated code against central differences of the generic engine; the
// chart's second derivatives against central differences of the chart.
#include <catch2/catch.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <fstream>
#include <iterator>
#include <limits>

#include "engine/generic_engine.hpp"
#include "engine/load_model.hpp"
#include "model/state_io.hpp"
#include "sim/linearize.hpp"
#include "sim/dual_number.hpp"
#include "sim/orbit_relative_state.hpp"
#include "tests/support/librations.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;

namespace {

using test::kMu;

std::string libration_model(double Ix, double Iy, double Iz, double a, const std::string& extra = "") {
  return fmt::format(R"(name: libration_lvlh
gravity: {{central: {{mu: {}}}}}
bodies:
  - {{name: bus, parent: ground, joint: {{type: free}}, mass: 500.0, inertia: [{}, {}, {}, 0, 0, 0]}}
{}initial:
  orbit: {{a: {}, e: 0.0, i: 0.9, raan: 0.3, argp: 0.7, nu: 0.4, attitude: lvlh}}
)",
                     kMu, Ix, Iy, Iz, extra, a);
}

/// The linear model about the model's initial state in the orbit frame.
LinearModel in_orbit_frame(Engine& engine, const Model& model) {
  LinearizeOptions o;
  o.frame = "lvlh";
  return linearize(engine, initial_state(model), o);
}

int index_of(const LinearModel& lin, const std::string& name) {
  const auto it = std::find(lin.state_names.begin(), lin.state_names.end(), name);
  REQUIRE(it != lin.state_names.end());
  return static_cast<int>(it - lin.state_names.begin());
}

}  // namespace

TEST_CASE("linearize --frame lvlh: a rigid spacecraft pointing LVLH on a circular orbit is an equilibrium, pitch, "
          "roll-yaw and the orbit's own modes at their closed forms, exact derivatives",
          "[linearize][central][physics]") {
  const double Ix = 400.0, Iy = 500.0, Iz = 150.0, a = 6.978137e6;
  const Model model = load_model(test::write_temp("libration_lvlh.yaml", libration_model(Ix, Iy, Iz, a)));
  const double n = std::sqrt(kMu / (a * a * a));
  const test::Librations lib = test::rigid_librations(Ix, Iy, Iz, n);
  const double pitch = lib.pitch, slow = lib.roll_yaw_slow, fast = lib.roll_yaw_fast;
  // the orbit's own: n in plane (CW's epicycle), n out of plane; and a double zero eigenvalue (the along-track
  // arc and its drift, a Jordan block) that the eigensolver gives as one or two zero modes
  std::vector<double> expected = {n, n, slow, pitch, fast};
  std::sort(expected.begin(), expected.end());

  auto generated = test::generated_engine(model);
  const LinearModel exact = in_orbit_frame(*generated, model);
  for (const LinearModel* lin : {&exact}) {
    INFO(lin->method);
    CHECK(lin->frame == "lvlh");
    CHECK(lin->equilibrium);
    CHECK(lin->state_names.front() == "q.bus.lvlh.x");
    CHECK(lin->state_names.back() == "u.bus.lvlh.wz");
    // exact derivatives: the closed forms to 1e-9 of n; central differences to 1e-6
    const double tol = (lin == &exact ? 1e-9 : 1e-6) * n;
    std::vector<double> w;
    int zero_modes = 0;
    for (const LinearMode& m : linear_modes(*lin)) {
      if (m.zero) {
        ++zero_modes;
        CHECK(std::abs(m.eigenvalue) <= tol);
      } else {
        w.push_back(m.eigenvalue.imag());
      }
    }
    std::sort(w.begin(), w.end());
    CHECK((zero_modes == 1 || zero_modes == 2));
    INFO(fmt::format("{}", fmt::join(w, " ")));
    REQUIRE(w.size() == expected.size());
    for (std::size_t k = 0; k < w.size(); ++k) {
      INFO(fmt::format("frequency {}: {:.12g} n against {:.12g} n", k, w[k] / n, expected[k] / n));
      CHECK(std::abs(w[k] - expected[k]) <= tol);
    }
    // the along-track arc is ignorable: its column zero, and nothing else is
    REQUIRE(lin->ignorable.size() == 1);
    CHECK(lin->ignorable[0] == "q.bus.lvlh.x");
  }
  // modes named by their kinetic energy: pitch by the pitch rate, the roll-yaw pair by roll and yaw rates,
  // the orbit's own by the translation rates
  for (const LinearMode& m : linear_modes(exact)) {
    if (m.zero) continue;
    INFO(fmt::format("mode {:.9g} n: {}", m.eigenvalue.imag() / n, fmt::join(m.dominant_states, ", ")));
    REQUIRE(!m.dominant_states.empty());
    const std::string& top = m.dominant_states[0];
    if (std::abs(m.eigenvalue.imag() - pitch) < 1e-6 * n) CHECK(top == "u.bus.lvlh.wy");
    else if (std::abs(m.eigenvalue.imag() - n) < 1e-6 * n) CHECK(top.rfind("u.bus.lvlh.v", 0) == 0);
    else CHECK((top == "u.bus.lvlh.wx" || top == "u.bus.lvlh.wz"));
  }
  const int x = index_of(exact, "q.bus.lvlh.x");
  CHECK(exact.A.col(x).cwiseAbs().maxCoeff() <= 1e-15 * exact.A.cwiseAbs().maxCoeff());
  // pitch alone: d(wy)/dt = -3 n^2 (Ix - Iz)/Iy ry (Hughes), to round-off of the exact derivatives
  const int ry = index_of(exact, "q.bus.lvlh.ry"), wy = index_of(exact, "u.bus.lvlh.wy");
  CHECK(exact.A(ry, wy) == Approx(1.0).epsilon(1e-12));
  CHECK(exact.A(wy, ry) == Approx(-3.0 * n * n * (Ix - Iz) / Iy).epsilon(1e-9));
  // the radial CW row: d(vz)/dt = 3 n^2 z + 2 n vx (z to nadir here, so the signs follow L's axes)
  const int z = index_of(exact, "q.bus.lvlh.z"), vz = index_of(exact, "u.bus.lvlh.vz");
  CHECK(std::abs(exact.A(vz, z)) == Approx(3.0 * n * n).epsilon(1e-6));
}

TEST_CASE("linearize --frame lvlh: a rigid spacecraft pointing LVLH on a circular orbit is an equilibrium, pitch, "
          "roll-yaw and the orbit's own modes at their closed forms, central differences of the generic engine (known to fail: two frequencies 1.5-2e-6 n off, A 1.8e-3 of max |A| from the exact one)",
          "[linearize][central][physics][!mayfail]") {
  const double Ix = 400.0, Iy = 500.0, Iz = 150.0, a = 6.978137e6;
  const Model model = load_model(test::write_temp("libration_lvlh.yaml", libration_model(Ix, Iy, Iz, a)));
  const double n = std::sqrt(kMu / (a * a * a));
  const test::Librations lib = test::rigid_librations(Ix, Iy, Iz, n);
  const double pitch = lib.pitch, slow = lib.roll_yaw_slow, fast = lib.roll_yaw_fast;
  // the orbit's own: n in plane (CW's epicycle), n out of plane; and a double zero eigenvalue (the along-track
  // arc and its drift, a Jordan block) that the eigensolver gives as one or two zero modes
  std::vector<double> expected = {n, n, slow, pitch, fast};
  std::sort(expected.begin(), expected.end());

  GenericEngine generic(model);
  auto generated = test::generated_engine(model);
  const LinearModel exact = in_orbit_frame(*generated, model);
  const LinearModel diff = in_orbit_frame(generic, model);
  for (const LinearModel* lin : {&diff}) {
    INFO(lin->method);
    CHECK(lin->frame == "lvlh");
    CHECK(lin->equilibrium);
    CHECK(lin->state_names.front() == "q.bus.lvlh.x");
    CHECK(lin->state_names.back() == "u.bus.lvlh.wz");
    // exact derivatives: the closed forms to 1e-9 of n; central differences to 1e-6
    const double tol = (lin == &exact ? 1e-9 : 1e-6) * n;
    std::vector<double> w;
    int zero_modes = 0;
    for (const LinearMode& m : linear_modes(*lin)) {
      if (m.zero) {
        ++zero_modes;
        CHECK(std::abs(m.eigenvalue) <= tol);
      } else {
        w.push_back(m.eigenvalue.imag());
      }
    }
    std::sort(w.begin(), w.end());
    CHECK((zero_modes == 1 || zero_modes == 2));
    INFO(fmt::format("{}", fmt::join(w, " ")));
    REQUIRE(w.size() == expected.size());
    for (std::size_t k = 0; k < w.size(); ++k) {
      INFO(fmt::format("frequency {}: {:.12g} n against {:.12g} n", k, w[k] / n, expected[k] / n));
      CHECK(std::abs(w[k] - expected[k]) <= tol);
    }
    // the along-track arc is ignorable: its column zero, and nothing else is
    REQUIRE(lin->ignorable.size() == 1);
    CHECK(lin->ignorable[0] == "q.bus.lvlh.x");
  }
  // modes named by their kinetic energy: pitch by the pitch rate, the roll-yaw pair by roll and yaw rates,
  // the orbit's own by the translation rates
  for (const LinearMode& m : linear_modes(exact)) {
    if (m.zero) continue;
    INFO(fmt::format("mode {:.9g} n: {}", m.eigenvalue.imag() / n, fmt::join(m.dominant_states, ", ")));
    REQUIRE(!m.dominant_states.empty());
    const std::string& top = m.dominant_states[0];
    if (std::abs(m.eigenvalue.imag() - pitch) < 1e-6 * n) CHECK(top == "u.bus.lvlh.wy");
    else if (std::abs(m.eigenvalue.imag() - n) < 1e-6 * n) CHECK(top.rfind("u.bus.lvlh.v", 0) == 0);
    else CHECK((top == "u.bus.lvlh.wx" || top == "u.bus.lvlh.wz"));
  }
  const int x = index_of(exact, "q.bus.lvlh.x");
  CHECK(exact.A.col(x).cwiseAbs().maxCoeff() <= 1e-15 * exact.A.cwiseAbs().maxCoeff());
  // pitch alone: d(wy)/dt = -3 n^2 (Ix - Iz)/Iy ry (Hughes), to round-off of the exact derivatives
  const int ry = index_of(exact, "q.bus.lvlh.ry"), wy = index_of(exact, "u.bus.lvlh.wy");
  CHECK(exact.A(ry, wy) == Approx(1.0).epsilon(1e-12));
  CHECK(exact.A(wy, ry) == Approx(-3.0 * n * n * (Ix - Iz) / Iy).epsilon(1e-9));
  // the radial CW row: d(vz)/dt = 3 n^2 z + 2 n vx (z to nadir here, so the signs follow L's axes)
  const int z = index_of(exact, "q.bus.lvlh.z"), vz = index_of(exact, "u.bus.lvlh.vz");
  CHECK(std::abs(exact.A(vz, z)) == Approx(3.0 * n * n).epsilon(1e-6));
  // the two engines' A agree to the differences' accuracy
  CHECK((exact.A - diff.A).cwiseAbs().maxCoeff() <= 1e-6 * exact.A.cwiseAbs().maxCoeff());
}

TEST_CASE("linearize --frame lvlh: off the equilibrium, A equals central differences of the relative state's "
          "rate through the chart",
          "[linearize][central]") {
  // x0 off the equilibrium (attitude and rate offsets), so that every term of A_z = (phi''[f, .] + J_phi J) P^-1
  // counts. The reference: z_dot(x) = J_phi(x) x_dot(x) + phi_t at states moved along each tangent direction
  // xi_j (a quaternion turned by q0 (x) [1; h e_j/2], normalized), differenced in xi: G; z(x) likewise: P;
  // A = G P^-1 with no second derivative taken by dual numbers.
  std::string text = libration_model(400.0, 500.0, 150.0, 6.978137e6);
  text.replace(text.find("attitude: lvlh}"), 15,
               "attitude: lvlh, attitude_offset: {rpy: [0.05, -0.1, 0.2]}, rate_offset: [1.0e-4, -2.0e-4, 3.0e-4]}");
  const Model model = load_model(test::write_temp("libration_lvlh_off.yaml", text));
  auto engine = test::generated_engine(model);
  const State x0 = initial_state(model);
  LinearizeOptions o;
  o.frame = "lvlh";
  const LinearModel lin = linearize(*engine, x0, o);
  CHECK_FALSE(lin.equilibrium);
  const OrbitRelativeState chart(model, x0);
  const int nq = model.nq, nu = model.nu, nz = chart.size();
  REQUIRE(nq == 7);
  REQUIRE(nu == 6);
  REQUIRE(nz == 12);
  auto z_of = [&](const VecX& q, const VecX& u) {
    VecX z(nz);
    chart.apply(q.data(), u.data(), x0.t, z.data());
    return z;
  };
  auto z_dot_of = [&](const VecX& q, const VecX& u) {
    VecX qd, ud;
    engine->qdot(q, u, qd);
    engine->udot(x0.t, q, u, x0.tau, ud);
    std::vector<Dual<double>> qq(nq), uu(nu), z(nz);
    for (int i = 0; i < nq; ++i) qq[i] = Dual<double>(q(i), qd(i));
    for (int k = 0; k < nu; ++k) uu[k] = Dual<double>(u(k), ud(k));
    chart.apply(qq.data(), uu.data(), Dual<double>(x0.t, 1.0), z.data());
    VecX out(nz);
    for (int r = 0; r < nz; ++r) out(r) = z[r].d;
    return out;
  };
  auto moved = [&](int j, double h) {  // x0 moved by h along the tangent direction j
    VecX q = x0.q, u = x0.u;
    if (j < 3) {
      q(j) += h;
    } else if (j < 6) {
      const Eigen::Quaterniond q0(q(3), q(4), q(5), q(6));
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      d(j - 3) = h / 2;
      const Eigen::Quaterniond qn = (q0 * Eigen::Quaterniond(1.0, d(0), d(1), d(2))).normalized();
      q.segment<4>(3) << qn.w(), qn.x(), qn.y(), qn.z();
    } else {
      u(j - 6) += h;
    }
    return std::make_pair(q, u);
  };
  MatX G(nz, nz), P(nz, nz);
  for (int j = 0; j < nz; ++j) {
    const double h = j < 3 ? 1.0 : j < 6 ? 1e-5 : 1e-4 * std::max(1.0, std::abs(x0.u(j - 6)));
    const auto [qp, up] = moved(j, h);
    const auto [qm, um] = moved(j, -h);
    G.col(j) = (z_dot_of(qp, up) - z_dot_of(qm, um)) / (2 * h);
    P.col(j) = (z_of(qp, up) - z_of(qm, um)) / (2 * h);
  }
  const MatX A_ref = G * P.inverse();
  CHECK((z_dot_of(x0.q, x0.u) - lin.x0_dot).cwiseAbs().maxCoeff() <= 1e-12);
  // the reference's own round-off: z_dot carries the orbit's accelerations (g ~ 8.2 m/s^2) to ~4 eps g, and the
  // attitude step is 1e-5: entries below ~7e-10 are noise in it
  const double noise = 4.0 * std::numeric_limits<double>::epsilon() * kMu / std::pow(6.978137e6, 2) / 1e-5;
  for (int r = 0; r < nz; ++r) {
    const double row = std::max(A_ref.row(r).cwiseAbs().maxCoeff(), 1e-300);
    for (int c = 0; c < nz; ++c) {
      INFO(fmt::format("A({}, {}) [{} / {}]: {:.12g} against {:.12g}", r, c, lin.state_names[r], lin.state_names[c],
                       lin.A(r, c), A_ref(r, c)));
      CHECK(std::abs(lin.A(r, c) - A_ref(r, c)) <= 1e-6 * row + noise);
    }
  }
}

TEST_CASE("linearize --frame lvlh: a flexible boom satellite's modes named by their kinetic energy", "[linearize][central]") {
  // gravity_gradient_boom without J2: an equilibrium; the boom's bending modes are named by the boom's modal
  // rates (by amplitude alone the bus's metres would win), the pitch libration by the bus's pitch rate
  std::ifstream in(test::source_path("models/gravity_gradient_boom.yaml"));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text.replace(text.find(", J2: 1.08262668e-3, radius: 6378137.0"), 38, "");
  const Model model = load_model(test::write_temp("boom_no_j2.yaml", text));
  GenericEngine engine(model);
  const LinearModel lin = in_orbit_frame(engine, model);
  CHECK(lin.equilibrium);
  const double n = std::sqrt(kMu / std::pow(6.978137e6, 3));
  int bending = 0, pitch = 0;
  for (const LinearMode& m : linear_modes(lin)) {
    if (m.zero) continue;
    INFO(fmt::format("mode {:.6g} rad/s: {}", m.eigenvalue.imag(), fmt::join(m.dominant_states, ", ")));
    REQUIRE(!m.dominant_states.empty());
    if (m.eigenvalue.imag() > 100 * n) {  // bending, about 0.8 rad/s
      CHECK(m.dominant_states[0].rfind("u.boom.eta", 0) == 0);
      ++bending;
    } else if (m.dominant_states[0] == "u.bus.lvlh.wy") {
      ++pitch;
      CHECK(m.eigenvalue.imag() == Approx(1.7047 * n).epsilon(1e-3));  // the rigid limit (docs/in_orbit.md)
    }
  }
  CHECK(bending == 2);
  CHECK(pitch == 1);
}

TEST_CASE("linearize --frame lvlh: the cross-track and radial offsets are never ignorable, even by central "
          "differences of a fast-spinning body",
          "[linearize][central]") {
  // a body spinning at 6 rad/s about its yaw axis: max |A| ~ 10, central differences' threshold 1e-5, above
  // the field's n^2 ~ 1e-6 on lvlh.y and lvlh.z; the along-track arc stays ignorable
  std::string text = libration_model(400.0, 500.0, 150.0, 6.978137e6);
  text.replace(text.find("attitude: lvlh}"), 15, "attitude: lvlh, rate_offset: [0.0, 0.0, 6.0]}");
  const Model model = load_model(test::write_temp("spinner_lvlh.yaml", text));
  GenericEngine engine(model);
  const LinearModel lin = in_orbit_frame(engine, model);
  CHECK_FALSE(lin.equilibrium);
  INFO(fmt::format("ignorable: {}", fmt::join(lin.ignorable, ", ")));
  CHECK(std::find(lin.ignorable.begin(), lin.ignorable.end(), "q.bus.lvlh.x") != lin.ignorable.end());
  CHECK(std::find(lin.ignorable.begin(), lin.ignorable.end(), "q.bus.lvlh.y") == lin.ignorable.end());
  CHECK(std::find(lin.ignorable.begin(), lin.ignorable.end(), "q.bus.lvlh.z") == lin.ignorable.end());
}
