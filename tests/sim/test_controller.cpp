// A controller in the loop (sim/controller.hpp) against closed forms: a rotor
// of inertia J driven by a motor torque (a named input), under a continuous
// PD law (a damped oscillator: exact solution) and under a digital one with
// zero-order hold (the exact discrete-time recursion of a double integrator).
#include <catch2/catch.hpp>

#include <cmath>
#include <sstream>

#include "engine/generic_engine.hpp"
#include "engine/load_model.hpp"
#include "model/state_io.hpp"
#include "sim/simulate.hpp"
#include "tests/support/test_support.hpp"

using namespace kanegen;

namespace {

const char* kRotor = R"(
name: rotor
bodies:
  - {name: wheel, parent: ground, joint: {type: revolute, axis: [0, 0, 1]}, mass: 1, inertia: [1.1, 1.1, 2.0, 0, 0, 0]}
initial:
  q: {wheel.angle: 1.0}
inputs:
  - {name: motor, type: joint_torque, joint: wheel}
outputs:
  - {name: rate, type: angular_velocity, body: wheel}
)";

/// The CSV of a run: rows of numbers, and the header.
std::vector<std::vector<double>> rows_of(const std::string& csv, std::vector<std::string>& header) {
  std::istringstream in(csv);
  std::string line;
  std::getline(in, line);
  header.clear();
  for (std::size_t a = 0, b; a <= line.size(); a = b + 1) {
    b = std::min(line.find(',', a), line.size());
    header.push_back(line.substr(a, b - a));
  }
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    std::vector<double> r;
    std::istringstream ls(line);
    std::string cell;
    while (std::getline(ls, cell, ',')) r.push_back(std::stod(cell));
    rows.push_back(r);
  }
  return rows;
}

int column(const std::vector<std::string>& header, const std::string& name) {
  return static_cast<int>(std::find(header.begin(), header.end(), name) - header.begin());
}

}  // namespace

TEST_CASE("controller: a continuous PD law makes the exact damped oscillator", "[controller]") {
  const Model model = load_model(test::write_temp("rotor_c.yaml", kRotor));
  auto engine = test::generated_engine(model);
  const double J = 2.0, k = 8.0, c = 1.6;  // w_n = 2 rad/s, zeta = 0.2
  SimulationOptions o;
  o.t_end = 5.0;
  o.dt_out = 0.5;
  o.integrator.kind = IntegratorKind::rkf78;
  o.integrator.rtol = 1e-12;
  o.integrator.atol = 1e-14;
  o.controller.law = [&](double, const VecX& q, const VecX&, const VecX& y, VecX& w) {
    w(0) = -k * q(0) - c * y(2);  // the gyro's z: the wheel's rate
  };
  std::ostringstream csv;
  simulate(*engine, initial_state(model), o, csv);
  std::vector<std::string> header;
  const auto rows = rows_of(csv.str(), header);
  const int iq = column(header, "wheel.angle"), iw = column(header, "motor");
  const double wn = std::sqrt(k / J), zeta = c / (2 * std::sqrt(k * J)), wd = wn * std::sqrt(1 - zeta * zeta);
  REQUIRE(rows.size() == 11);
  for (const auto& r : rows) {
    const double t = r[0];
    const double theta = std::exp(-zeta * wn * t) * (std::cos(wd * t) + zeta * wn / wd * std::sin(wd * t));
    INFO("t = " << t);
    CHECK(std::abs(r[iq] - theta) <= 1e-9);
    CHECK(std::abs(r[iw] - (-k * r[iq] - c * r[column(header, "rate.z")])) <= 1e-12);  // the inputs at that time
  }
}

TEST_CASE("controller: a digital law holds its inputs and samples at its rate", "[controller]") {
  const Model model = load_model(test::write_temp("rotor_d.yaml", kRotor));
  GenericEngine engine(model);
  const double J = 2.0, k = 8.0, c = 1.6, T = 0.25;
  SimulationOptions o;
  o.t_end = 3.0;
  o.dt_out = 0.05;
  o.integrator.kind = IntegratorKind::rkf78;
  o.integrator.rtol = 1e-12;
  o.integrator.atol = 1e-14;
  std::vector<double> sample_times;
  o.controller.period = T;
  o.controller.law = [&](double t, const VecX& q, const VecX& u, const VecX&, VecX& w) {
    sample_times.push_back(t);
    w(0) = -k * q(0) - c * u(0);
  };
  std::ostringstream csv;
  simulate(engine, initial_state(model), o, csv);
  // samples at 0, T, 2T, ... (12 of them), each once
  REQUIRE(sample_times.size() == 12);
  for (std::size_t i = 0; i < sample_times.size(); ++i) CHECK(std::abs(sample_times[i] - i * T) <= 1e-12);
  // the exact zero-order-hold recursion of J theta'' = w
  double th = 1.0, om = 0.0;
  std::vector<std::string> header;
  const auto rows = rows_of(csv.str(), header);
  REQUIRE(rows.size() == 61);
  const int iq = column(header, "wheel.angle"), iw = column(header, "motor");
  for (int s = 0; s < 12; ++s) {
    const double w = -k * th - c * om;
    for (int j = 0; j < 5; ++j) {  // rows within the period: inputs held
      const auto& r = rows[5 * s + j];
      const double tau = r[0] - s * T;
      INFO("t = " << r[0]);
      CHECK(r[iw] == rows[5 * s][iw]);  // held bit for bit within the period
      CHECK(std::abs(r[iw] - w) <= 1e-10);
      CHECK(std::abs(r[iq] - (th + om * tau + 0.5 * w / J * tau * tau)) <= 1e-10);
    }
    th += om * T + 0.5 * w / J * T * T;
    om += w / J * T;
  }
  CHECK(std::abs(rows.back()[iq] - th) <= 1e-10);
}
