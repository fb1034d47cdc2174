// peer_model.hpp — shared by the peer-engine translators (mujoco_peer, simbody_peer).
//
// Reads a kanegen model file (../shared/spec/model-format.md), restricted to RIGID
// bodies, into a small read-only `Model`; reads a STATE.json (interface.md) into a
// `State` in kanegen's q/u ordering; reads the `udot` of a `kanegen eval` JSON; and
// provides the comparison and timing helpers both peers use.
//
// Deliberately independent of the kanegen runtime: the peers are outside checks, so
// they re-read the model format themselves (only the subset they can translate).
//
// Frame naming (Drake style): R_PJ = joint frame J's orientation in parent P
// (x_P = R_PJ x_J), p_PJ = J's origin from P's origin in P components, `_B` = body
// frame components, `_N` = inertial (ground) frame components.
#pragma once

#include <Eigen/Dense>
#include <yaml-cpp/yaml.h>
#include <nlohmann/json.hpp>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace peers {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using Eigen::VectorXd;

/// Thrown for a model or state the peers cannot (or refuse to) translate.
struct Refused : std::runtime_error {
  using std::runtime_error::runtime_error;
};

enum class JointType { revolute, prismatic, fixed, free, universal, gimbal, cylindrical, planar, ball };

/// One elementary motion of a joint, as model-format.md's joint table composes
/// them: a body-fixed (intrinsic) sequence from J to B, each axis in the frame
/// turned by the motions before it. `q`, `u`: the coordinate/speed offset within
/// the joint (a ball's quaternion takes q..q+3 and u..u+2).
struct Motion {
  enum class Kind { hinge, slide, ball, free } kind;
  Vector3d axis;  ///< unit axis (hinge, slide)
  int q = 0, u = 0;
};

struct Body {
  std::string name;
  int parent = -1;                         ///< index into Model::bodies; -1 = ground
  JointType joint = JointType::fixed;
  std::vector<Motion> motions;             ///< the joint as elementary motions, J to B
  Vector3d p_PJ = Vector3d::Zero();        ///< joint frame origin in the parent frame
  Matrix3d R_PJ = Matrix3d::Identity();    ///< joint frame orientation in the parent frame
  /// Spring and damper per speed (model-format.md: a number or one per coordinate;
  /// a ball joint: damping only, the same on its three speeds).
  std::vector<double> stiffness, damping, rest;
  double mass = 0;                         ///< kg
  Vector3d com_B = Vector3d::Zero();       ///< centre of mass from the body origin, B
  Matrix3d I_Bcm_B = Matrix3d::Zero();     ///< inertia about the com, B axes (a matrix)
  int q_index = -1, u_index = -1;          ///< first coordinate/speed in kanegen ordering
  int nq = 0, nu = 0;
  /// Where the joint's unit quaternion [w x y z] starts within q (-1: none).
  int quaternion_offset() const {
    return joint == JointType::free ? 3 : joint == JointType::ball ? 0 : -1;
  }
};

struct Model {
  std::string name;
  Vector3d gravity_N = Vector3d::Zero();
  std::vector<Body> bodies;                ///< parents first (as in the file)
  std::vector<std::string> q_names, u_names;
  int nq = 0, nu = 0;
  std::map<std::string, double> initial_q, initial_u;  ///< `initial:` as given (by name)
};

/// A state in kanegen's conventions (model-format.md / dynamics.md). Free joint:
/// q = [x y z qw qx qy qz] (origin in J, quaternion R_JB), u = [v_B, w_B].
struct State {
  double t = 0;
  VectorXd q, u;
};

// ---------------------------------------------------------------------------------
// Rotations
// ---------------------------------------------------------------------------------

/// R(quat) of dynamics.md: takes child components to parent components. The
/// quaternion [w, x, y, z] is normalized first.
inline Matrix3d rotation_from_quaternion(double w, double x, double y, double z) {
  const double n = std::sqrt(w * w + x * x + y * y + z * z);
  if (!(n > 0)) throw Refused("zero quaternion");
  return Eigen::Quaterniond(w / n, x / n, y / n, z / n).toRotationMatrix();
}

/// rpy: [r, p, y] = Rz(y) Ry(p) Rx(r).
inline Matrix3d rotation_from_rpy(double r, double p, double y) {
  using Eigen::AngleAxisd;
  return (AngleAxisd(y, Vector3d::UnitZ()) * AngleAxisd(p, Vector3d::UnitY()) *
          AngleAxisd(r, Vector3d::UnitX()))
      .toRotationMatrix();
}

/// An orthonormal, right-handed frame whose column `column` (0 = x, 1 = y, 2 = z)
/// is the unit vector `a`. Used to align a mobilizer's fixed axis with ours.
inline Matrix3d frame_with_axis(const Vector3d& a, int column) {
  const Vector3d e = a.normalized();
  // Any vector not parallel to e: the coordinate axis least aligned with it.
  Eigen::Index k;
  e.cwiseAbs().minCoeff(&k);
  const Vector3d t1 = (Vector3d::Unit(k) - e * e(k)).normalized();
  const Vector3d t2 = e.cross(t1);
  Matrix3d R;
  // Columns (e, t1, t2) are right-handed; rotate the triple so e lands in `column`.
  R.col(column) = e;
  R.col((column + 1) % 3) = t1;
  R.col((column + 2) % 3) = t2;
  return R;
}

// ---------------------------------------------------------------------------------
// Model reading
// ---------------------------------------------------------------------------------
namespace detail {

inline std::string where(const std::string& file, const YAML::Node& n, const std::string& field) {
  return file + ":" + std::to_string(n.Mark().line + 1) + ": " + field;
}

inline Vector3d vec3(const YAML::Node& n, const std::string& ctx) {
  if (!n.IsSequence() || n.size() != 3) throw Refused(ctx + ": expected a 3-vector");
  return {n[0].as<double>(), n[1].as<double>(), n[2].as<double>()};
}

inline Matrix3d mat3(const YAML::Node& n, const std::string& ctx) {
  if (!n.IsSequence() || n.size() != 3) throw Refused(ctx + ": expected a 3x3 list");
  Matrix3d M;
  for (int i = 0; i < 3; ++i) M.row(i) = vec3(n[i], ctx).transpose();
  return M;
}

/// `rotation:` — exactly one of rpy, matrix, axis_angle, quaternion [w,x,y,z].
inline Matrix3d rotation(const YAML::Node& n, const std::string& ctx) {
  if (!n) return Matrix3d::Identity();
  if (!n.IsMap() || n.size() != 1) throw Refused(ctx + ": expected one of rpy, matrix, axis_angle, quaternion");
  if (n["rpy"]) {
    const Vector3d rpy = vec3(n["rpy"], ctx + ".rpy");
    return rotation_from_rpy(rpy(0), rpy(1), rpy(2));
  }
  if (n["matrix"]) return mat3(n["matrix"], ctx + ".matrix");  // used as given (spec)
  if (n["axis_angle"]) {
    const YAML::Node aa = n["axis_angle"];
    const Vector3d axis = vec3(aa[0], ctx + ".axis_angle");
    return Eigen::AngleAxisd(aa[1].as<double>(), axis.normalized()).toRotationMatrix();
  }
  if (n["quaternion"]) {
    const YAML::Node q = n["quaternion"];
    if (!q.IsSequence() || q.size() != 4) throw Refused(ctx + ".quaternion: expected [w, x, y, z]");
    return rotation_from_quaternion(q[0].as<double>(), q[1].as<double>(), q[2].as<double>(),
                                    q[3].as<double>());
  }
  throw Refused(ctx + ": unknown rotation form");
}

/// `inertia:` — [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] (matrix entries) or a 3x3 list.
inline Matrix3d inertia(const YAML::Node& n, const std::string& ctx) {
  if (!n) return Matrix3d::Zero();
  if (n.IsSequence() && n.size() == 6) {
    double v[6];
    for (int i = 0; i < 6; ++i) v[i] = n[i].as<double>();
    Matrix3d I;
    I << v[0], v[3], v[4],  //
        v[3], v[1], v[5],   //
        v[4], v[5], v[2];
    return I;
  }
  const Matrix3d I = mat3(n, ctx);
  return 0.5 * (I + I.transpose());
}

/// `sequence: zyx` -> the unit axes in order.
inline std::vector<Vector3d> sequence_axes(const std::string& seq, const std::string& ctx) {
  if (seq.size() != 3) throw Refused(ctx + ": expected three letters from x, y, z");
  std::vector<Vector3d> axes;
  for (char c : seq) {
    if (c < 'x' || c > 'z') throw Refused(ctx + ": expected three letters from x, y, z");
    axes.push_back(Vector3d::Unit(c - 'x'));
  }
  return axes;
}

inline std::vector<Vector3d> axes_list(const YAML::Node& n, std::size_t count, const std::string& ctx) {
  if (!n.IsSequence() || n.size() != count) throw Refused(ctx + ": expected " + std::to_string(count) + " axes");
  std::vector<Vector3d> axes;
  for (std::size_t k = 0; k < count; ++k) axes.push_back(vec3(n[k], ctx).normalized());
  return axes;
}

/// The joint table of model-format.md as elementary motions, J to B.
inline std::vector<Motion> motions(JointType type, const YAML::Node& jn, const std::string& ctx) {
  using K = Motion::Kind;
  const Vector3d axis = jn["axis"] ? vec3(jn["axis"], ctx + ".joint.axis").normalized() : Vector3d(Vector3d::UnitZ());
  auto turns = [](const std::vector<Vector3d>& axes) {
    std::vector<Motion> out;
    for (std::size_t k = 0; k < axes.size(); ++k) out.push_back({K::hinge, axes[k], int(k), int(k)});
    return out;
  };
  switch (type) {
    case JointType::revolute: return {{K::hinge, axis, 0, 0}};
    case JointType::prismatic: return {{K::slide, axis, 0, 0}};
    case JointType::fixed: return {};
    case JointType::free: return {{K::free, Vector3d::Zero(), 0, 0}};
    case JointType::universal:
      return turns(jn["axes"] ? axes_list(jn["axes"], 2, ctx + ".joint.axes")
                              : std::vector<Vector3d>{Vector3d::UnitX(), Vector3d::UnitY()});
    case JointType::gimbal:
      if (jn["axes"]) return turns(axes_list(jn["axes"], 3, ctx + ".joint.axes"));
      return turns(sequence_axes(jn["sequence"] ? jn["sequence"].as<std::string>() : "xyz", ctx + ".joint.sequence"));
    case JointType::cylindrical: return {{K::hinge, axis, 0, 0}, {K::slide, axis, 1, 1}};
    case JointType::planar:
      return {{K::slide, Vector3d::UnitX(), 0, 0}, {K::slide, Vector3d::UnitY(), 1, 1},
              {K::hinge, Vector3d::UnitZ(), 2, 2}};
    case JointType::ball: return {{K::ball, Vector3d::Zero(), 0, 0}};
  }
  throw Refused(ctx + ".joint.type: unhandled");
}

/// A spring/damper key: absent (zeros), a number (every speed), or one entry per
/// coordinate. `ball`: one number for all three speeds.
inline std::vector<double> per_speed(const YAML::Node& n, int nu, bool ball, const std::string& ctx) {
  if (!n) return std::vector<double>(std::size_t(nu), 0.0);
  if (n.IsScalar()) return std::vector<double>(std::size_t(nu), n.as<double>());
  if (ball || !n.IsSequence() || n.size() != std::size_t(nu))
    throw Refused(ctx + ": expected a number or " + std::to_string(nu) + " numbers");
  std::vector<double> v;
  for (const auto& x : n) v.push_back(x.as<double>());
  return v;
}

}  // namespace detail

/// Reads a rigid-body model file. Refuses what the peers do not translate:
/// flexible bodies, prescribed motion, joints attached at nodes.
inline Model load_model(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw Refused(path + ": " + e.what());
  }
  Model m;
  m.name = root["name"] ? root["name"].as<std::string>() : "model";
  if (root["gravity"]) m.gravity_N = detail::vec3(root["gravity"], detail::where(path, root["gravity"], "gravity"));

  std::map<std::string, int> index;
  const YAML::Node bodies = root["bodies"];
  if (!bodies || !bodies.IsSequence()) throw Refused(path + ": bodies: expected a list");
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const YAML::Node bn = bodies[i];
    const std::string ctx = detail::where(path, bn, "bodies[" + std::to_string(i) + "]");
    Body b;
    b.name = bn["name"].as<std::string>();
    if (bn["flexible"]) throw Refused(ctx + ".flexible: flexible bodies are not translated to peer engines");
    const std::string parent = bn["parent"].as<std::string>();
    if (parent != "ground") {
      if (!index.count(parent)) throw Refused(ctx + ".parent: unknown or later body '" + parent + "'");
      b.parent = index.at(parent);
    }
    const YAML::Node jn = bn["joint"];
    const std::string type = jn["type"].as<std::string>();
    if (jn["motion"]) throw Refused(ctx + ".joint.motion: prescribed motion is not translated");
    if (jn["node"]) throw Refused(ctx + ".joint.node: joints at flexible nodes are not translated");
    static const std::map<std::string, JointType> types = {
        {"revolute", JointType::revolute},   {"prismatic", JointType::prismatic},
        {"fixed", JointType::fixed},         {"free", JointType::free},
        {"universal", JointType::universal}, {"gimbal", JointType::gimbal},
        {"cylindrical", JointType::cylindrical}, {"planar", JointType::planar},
        {"ball", JointType::ball}};
    if (!types.count(type)) throw Refused(ctx + ".joint.type: unknown joint type '" + type + "'");
    b.joint = types.at(type);
    if (jn["position"]) b.p_PJ = detail::vec3(jn["position"], ctx + ".joint.position");
    b.R_PJ = detail::rotation(jn["rotation"], ctx + ".joint.rotation");
    b.motions = detail::motions(b.joint, jn, ctx);
    b.nu = 0;
    for (const Motion& mo : b.motions)
      b.nu += mo.kind == Motion::Kind::free ? 6 : mo.kind == Motion::Kind::ball ? 3 : 1;
    const bool ball = b.joint == JointType::ball;
    if (ball && (jn["stiffness"] || jn["rest"]))
      throw Refused(ctx + ".joint: a ball joint takes damping only");
    b.stiffness = detail::per_speed(jn["stiffness"], b.nu, ball, ctx + ".joint.stiffness");
    b.damping = detail::per_speed(jn["damping"], b.nu, ball, ctx + ".joint.damping");
    b.rest = detail::per_speed(jn["rest"], b.nu, ball, ctx + ".joint.rest");
    if (bn["mass"]) b.mass = bn["mass"].as<double>();
    if (bn["com"]) b.com_B = detail::vec3(bn["com"], ctx + ".com");
    b.I_Bcm_B = detail::inertia(bn["inertia"], ctx + ".inertia");

    // Coordinate and speed names and ordering (model-format.md, "Joints").
    b.q_index = m.nq;
    b.u_index = m.nu;
    auto add = [&](std::vector<std::string> qs, std::vector<std::string> us) {
      for (auto& s : qs) m.q_names.push_back(b.name + "." + s);
      for (auto& s : us) m.u_names.push_back(b.name + "." + s);
      b.nq = int(qs.size());
      b.nu = int(us.size());
      m.nq += b.nq;
      m.nu += b.nu;
    };
    static const std::map<JointType, std::pair<std::vector<std::string>, std::vector<std::string>>> names = {
        {JointType::revolute, {{"angle"}, {"angle_rate"}}},
        {JointType::prismatic, {{"disp"}, {"disp_rate"}}},
        {JointType::fixed, {{}, {}}},
        {JointType::free, {{"x", "y", "z", "qw", "qx", "qy", "qz"}, {"vx", "vy", "vz", "wx", "wy", "wz"}}},
        {JointType::universal, {{"angle1", "angle2"}, {"angle1_rate", "angle2_rate"}}},
        {JointType::gimbal, {{"angle1", "angle2", "angle3"}, {"angle1_rate", "angle2_rate", "angle3_rate"}}},
        {JointType::cylindrical, {{"angle", "disp"}, {"angle_rate", "disp_rate"}}},
        {JointType::planar, {{"x", "y", "angle"}, {"x_rate", "y_rate", "angle_rate"}}},
        {JointType::ball, {{"qw", "qx", "qy", "qz"}, {"wx", "wy", "wz"}}}};
    add(names.at(b.joint).first, names.at(b.joint).second);
    index[b.name] = int(m.bodies.size());
    m.bodies.push_back(std::move(b));
  }
  if (const YAML::Node init = root["initial"]) {
    if (init["q"]) for (const auto& kv : init["q"]) m.initial_q[kv.first.as<std::string>()] = kv.second.as<double>();
    if (init["u"])
      for (const auto& kv : init["u"]) {
        std::string k = kv.first.as<std::string>();  // an older speed name means the rate
        if (std::find(m.u_names.begin(), m.u_names.end(), k) == m.u_names.end()) k += "_rate";
        m.initial_u[k] = kv.second.as<double>();
      }
  }
  return m;
}

// ---------------------------------------------------------------------------------
// States
// ---------------------------------------------------------------------------------

/// The state of interface.md: a name not given takes the model's `initial:` value,
/// else 0; a quaternion not given at all takes the initial one or the identity; a
/// quaternion given in part is refused; quaternions are normalized. Without a path,
/// the model's `initial:` state. Inputs `tau` are not supported (refused if non-zero).
inline State load_state(const Model& m, const std::optional<std::string>& path) {
  std::map<std::string, double> q = m.initial_q, u = m.initial_u;
  State s;
  if (path) {
    std::ifstream in(*path);
    if (!in) throw Refused(*path + ": cannot open");
    const nlohmann::json j = nlohmann::json::parse(in);
    s.t = j.value("t", 0.0);
    auto check = [&](const char* key, const std::vector<std::string>& names) {
      if (!j.contains(key)) return std::map<std::string, double>{};
      std::map<std::string, double> given;
      for (const auto& [k0, v] : j.at(key).items()) {
        std::string k = k0;  // a speed's older name (its coordinate's) means the rate
        if (std::string(key) == "u" && std::find(names.begin(), names.end(), k) == names.end() &&
            std::find(names.begin(), names.end(), k + "_rate") != names.end())
          k += "_rate";
        if (std::find(names.begin(), names.end(), k) == names.end())
          throw Refused(*path + ": " + key + "." + k + ": unknown name");
        given[k] = v.get<double>();
      }
      return given;
    };
    const auto gq = check("q", m.q_names), gu = check("u", m.u_names);
    // A quaternion given (in full) in the state replaces the initial one as a whole.
    for (const Body& b : m.bodies) {
      if (b.quaternion_offset() < 0) continue;
      int n = 0;
      for (const char* c : {".qw", ".qx", ".qy", ".qz"}) n += int(gq.count(b.name + c));
      if (n != 0 && n != 4) throw Refused(*path + ": q: quaternion of '" + b.name + "' given in part");
    }
    for (const auto& [k, v] : gq) q[k] = v;
    for (const auto& [k, v] : gu) u[k] = v;
    if (j.contains("tau"))
      for (const auto& [k, v] : j.at("tau").items())
        if (v.get<double>() != 0.0) throw Refused(*path + ": tau: inputs are not supported by the peers");
  }
  s.q = VectorXd::Zero(m.nq);
  s.u = VectorXd::Zero(m.nu);
  for (int i = 0; i < m.nq; ++i) if (q.count(m.q_names[i])) s.q(i) = q.at(m.q_names[i]);
  for (int i = 0; i < m.nu; ++i) if (u.count(m.u_names[i])) s.u(i) = u.at(m.u_names[i]);
  for (const Body& b : m.bodies) {
    if (b.quaternion_offset() < 0) continue;
    auto quat = s.q.segment<4>(b.q_index + b.quaternion_offset());
    int n = 0;
    for (const char* c : {".qw", ".qx", ".qy", ".qz"}) n += int(q.count(b.name + c));
    if (n == 0) quat << 1, 0, 0, 0;
    else if (n != 4) throw Refused("initial: quaternion of '" + b.name + "' given in part");
    if (!(quat.norm() > 0)) throw Refused("quaternion of '" + b.name + "' is zero");
    quat.normalize();
  }
  return s;
}

// ---------------------------------------------------------------------------------
// Reference comparison, output, timing
// ---------------------------------------------------------------------------------

/// How a peer's u̇ compares with a `kanegen eval` JSON (fields u_names, udot, and,
/// when present, M and F in kanegen's coordinates).
struct Comparison {
  /// Forward error: max_i |udot_i - ref_i| / max_i |ref_i| (entries matched by name).
  double max_rel_diff = 0;
  /// 2-norm condition number λmax/λmin of kanegen's M (NaN without M): the forward
  /// error of ANY double-precision solver can reach about cond_M · 1e-16.
  double cond_M = std::numeric_limits<double>::quiet_NaN();
  /// Normwise backward error of the peer's u̇ in kanegen's equations,
  /// ‖M u̇ − F‖∞ / (‖M‖∞ ‖u̇‖∞ + ‖F‖∞) (NaN without M, F): of the order of 1e-16
  /// when both engines define the same M and F, whatever the conditioning.
  double backward_error = std::numeric_limits<double>::quiet_NaN();
};

inline Comparison compare(const Model& m, const VectorXd& udot, const std::string& ref_path) {
  std::ifstream in(ref_path);
  if (!in) throw Refused(ref_path + ": cannot open");
  const nlohmann::json j = nlohmann::json::parse(in);
  const auto names = j.at("u_names").get<std::vector<std::string>>();
  const auto ref = j.at("udot").get<std::vector<double>>();
  if (names.size() != std::size_t(m.nu) || ref.size() != names.size())
    throw Refused(ref_path + ": u_names/udot do not match the model's " + std::to_string(m.nu) + " speeds");
  // perm[k]: our index of the reference's k-th speed.
  std::vector<int> perm(names.size());
  for (std::size_t k = 0; k < names.size(); ++k) {
    const auto it = std::find(m.u_names.begin(), m.u_names.end(), names[k]);
    if (it == m.u_names.end()) throw Refused(ref_path + ": unknown speed name " + names[k]);
    perm[k] = int(it - m.u_names.begin());
  }
  Comparison c;
  double diff = 0, scale = 0;
  for (std::size_t k = 0; k < names.size(); ++k) {
    diff = std::max(diff, std::abs(udot(perm[k]) - ref[k]));
    scale = std::max(scale, std::abs(ref[k]));
  }
  c.max_rel_diff = scale > 0 ? diff / scale : diff;
  if (j.contains("M") && j.contains("F") && m.nu > 0) {
    using MatrixXl = Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>;
    using VectorXl = Eigen::Matrix<long double, Eigen::Dynamic, 1>;
    const auto rows = j.at("M").get<std::vector<std::vector<double>>>();
    const auto F = j.at("F").get<std::vector<double>>();
    const Eigen::Index n = m.nu;
    MatrixXl M(n, n);
    VectorXl f(n), x(n);
    for (Eigen::Index r = 0; r < n; ++r) {
      for (Eigen::Index s = 0; s < n; ++s) M(r, s) = rows.at(r).at(s);
      f(r) = F.at(r);
      x(r) = udot(perm[r]);  // the peer's u̇ in the reference's ordering
    }
    const Eigen::VectorXd lambda =
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(M.cast<double>(), Eigen::EigenvaluesOnly).eigenvalues();
    c.cond_M = lambda(n - 1) / lambda(0);
    const long double norm_M = M.cwiseAbs().rowwise().sum().maxCoeff();
    c.backward_error = double((M * x - f).cwiseAbs().maxCoeff() /
                              (norm_M * x.cwiseAbs().maxCoeff() + f.cwiseAbs().maxCoeff()));
  }
  return c;
}

/// Median over batches of the mean wall time of one call, in ns. `n_calls` calls
/// are timed in batches of `batch` (so the clock's own cost, ~20 ns, is spread
/// over the batch), after n_calls/10 untimed warm-up calls.
template <class F>
double median_ns_per_call(F&& call, long n_calls, int batch = 10) {
  using clock = std::chrono::steady_clock;
  for (long i = 0; i < std::max(1L, n_calls / 10); ++i) call();
  const long n_batches = std::max(1L, n_calls / batch);
  std::vector<double> per_call(n_batches);
  for (long b = 0; b < n_batches; ++b) {
    const auto t0 = clock::now();
    for (int i = 0; i < batch; ++i) call();
    const auto t1 = clock::now();
    per_call[b] = std::chrono::duration<double, std::nano>(t1 - t0).count() / batch;
  }
  std::nth_element(per_call.begin(), per_call.begin() + n_batches / 2, per_call.end());
  return per_call[n_batches / 2];
}

/// The JSON every peer prints: model, engine, u_names, udot (kanegen conventions),
/// and when asked max_rel_diff (against REF.json) and ns_per_eval.
inline nlohmann::ordered_json report(const Model& m, const std::string& engine, const VectorXd& udot) {
  nlohmann::ordered_json j;
  j["model"] = m.name;
  j["engine"] = engine;
  j["u_names"] = m.u_names;
  j["udot"] = std::vector<double>(udot.data(), udot.data() + udot.size());
  return j;
}


// ---------------------------------------------------------------------------------
// Command line shared by the peers:  X_peer MODEL.yaml [--state S.json] [--check REF.json]
//                                           [--time N] [--tol T]
// ---------------------------------------------------------------------------------

struct Options {
  std::string model;
  std::optional<std::string> state, check;
  long time_calls = 0;
  double tol = 1e-12;
};

/// Adds the shared options to `app` (a peer may add its own before parsing).
inline void add_options(CLI::App& app, Options& o) {
  app.add_option("MODEL", o.model, "model file (rigid bodies only)")->required()->check(CLI::ExistingFile);
  app.add_option("--state", o.state, "STATE.json (default: the model's initial: state)")->check(CLI::ExistingFile);
  app.add_option("--check", o.check, "kanegen eval JSON: print the max relative difference of udot")
      ->check(CLI::ExistingFile);
  app.add_option("--time", o.time_calls, "time N evaluations; print the median ns per evaluation");
  app.add_option("--tol", o.tol, "exit 1 if the relative difference exceeds this (default 1e-12)");
}

/// Prints the report (JSON on stdout) after the check and the timing; returns the
/// exit status: 0, or 1 when --check finds a difference above --tol.
inline int finish(const Options& o, const Model& m, const std::string& engine, const VectorXd& udot,
                  const std::function<void()>& one_evaluation) {
  auto j = report(m, engine, udot);
  int status = 0;
  if (o.check) {
    const Comparison c = compare(m, udot, *o.check);
    j["max_rel_diff"] = c.max_rel_diff;
    if (!std::isnan(c.cond_M)) {
      j["cond_M"] = c.cond_M;
      j["backward_error"] = c.backward_error;
    }
    // the same equations: a forward difference within tol, or (ill-conditioned
    // M, where two correct solvers differ by up to cond(M) 1e-16) a backward
    // error in kanegen's M u-dot = F below 1e-14
    if (!(c.max_rel_diff <= o.tol || c.backward_error <= 1e-14)) status = 1;
  }
  if (o.time_calls > 0) j["ns_per_eval"] = median_ns_per_call(one_evaluation, o.time_calls);
  std::cout << j.dump(1) << "\n";
  return status;
}

}  // namespace peers
