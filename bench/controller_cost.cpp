// The cost of a control law in the loop, per call: the slew example
// (models/gnc/slew_spacecraft.yaml) integrated with fixed-step RK4 (so that
// every run evaluates the right-hand side the same number of times) open
// loop, and with the PD law of examples/gnc_slew as a continuous C++
// controller (called at every evaluation, with the named outputs computed
// for it). Prints JSON; scripts/gnc_report.py runs the same with the law in
// Python (import kanegen) and reports both per-call costs.
//   kanegen_controller_cost [--t-end 60] [--h 0.01] [--repeats 3]
#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cstring>
#include <sstream>

#include "codegen/jit_generator.hpp"
#include "engine/jit.hpp"
#include "engine/load_model.hpp"
#include "model/state_io.hpp"
#include "sim/simulate.hpp"

using namespace kanegen;

int main(int argc, char** argv) {
  double t_end = 60.0, h = 0.01;
  int repeats = 3;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--t-end")) t_end = std::atof(argv[i + 1]);
    if (!std::strcmp(argv[i], "--h")) h = std::atof(argv[i + 1]);
    if (!std::strcmp(argv[i], "--repeats")) repeats = std::atoi(argv[i + 1]);
  }
  const Model model = load_model(std::string(KANEGEN_SOURCE_DIR) + "/models/gnc/slew_spacecraft.yaml");
  auto engine = jit_load(model, codegen::jit_code_generator());
  const int att = model.output_index("star_tracker.qw"), gyro = model.output_index("gyro.x");
  const Eigen::Vector3d I(995.0, 380.0, 875.0);
  const double bw = 0.05, zeta = 0.9, tmax = 0.3, half = 0.5 * 30.0 * M_PI / 180.0;
  const Eigen::Quaterniond target(std::cos(half), 0, 0, std::sin(half));
  auto pd = [&](double, const VecX&, const VecX&, const VecX& y, VecX& w) {
    Eigen::Quaterniond e = target.conjugate() * Eigen::Quaterniond(y(att), y(att + 1), y(att + 2), y(att + 3));
    if (e.w() < 0) e.coeffs() = -e.coeffs();
    Eigen::Vector3d torque = -(I.cwiseProduct(2.0 * bw * bw * e.vec()) + I.cwiseProduct(2.0 * zeta * bw * y.segment<3>(gyro)));
    const double peak = torque.cwiseAbs().maxCoeff();
    if (peak > tmax) torque *= tmax / peak;
    w = -torque;
  };
  auto run = [&](bool closed) {
    SimulationOptions o;
    o.t_end = t_end;
    o.dt_out = 1.0;
    o.integrator.kind = IntegratorKind::rk4;
    o.integrator.h = h;
    if (closed) o.controller.law = pd;
    double best = 1e300;
    long evals = 0;
    for (int r = 0; r < repeats; ++r) {
      std::ostringstream csv;
      const auto t0 = std::chrono::steady_clock::now();
      const SimulationResult res = simulate(*engine, initial_state(model), o, csv);
      best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      evals = res.stats.rhs_evals;
    }
    return std::make_pair(best, evals);
  };
  const auto open = run(false), closed = run(true);
  fmt::print("{{\"t_end\": {}, \"h\": {}, \"rhs_evals\": {}, \"open_loop_s\": {:.6f}, \"cpp_continuous_s\": {:.6f}, "
             "\"cpp_per_call_us\": {:.4f}}}\n",
             t_end, h, closed.second, open.first, closed.first, 1e6 * (closed.first - open.first) / closed.second);
  return 0;
}
