// The named inputs as applied wrenches and the named outputs (sensors),
// symbolically: the counterparts of dynamics/applied_inputs.hpp and
// dynamics/sensors.hpp, under the same names. Ports are carried to the
// generator's bodies and frames by merge_fixed_bodies and choose_joint_frames
// (model/inputs_outputs.hpp: move_ports), so here every point and axis is
// already in the frame of ctx.model's body.
#include <algorithm>
#include <optional>
#include <fmt/format.h>

#include "codegen/kane_context.hpp"

namespace kanegen::codegen {

using namespace GiNaC;

std::vector<ex> input_wrench(KaneContext& ctx, int j) {
  const Body& b = ctx.model.bodies[j];
  const int m = b.n_modes();
  std::vector<ex> W(6 + m, ex(0));
  const SymBodyWorkspace& s = ctx.body[j];
  for (const Input& in : ctx.model.inputs) {
    if (in.body != j || in.type == InputType::joint_torque) continue;
    if (in.node >= 0) {  // a force at a node: at its displaced position, with modal rows Phi~^T f
      ctx.C.group = b.name;
      const FlexibleData& fd = *b.flex;
      const int k = in.node;
      const auto& w = ctx.x.inputs;
      const SV3 v{{w[in.offset], w[in.offset + 1], w[in.offset + 2]}};
      const SV3 f_B = in.axes == Axes::inertial
                          ? ctx.A.mul_t(s.R_NB, v)
                          : ctx.A.mul(ctx.cmat(in.R_BX, in.name + "_R_BX", "", "input axes in the body frame"), v);
      SV3 s_k = ctx.cvec(fd.nodes[k].rho_B, in.name + "_rho", "m", "the node's undeformed position");
      std::vector<SV3> Phi_t(m);
      for (int i = 0; i < m; ++i)
        Phi_t[i] = ctx.cvec(fd.Phi.block(3 * k, i, 3, 1), fmt::format("{}_Phi{}", in.name, i + 1), "m",
                            "mode shape at the node");
      for (int a = 0; a < 3; ++a) {
        ex sum = s_k[a];
        for (int i = 0; i < m; ++i) sum += Phi_t[i][a] * s.eta[i];
        if (fd.has_second_order(k) && fd.Gamma[k][a].size())
          for (int i = 0; i < m; ++i) {
            ex Ge = 0;  // (Gamma^a eta)_i
            for (int l = 0; l < m; ++l)
              Ge += ctx.c(fd.Gamma[k][a](i, l), fmt::format("{}_G_{}_{}_{}", in.name, a, i + 1, l + 1), "1/m",
                          "foreshortening matrix at the node") * s.eta[l];
            Ge = ctx.A.let(Ge);
            sum += Ge * s.eta[i] / 2;
            Phi_t[i][a] = ctx.A.let(Phi_t[i][a] + Ge);
          }
        s_k[a] = ctx.A.let(sum);
      }
      const SV3 sxf = ctx.A.cross(s_k, f_B);
      for (int a = 0; a < 3; ++a) W[a] += f_B[a], W[3 + a] += sxf[a];
      for (int i = 0; i < m; ++i) W[6 + i] += ctx.A.dot(Phi_t[i], f_B);
      continue;
    }
    ctx.C.group = ctx.model.bodies[j].name;
    const auto& w = ctx.x.inputs;
    SV3 f, t;
    if (in.type == InputType::thruster) {
      const SV3 d = ctx.cvec(in.direction_B, in.name + "_direction", "", "thrust direction, body axes");
      f = ctx.A.scale(w[in.offset], d);
    } else {
      const SV3 v{{w[in.offset], w[in.offset + 1], w[in.offset + 2]}};
      const SV3 v_B = in.axes == Axes::inertial
                          ? ctx.A.mul_t(s.R_NB, v)
                          : ctx.A.mul(ctx.cmat(in.R_BX, in.name + "_R_BX", "", "input axes in the body frame"), v);
      (in.type == InputType::force ? f : t) = v_B;
    }
    const SV3 p = ctx.cvec(in.point_B, in.name + "_point", "m", "point of application, body components");
    const SV3 pxf = ctx.A.cross(p, f);
    for (int a = 0; a < 3; ++a) {
      W[a] += f[a];
      W[3 + a] += t[a] + pxf[a];
    }
  }
  for (ex& e : W) e = ctx.A.P.let(e);
  return W;  // [force; torque about O_B; modal forces]
}

ex joint_input(KaneContext& ctx, int j, int own) {
  ex f = 0;
  for (const Input& in : ctx.model.inputs)
    if (in.body == j && in.type == InputType::joint_torque && own >= in.speed && own < in.speed + in.speeds)
      f += ctx.x.inputs[in.offset + own - in.speed];
  return f;
}

namespace {

/// The system's centre of mass from the central body and its velocity, N
/// components: (Sum m r_O + R_NB S) / M and p / M (dynamics/sensors.hpp:
/// system_centre_of_mass).
std::pair<SV3, SV3> system_centre_of_mass(KaneContext& ctx) {
  ctx.P.section("the system's centre of mass (orbit-frame outputs)");
  ex mass = 0;
  SV3 first{{0, 0, 0}};
  for (std::size_t j = 0; j < ctx.model.bodies.size(); ++j) {
    const SymBodyWorkspace& s = ctx.body[j];
    const SV3 RS = ctx.A.mul(s.R_NB, first_moment_B(s));
    mass += s.M_body(0, 0);
    for (int a = 0; a < 3; ++a) first[a] = ctx.A.let(first[a] + s.M_body(0, 0) * s.r_NO_N[a] + RS[a]);
  }
  const ex inv_mass = ctx.A.let(1 / mass);
  const std::vector<ex> pH = compute_momentum(ctx);
  SV3 r, v;
  for (int a = 0; a < 3; ++a) r[a] = ctx.P.let(first[a] * inv_mass), v[a] = ctx.P.let(pH[a] * inv_mass);
  return {r, v};
}

/// "a, b, c": the values bound as temporaries of the output program, printed
/// for a statement that calls a support function; each added to dep.
std::string printed_lets(KaneContext& ctx, const std::vector<ex>& v, ex& dep) {
  OpCount dummy;
  std::vector<std::string> e;
  for (const ex& x : v) {
    const ex b = ctx.P.let(x);
    e.push_back(print_cpp(b, dummy));
    dep += b;
  }
  return fmt::format("{}", fmt::join(e, ", "));
}

/// "{a, b, c}": printed_lets as an array initializer.
std::string array_of(KaneContext& ctx, const std::vector<ex>& v, ex& dep) {
  return "{" + printed_lets(ctx, v, dep) + "}";
}

std::vector<ex> entries(const SV3& v) { return {v[0], v[1], v[2]}; }
std::vector<ex> entries(const SM3& R) {
  std::vector<ex> e;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) e.push_back(R(r, c));
  return e;
}

}  // namespace

void assign_sensor_outputs(KaneContext& ctx, const std::vector<ex>& wrenches,
                           const std::vector<std::vector<ex>>& accelerations, const std::string& y) {
  const Model& model = ctx.model;
  std::optional<std::pair<SV3, SV3>> com;
  if (std::any_of(model.sensors.begin(), model.sensors.end(), [](const Sensor& sn) { return orbit_sensor(sn.type); }))
    com = system_centre_of_mass(ctx);
  for (const Sensor& sn : model.sensors) {
    if (system_sensor(sn.type)) {
      ctx.P.section(fmt::format("output {}: {}", sn.name, to_string(sn.type)));
      const auto& [r_c, v_c] = *com;
      if (sn.type == SensorType::orbit_elements) {
        ex dep = 0;
        const std::string r = array_of(ctx, entries(r_c), dep), v = array_of(ctx, entries(v_c), dep);
        const ex mu = ctx.P.let(ctx.central_mu());
        dep += mu;
        OpCount dummy;
        ctx.P.statement(fmt::format("{{ const T r_c[3] = {}; const T v_c[3] = {}; orbit_elements_output(T({}), r_c, "
                                    "v_c, {} + {}); }}",
                                    r, v, print_cpp(mu, dummy), y, sn.offset),
                        dep);
      } else {
        const SV3& c = sn.type == SensorType::com_position ? r_c : v_c;
        for (int a = 0; a < 3; ++a) ctx.P.assign(fmt::format("{}[{}]", y, sn.offset + a), c[a]);
      }
      continue;
    }
    const int j = sn.body;
    const SymBodyWorkspace& s = ctx.body[j];
    ctx.P.section(fmt::format("output {}: {} of {}", sn.name, to_string(sn.type), model.bodies[j].name));
    ctx.C.group = model.bodies[j].name;
    const SM3 R_BX = ctx.cmat(sn.R_BX, sn.name + "_R_BX", "", "output axes in the body frame");
    const SV3 p = ctx.cvec(sn.point_B, sn.name + "_point", "m", "sensor point, body components");
    auto put = [&](const SV3& v_B, int offset) {
      const SV3 v_X = ctx.A.mul_t(R_BX, v_B);
      for (int a = 0; a < 3; ++a) ctx.P.assign(fmt::format("{}[{}]", y, offset + a), v_X[a]);
    };
    auto put_N = [&](const SV3& v_N, int offset) {
      for (int a = 0; a < 3; ++a) ctx.P.assign(fmt::format("{}[{}]", y, offset + a), v_N[a]);
    };
    switch (sn.type) {
      case SensorType::angular_velocity: put(s.w_B, sn.offset); break;
      case SensorType::attitude_lvlh:
      case SensorType::angular_velocity_lvlh: {
        const auto& [r_c, v_c] = *com;
        ex dep = 0;
        const std::string r = array_of(ctx, entries(r_c), dep), v = array_of(ctx, entries(v_c), dep);
        const std::string R = array_of(ctx, entries(ctx.A.mul(s.R_NB, R_BX)), dep);
        if (sn.type == SensorType::attitude_lvlh) {
          ctx.P.statement(fmt::format("{{ const T r_c[3] = {}; const T v_c[3] = {}; const T R_NX[9] = {}; "
                                      "attitude_lvlh_output(r_c, v_c, R_NX, {} + {}); }}",
                                      r, v, R, y, sn.offset),
                          dep);
        } else {
          const std::string w = array_of(ctx, entries(ctx.A.mul_t(R_BX, s.w_B)), dep);
          ctx.P.statement(fmt::format("{{ const T r_c[3] = {}; const T v_c[3] = {}; const T R_NX[9] = {}; const T "
                                      "w_X[3] = {}; angular_velocity_lvlh_output(r_c, v_c, R_NX, w_X, {} + {}); }}",
                                      r, v, R, w, y, sn.offset),
                          dep);
        }
        break;
      }
      case SensorType::attitude: {
        ex dep = 0;
        const std::string R = printed_lets(ctx, entries(ctx.A.mul(s.R_NB, R_BX)), dep);
        ctx.P.statement(fmt::format("attitude_quaternion({}, {} + {});", R, y, sn.offset), dep);
        break;
      }
      case SensorType::position: put_N(ctx.A.add(s.r_NO_N, ctx.A.mul(s.R_NB, p)), sn.offset); break;
      case SensorType::velocity: put_N(ctx.A.mul(s.R_NB, ctx.A.add(s.v_O_B, ctx.A.cross(s.w_B, p))), sn.offset); break;
      case SensorType::acceleration:
      case SensorType::specific_force: {
        // With gravity as a base acceleration (kane_context.hpp) the bodies'
        // accelerations are specific forces a - g; the acceleration adds g back.
        const auto& z = accelerations[j];
        const SV3 a_O{{z[0], z[1], z[2]}}, alpha{{z[3], z[4], z[5]}};
        SV3 a = ctx.A.add(ctx.A.add(a_O, ctx.A.cross(alpha, p)), ctx.A.cross(s.w_B, ctx.A.cross(s.w_B, p)));
        const bool gib = ctx.gravity_in_base_acceleration;
        const bool accel = sn.type == SensorType::acceleration;
        if (ctx.has_central()) {  // no base acceleration: a is the acceleration; the field at the point
          if (!accel) a = ctx.A.sub(a, ctx.A.mul_t(s.R_NB, central_field_at(ctx, ctx.A.add(s.r_NO_N, ctx.A.mul(s.R_NB, p)))));
        } else if (gib == accel) {  // acceleration from a - g, or a - g from a
          const SV3 g_B = ctx.A.mul_t(s.R_NB, ctx.gravity(1.0, "gravity", "gravity in N"));
          a = accel ? ctx.A.add(a, g_B) : ctx.A.sub(a, g_B);
        }
        put(a, sn.offset);
        break;
      }
      case SensorType::reaction: {
        const SV3 f{{wrenches[6 * j], wrenches[6 * j + 1], wrenches[6 * j + 2]}};
        // torque about the sensor's point: the model's O_B, which the generator's frame may have moved from
        // (codegen/joint_frames.hpp: the point is then -o_B in B' components; 0 otherwise)
        const SV3 t = ctx.A.sub(SV3{{wrenches[6 * j + 3], wrenches[6 * j + 4], wrenches[6 * j + 5]}}, ctx.A.cross(p, f));
        put(f, sn.offset);
        put(t, sn.offset + 3);
        break;
      }
      case SensorType::deflection: {
        const FlexibleData& fd = *model.bodies[j].flex;
        const int k = sn.node;
        SV3 d;
        for (int a = 0; a < 3; ++a) {
          ex sum = 0;
          for (int m = 0; m < fd.modes(); ++m)
            sum += ctx.c(fd.Phi(3 * k + a, m), fmt::format("{}_Phi_{}_{}", sn.name, a, m + 1), "m",
                         "mode shape at the node") * s.eta[m];
          if (fd.has_second_order(k) && fd.Gamma[k][a].size())
            for (int m = 0; m < fd.modes(); ++m)
              for (int n = 0; n < fd.modes(); ++n)
                sum += ctx.c(0.5 * fd.Gamma[k][a](m, n), fmt::format("{}_G_{}_{}_{}", sn.name, a, m + 1, n + 1),
                             "1/m", "half the foreshortening matrix at the node") * s.eta[m] * s.eta[n];
          d[a] = ctx.P.let(sum);
        }
        put(d, sn.offset);
        break;
      }
      default: break;  // the system's, above
    }
  }
}

std::string orbit_frame_support_code() {
  return R"(
// ---- atan2 of dual numbers (the orbit-frame outputs' Jacobian) ----
template <int W> inline Dual<W> atan2(const Dual<W>& y, const Dual<W>& x) { Dual<W> r; r.v = std::atan2(y.v, x.v); const double f = 1.0 / (x.v * x.v + y.v * y.v); for (int i = 0; i < W; ++i) r.d[i] = (x.v * y.d[i] - y.v * x.d[i]) * f; return r; }
)";
}

std::string attitude_support_code() {
  return R"(
// ---- attitude output: quaternion [w, x, y, z] of a rotation matrix, w >= 0 ----
// (Shepperd's method: the largest of 4w^2, 4x^2, 4y^2, 4z^2 is divided by.)
template <class T>
inline void attitude_quaternion(const T& R00, const T& R01, const T& R02, const T& R10, const T& R11, const T& R12,
                                const T& R20, const T& R21, const T& R22, T* qout) {
  using std::sqrt;
  const T tr = R00 + R11 + R22;
  T w, x, y, z;
  if (tr > R00 && tr > R11 && tr > R22) {
    const T s = 2.0 * sqrt(1.0 + tr);
    w = 0.25 * s, x = (R21 - R12) / s, y = (R02 - R20) / s, z = (R10 - R01) / s;
  } else if (R00 > R11 && R00 > R22) {
    const T s = 2.0 * sqrt(1.0 + R00 - R11 - R22);
    w = (R21 - R12) / s, x = 0.25 * s, y = (R01 + R10) / s, z = (R02 + R20) / s;
  } else if (R11 > R22) {
    const T s = 2.0 * sqrt(1.0 + R11 - R00 - R22);
    w = (R02 - R20) / s, x = (R01 + R10) / s, y = 0.25 * s, z = (R12 + R21) / s;
  } else {
    const T s = 2.0 * sqrt(1.0 + R22 - R00 - R11);
    w = (R10 - R01) / s, x = (R02 + R20) / s, y = (R12 + R21) / s, z = 0.25 * s;
  }
  const double sign = 0.0 > w ? -1.0 : 1.0;
  qout[0] = sign * w, qout[1] = sign * x, qout[2] = sign * y, qout[3] = sign * z;
}
)";
}

}  // namespace kanegen::codegen
