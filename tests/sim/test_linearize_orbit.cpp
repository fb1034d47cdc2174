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
          "roll-yaw and the orbit's own modes at their closed forms, exact derivatives and central differences",
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

  GenericEngine generic(model);
  auto generated = test::generated_engine(model);
  const LinearModel exact = in_orbit_frame(*generated, model);
  const LinearModel diff = in_orbit_frame(generic, model);  // differenced in the chart's own coordinates
  for (const LinearModel* lin : {&exact, &diff}) {
    INFO(lin->method);
    CHECK(lin->frame == "lvlh");
    CHECK(lin->equilibrium);
    CHECK(lin->state_names.front() == "q.bus.lvlh.x");
    CHECK(lin->state_names.back() == "u.bus.lvlh.wz");
    // exact derivatives: the closed forms to 1e-9 of n; central differences to 1e-8 (measured: 2e-10). Differenced
    // in the inertial coordinates and turned into the chart's, two were 2e-6 n off and A 1.8e-3 from the exact
    // one (the orbit's 7.5e3 m/s turned by an attitude step, the differences' round-off multiplied by it)
    const double tol = (lin == &exact ? 1e-9 : 1e-8) * n;
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
    // the along-track arc is ignorable: its column zero, and nothing else is (the yaw angle's stiffness, 8e-7
    // 1/s^2, is far below A's unit entries but most of its own row)
    INFO(fmt::format("ignorable: {}", fmt::join(lin->ignorable, ", ")));
    REQUIRE(lin->ignorable.size() == 1);
    CHECK(lin->ignorable[0] == "q.bus.lvlh.x");
  }
  // the two engines' A agree to the differences' accuracy (measured: 1.8e-7 of max |A|, the position rows'
  // round-off eps 7.5e3 m/s / 1e-5)
  CHECK((exact.A - diff.A).cwiseAbs().maxCoeff() <= 1e-6 * exact.A.cwiseAbs().maxCoeff());
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

TEST_CASE("linearize --frame lvlh: outputs by central differences in the chart agree with the exact ones, the "
          "inertial velocity too",
          "[linearize][central]") {
  // an inertial velocity sensor's attitude column is the orbit's 7.5e3 m/s turned (R_NB [v_B]x), which the chart
  // undoes: its C differenced in the inertial coordinates and turned by P^-1 carried eps 7.5e3 / h times P^-1's
  // 7.5e3 (1e-2 of its unit entries); differenced in the chart's own coordinates it agrees with the exact C
  const std::string outputs = R"(outputs:
  - {name: v_gps, type: velocity, body: bus, point: [0.3, -0.2, 0.5]}
  - {name: r_gps, type: position, body: bus, point: [0.3, -0.2, 0.5]}
  - {name: star_tracker, type: attitude, body: bus}
  - {name: gyro, type: angular_velocity, body: bus}
  - {name: imu, type: specific_force, body: bus, point: [0.3, -0.2, 0.5]}
inputs:
  - {name: torque, type: torque, body: bus, axes: body}
)";
  const Model model = load_model(test::write_temp("libration_lvlh_outputs.yaml",
                                                  libration_model(400.0, 500.0, 150.0, 6.978137e6, outputs)));
  GenericEngine generic(model);
  auto generated = test::generated_engine(model);
  const LinearModel exact = in_orbit_frame(*generated, model);
  const LinearModel diff = in_orbit_frame(generic, model);
  REQUIRE(exact.method.rfind("exact", 0) == 0);
  REQUIRE(diff.method.rfind("central differences in the orbit frame's chart", 0) == 0);
  REQUIRE(exact.output_names == diff.output_names);
  REQUIRE(exact.C.rows() == 15);  // 3 + 3 + 3 (a small rotation) + 3 + 3
  CHECK((exact.A - diff.A).cwiseAbs().maxCoeff() <= 1e-6 * exact.A.cwiseAbs().maxCoeff());
  // an output's own round-off over the attitude step (1e-5 rad): a position of 7e6 m differenced so carries
  // ~eps 7e6 / 1e-5 ~ 2e-4 in its attitude columns, inertial coordinates or the chart's alike
  const double eps = std::numeric_limits<double>::epsilon();
  for (int r = 0; r < exact.C.rows(); ++r) {
    const double scale = std::max(exact.C.row(r).cwiseAbs().maxCoeff(), 1e-300);
    const double noise = 4.0 * eps * std::abs(exact.y0(r)) / 1e-5;
    INFO(fmt::format("{}: C row {} against {}", exact.output_names[r], fmt::join(diff.C.row(r), " "),
                     fmt::join(exact.C.row(r), " ")));
    CHECK((exact.C.row(r) - diff.C.row(r)).cwiseAbs().maxCoeff() <= 1e-6 * scale + noise);
    CHECK((exact.D.row(r) - diff.D.row(r)).cwiseAbs().maxCoeff() <= 1e-6 * std::max(1.0, exact.D.row(r).cwiseAbs().maxCoeff()));
  }
  // the velocity sensor along lvlh.vx = r0 phi_dot (the whole system turned about the orbit normal): the sensor
  // point moves at phi_dot times its distance from the normal through the central body, the bus's r0 = a less
  // its 0.5 m towards nadir, its 0.3 m along track at right angles: |C| = sqrt((a - 0.5)^2 + 0.3^2) / a
  const int vx = index_of(exact, "u.bus.lvlh.vx");
  const double a = 6.978137e6, expected = std::hypot(a - 0.5, 0.3) / a;
  CHECK(std::abs(exact.C.block(0, vx, 3, 1).norm() - expected) <= 1e-12);
  CHECK(std::abs(diff.C.block(0, vx, 3, 1).norm() - expected) <= 1e-9);
}
