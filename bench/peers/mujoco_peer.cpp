// mujoco_peer.cpp — a kanegen model (rigid bodies) built in MuJoCo 2.2, as an
// outside check of kanegen's u̇ and a speed reference.
//
//   mujoco_peer MODEL.yaml [--state S.json] [--check REF.json] [--time N] [--xml OUT.xml]
//               [--kanegen] [--rounds R] [--work-precision REF_END.json --t-end T]
//
// With --kanegen, kanegen's generated (JIT: at the default flags, which add an
// AVX2 clone picked at load time, and for baseline x86-64 alone) and generic engines are built from
// the same file by kanegen's own loader, their u-dot checked against MuJoCo's
// (--tol) and all three timed interleaved in this process (R rounds, each
// engine one batch of ~1 ms per round; medians). With --work-precision, the
// final-state error against REF_END.json (STATE.json) against wall time, for
// MuJoCo's RK4 at a sweep of steps and kanegen's integrators at a sweep of
// tolerances (generated engine), and the wall time each needs for a final
// error of 1e-6 and 1e-8.
//
// Prints JSON: u_names and udot in kanegen's conventions, max_rel_diff against a
// `kanegen eval` JSON (--check), ns_per_eval = median wall time of one mj_forward
// (--time N). Exit 0; 1 when the difference exceeds --tol (1e-12); 2 when the model
// or state is refused (also by MuJoCo's compiler).
//
// Translation (see NOTES.md for the derivations):
//   * Every kanegen body becomes an MJCF <body> nested in its parent's, with
//     pos = p_PJ and quat = quat(R_PJ): a MuJoCo body frame at q = 0 IS our joint
//     frame J, and our body frame B is MuJoCo's body frame for every q.
//   * revolute -> hinge, prismatic -> slide, both at pos 0 with our `axis` (given in
//     the child frame at q = 0, i.e. in J): MuJoCo then puts the child at
//     R_PJ·Rot(axis, θ) and at p_PJ + R_PJ·axis·s, exactly dynamics.md's table.
//     Spring and damper: stiffness = k, springref = rest, damping = c, so MuJoCo's
//     passive force is -k(q - rest) - c q̇ as ours.
//   * universal, gimbal, cylindrical, planar -> the hinges and slides of our joint
//     table in one body, in order (MuJoCo composes a body's joints as a body-fixed
//     sequence, each axis in the frame the joints before it turned); ball -> ball
//     (qpos = our quaternion R_JB, qvel = our ω_B: both MuJoCo's conventions too),
//     its damper on the three dofs, no spring.
//   * fixed -> a body without joint (welded to its parent).
//   * free -> MuJoCo free joint (allowed only on children of the world body in 2.2).
//     Its qpos/qvel are world-frame position, quaternion, world linear velocity of the
//     body origin and body-frame angular velocity: converted here (FreeJoint below).
//   * inertia: <inertial pos=com quat=q_BI diaginertia=λ> with the principal axes
//     computed here in double precision (MuJoCo 2.2's own `fullinertia`
//     diagonalization stops at a 1e-12 absolute tolerance).
//   * everything that would add forces is off: no geoms, contacts, constraints,
//     limits, friction loss, armature, fluid (density = viscosity = 0).
#include "peer_model.hpp"

#include <mujoco/mujoco.h>
#include <fmt/format.h>

#include "bench_support.hpp"
#include "codegen/jit_generator.hpp"
#include "engine/generic_engine.hpp"
#include "engine/jit.hpp"
#include "engine/load_model.hpp"
#include "model/state_io.hpp"
#include "sim/simulate.hpp"
#include "sim/work_precision.hpp"

#include <cstring>
#include <memory>

namespace {

using namespace peers;
using Eigen::Quaterniond;

// ---------------------------------------------------------------------------------
// MJCF generation
// ---------------------------------------------------------------------------------

/// Shortest decimal that reads back as the same double (fmt's "{}").
std::string num(double x) { return fmt::format("{}", x); }
std::string vec(const Vector3d& v) { return fmt::format("{} {} {}", v(0), v(1), v(2)); }
std::string quat(const Quaterniond& q) {
  const Quaterniond n = q.normalized();
  return fmt::format("{} {} {} {}", n.w(), n.x(), n.y(), n.z());
}

/// Principal moments and axes of a symmetric inertia: I_B = R_BI diag(λ) R_BIᵀ,
/// with R_BI a proper rotation (det +1), returned as the quaternion q_BI.
struct Principal {
  Vector3d moments;
  Quaterniond q_BI;
};
Principal principal_axes(const Matrix3d& I_B) {
  Eigen::SelfAdjointEigenSolver<Matrix3d> eig(I_B);
  Matrix3d R_BI = eig.eigenvectors();
  if (R_BI.determinant() < 0) R_BI.col(2) = -R_BI.col(2);  // a reflection is no rotation
  return {eig.eigenvalues(), Quaterniond(R_BI)};
}

/// The MJCF joint of one elementary motion: named after its first speed (a free
/// joint after its body).
std::string joint_name(const Model& m, const Body& b, const Motion& mo) {
  return mo.kind == Motion::Kind::free ? b.name + ".free" : m.u_names[b.u_index + mo.u];
}

void write_body(const Model& m, int i, const std::vector<std::vector<int>>& children, std::string& xml,
                int depth) {
  const Body& b = m.bodies[i];
  const std::string ind(2 * depth, ' ');
  xml += fmt::format("{}<body name=\"{}\" pos=\"{}\" quat=\"{}\">\n", ind, b.name, vec(b.p_PJ),
                     quat(Quaterniond(b.R_PJ)));
  for (const Motion& mo : b.motions) {
    if (mo.kind == Motion::Kind::free) {
      if (b.parent != -1)
        throw Refused("body '" + b.name + "': MuJoCo 2.2 allows a free joint only on a child of the world body");
      xml += fmt::format(
          "{}  <joint name=\"{}\" type=\"free\" stiffness=\"0\" damping=\"0\" armature=\"0\" "
          "frictionloss=\"0\"/>\n",
          ind, joint_name(m, b, mo));
      continue;
    }
    // MuJoCo composes a body's joints in order, each axis in the frame the joints
    // before it turned: the body-fixed sequence of our joint table.
    const std::string type = mo.kind == Motion::Kind::hinge ? "hinge" : mo.kind == Motion::Kind::slide ? "slide" : "ball";
    const std::string axis = mo.kind == Motion::Kind::ball ? "" : fmt::format(" axis=\"{}\"", vec(mo.axis));
    // A ball joint has a damper only (stiffness 0).
    xml += fmt::format(
        "{}  <joint name=\"{}\" type=\"{}\" pos=\"0 0 0\"{} stiffness=\"{}\" springref=\"{}\" damping=\"{}\" "
        "armature=\"0\" frictionloss=\"0\" limited=\"false\"/>\n",
        ind, joint_name(m, b, mo), type, axis, num(b.stiffness[mo.u]), num(b.rest[mo.u]), num(b.damping[mo.u]));
  }
  if (b.mass > 0) {
    const Principal p = principal_axes(b.I_Bcm_B);
    xml += fmt::format("{}  <inertial pos=\"{}\" quat=\"{}\" mass=\"{}\" diaginertia=\"{}\"/>\n", ind,
                       vec(b.com_B), quat(p.q_BI), num(b.mass), vec(p.moments));
  }
  for (int c : children[i]) write_body(m, c, children, xml, depth + 1);
  xml += ind + "</body>\n";
}

/// The MJCF text of the model.
std::string mjcf(const Model& m) {
  std::vector<std::vector<int>> children(m.bodies.size());
  std::vector<int> roots;
  for (std::size_t i = 0; i < m.bodies.size(); ++i)
    (m.bodies[i].parent < 0 ? roots : children[m.bodies[i].parent]).push_back(int(i));
  std::string xml = fmt::format("<mujoco model=\"{}\">\n", m.name);
  // Explicit inertials only, no mass/inertia bounds or balancing, no body fusion.
  xml += "  <compiler angle=\"radian\" inertiafromgeom=\"false\" boundmass=\"0\" boundinertia=\"0\" "
         "balanceinertia=\"false\" fusestatic=\"false\"/>\n";
  // Gravity; no fluid forces; no contact or constraint of any kind. Passive forces
  // (our springs and dampers) and gravity stay enabled.
  xml += fmt::format("  <option gravity=\"{}\" density=\"0\" viscosity=\"0\">\n", vec(m.gravity_N));
  xml += "    <flag contact=\"disable\" constraint=\"disable\" equality=\"disable\" "
         "frictionloss=\"disable\" limit=\"disable\" actuation=\"disable\"/>\n";
  xml += "  </option>\n  <worldbody>\n";
  for (int r : roots) write_body(m, r, children, xml, 2);
  xml += "  </worldbody>\n</mujoco>\n";
  return xml;
}

/// Compiles MJCF text through MuJoCo's virtual file system (no temporary file).
mjModel* compile(const std::string& xml) {
  auto vfs = std::make_unique<mjVFS>();  // ~2 MB: not on the stack
  mj_defaultVFS(vfs.get());
  const char* file = "peer_model.xml";
  if (mj_makeEmptyFileVFS(vfs.get(), file, int(xml.size())) != 0) throw Refused("MuJoCo VFS: cannot add file");
  const int k = mj_findFileVFS(vfs.get(), file);
  std::memcpy(vfs->filedata[k], xml.data(), xml.size());
  char error[1000] = "";
  mjModel* m = mj_loadXML(file, vfs.get(), error, sizeof error);
  mj_deleteVFS(vfs.get());
  if (!m) throw Refused(std::string("MuJoCo refused the model: ") + error);
  return m;
}

// ---------------------------------------------------------------------------------
// The peer: kanegen state -> qpos/qvel, mj_forward, qacc -> kanegen u̇
// ---------------------------------------------------------------------------------

class MujocoPeer {
 public:
  explicit MujocoPeer(const Model& model) : model_(model), xml_(mjcf(model)) {
    m_ = compile(xml_);
    d_ = mj_makeData(m_);
    if (m_->nv != model.nu) throw Refused(fmt::format("MuJoCo has {} dofs, kanegen {}", m_->nv, model.nu));
    for (const Body& b : model.bodies)
      for (const Motion& mo : b.motions) {
        const std::string jname = joint_name(model, b, mo);
        const int j = mj_name2id(m_, mjOBJ_JOINT, jname.c_str());
        if (j < 0) throw Refused("MuJoCo lost joint " + jname);
        adr_.push_back({&b, &mo, m_->jnt_qposadr[j], m_->jnt_dofadr[j]});
      }
  }
  ~MujocoPeer() {
    mj_deleteData(d_);
    mj_deleteModel(m_);
  }
  MujocoPeer(const MujocoPeer&) = delete;
  MujocoPeer& operator=(const MujocoPeer&) = delete;

  const std::string& xml() const { return xml_; }

  /// Writes our (q, u) into d->qpos, d->qvel. Hinge, slide: the coordinate and
  /// its rate. Ball: the quaternion R_JB and ω_B (MuJoCo's ball qvel is in the
  /// child frame, as ours).
  ///
  /// Free joint (parent = ground, joint frame J fixed in N; R_NB = R_NJ R(quat)):
  ///   qpos[0:3] = p_NJ + R_NJ [x y z]        body origin in N
  ///   qpos[3:7] = quat(R_NJ) ⊗ quat          orientation of B in N
  ///   qvel[0:3] = R_NB v_B                   v_N: velocity of the body origin in N
  ///   qvel[3:6] = ω_B                        MuJoCo's angular velocity is in B too
  void set_state(const State& s) {
    for (const Adr& a : adr_) {
      const Body& b = *a.body;
      if (a.motion->kind != Motion::Kind::free) {
        const int nq = a.motion->kind == Motion::Kind::ball ? 4 : 1, nv = a.motion->kind == Motion::Kind::ball ? 3 : 1;
        for (int k = 0; k < nq; ++k) d_->qpos[a.qpos + k] = s.q(b.q_index + a.motion->q + k);
        for (int k = 0; k < nv; ++k) d_->qvel[a.dof + k] = s.u(b.u_index + a.motion->u + k);
        continue;
      }
      const Vector3d x = s.q.segment<3>(b.q_index);
      const Quaterniond q_JB(s.q(b.q_index + 3), s.q(b.q_index + 4), s.q(b.q_index + 5), s.q(b.q_index + 6));
      const Quaterniond q_NB = (Quaterniond(b.R_PJ) * q_JB.normalized()).normalized();
      const Vector3d p_N = b.p_PJ + b.R_PJ * x;
      const Vector3d v_N = q_NB.toRotationMatrix() * s.u.segment<3>(b.u_index);
      const Vector3d w_B = s.u.segment<3>(b.u_index + 3);
      for (int k = 0; k < 3; ++k) {
        d_->qpos[a.qpos + k] = p_N(k);
        d_->qvel[a.dof + k] = v_N(k);
        d_->qvel[a.dof + 3 + k] = w_B(k);
      }
      d_->qpos[a.qpos + 3] = q_NB.w();
      d_->qpos[a.qpos + 4] = q_NB.x();
      d_->qpos[a.qpos + 5] = q_NB.y();
      d_->qpos[a.qpos + 6] = q_NB.z();
    }
  }

  /// One evaluation: what --time measures.
  void forward() { mj_forward(m_, d_); }

  /// Integrates from `s` over t_end with MuJoCo's RK4 at step h (mj_step, as a
  /// MuJoCo user would); returns the final (q, u) in kanegen's order (rigid
  /// joints other than free: qpos, qvel are q, u).
  std::pair<VectorXd, VectorXd> rk4(const State& s, double h, double t_end) {
    mj_resetData(m_, d_);
    set_state(s);
    m_->opt.integrator = mjINT_RK4;
    m_->opt.timestep = h;
    const long n = std::lround(t_end / h);
    for (long i = 0; i < n; ++i) mj_step(m_, d_);
    VectorXd q(model_.nq), u(model_.nu);
    for (const Adr& a : adr_) {
      if (a.motion->kind == Motion::Kind::free) throw Refused("work-precision: free joints are not converted back");
      const int nq = a.motion->kind == Motion::Kind::ball ? 4 : 1, nv = a.motion->kind == Motion::Kind::ball ? 3 : 1;
      for (int k = 0; k < nq; ++k) q(a.body->q_index + a.motion->q + k) = d_->qpos[a.qpos + k];
      for (int k = 0; k < nv; ++k) u(a.body->u_index + a.motion->u + k) = d_->qvel[a.dof + k];
    }
    return {q, u};
  }

  /// d->qacc in kanegen's u̇ (call after set_state and forward, with the same s).
  ///
  /// Free joint: with a_N = qacc[0:3] (= d/dt v_N) and ω̇_B = qacc[3:6],
  ///   v_B = R_NBᵀ v_N  =>  v̇_B = R_NBᵀ a_N + (d/dt R_NBᵀ) v_N = R_NBᵀ a_N − ω_B × v_B
  ///   (Ṙ_NB = R_NB [ω_B]×), and ω̇_B (B components) is MuJoCo's qacc[3:6] as it is.
  VectorXd udot(const State& s) const {
    VectorXd ud(model_.nu);
    for (const Adr& a : adr_) {
      const Body& b = *a.body;
      if (a.motion->kind != Motion::Kind::free) {
        const int nv = a.motion->kind == Motion::Kind::ball ? 3 : 1;
        for (int k = 0; k < nv; ++k) ud(b.u_index + a.motion->u + k) = d_->qacc[a.dof + k];
        continue;
      }
      const Quaterniond q_NB(d_->qpos[a.qpos + 3], d_->qpos[a.qpos + 4], d_->qpos[a.qpos + 5],
                             d_->qpos[a.qpos + 6]);
      const Matrix3d R_NB = q_NB.normalized().toRotationMatrix();
      const Vector3d a_N(d_->qacc + a.dof);
      const Vector3d wdot_B(d_->qacc + a.dof + 3);
      const Vector3d v_B = s.u.segment<3>(b.u_index), w_B = s.u.segment<3>(b.u_index + 3);
      ud.segment<3>(b.u_index) = R_NB.transpose() * a_N - w_B.cross(v_B);
      ud.segment<3>(b.u_index + 3) = wdot_B;
    }
    return ud;
  }

  /// Largest relative error of what MuJoCo compiled against what we asked for:
  /// body frames (pos, rotation), joint axes, com, mass and inertia about the com
  /// (re-assembled from MuJoCo's principal moments and iquat). A diagnostic for the
  /// 1e-12 comparison: it should be ~1e-16.
  double compile_error() const {
    double err = 0;
    auto upd = [&err](double diff, double scale) { err = std::max(err, diff / std::max(scale, 1e-300)); };
    for (const Body& b : model_.bodies) {
      const int id = mj_name2id(m_, mjOBJ_BODY, b.name.c_str());
      const mjtNum* bq = m_->body_quat + 4 * id;
      const Matrix3d R = Quaterniond(bq[0], bq[1], bq[2], bq[3]).toRotationMatrix();
      if (b.joint != JointType::free) {
        upd((R - b.R_PJ).cwiseAbs().maxCoeff(), 1);
        upd((Vector3d(m_->body_pos + 3 * id) - b.p_PJ).cwiseAbs().maxCoeff(), std::max(1.0, b.p_PJ.norm()));
      }
      if (b.mass > 0) {
        const mjtNum* iq = m_->body_iquat + 4 * id;
        const Matrix3d R_BI = Quaterniond(iq[0], iq[1], iq[2], iq[3]).toRotationMatrix();
        const Matrix3d I = R_BI * Vector3d(m_->body_inertia + 3 * id).asDiagonal() * R_BI.transpose();
        upd((I - b.I_Bcm_B).cwiseAbs().maxCoeff(), b.I_Bcm_B.cwiseAbs().maxCoeff());
        upd(std::abs(m_->body_mass[id] - b.mass), b.mass);
        upd((Vector3d(m_->body_ipos + 3 * id) - b.com_B).cwiseAbs().maxCoeff(), std::max(1.0, b.com_B.norm()));
      }
    }
    for (const Adr& a : adr_)
      if (a.motion->kind == Motion::Kind::hinge || a.motion->kind == Motion::Kind::slide) {
        const int j = m_->dof_jntid[a.dof];
        upd((Vector3d(m_->jnt_axis + 3 * j) - a.motion->axis).cwiseAbs().maxCoeff(), 1);
      }
    return err;
  }

 private:
  struct Adr {
    const Body* body;
    const Motion* motion;
    int qpos, dof;  ///< first qpos / qvel (dof) address of the motion's MuJoCo joint
  };
  const Model& model_;
  std::string xml_;
  mjModel* m_ = nullptr;
  mjData* d_ = nullptr;
  std::vector<Adr> adr_;
};

}  // namespace

using Clock = std::chrono::steady_clock;

/// Largest normwise backward error accepted as "the same equations": a peer's
/// u-dot x is checked in kanegen's M x = F. The forward difference of two
/// correct solvers can reach cond(M) 1e-16 (chain_64: cond(M) ~ 1e4 .. 1e5).
constexpr double kBackwardTol = 1e-14;

/// ||M x - F||_inf / (||M||_inf ||x||_inf + ||F||_inf).
double backward_error(const kanegen::MatX& M, const kanegen::VecX& F, const VectorXd& x) {
  const double nM = M.cwiseAbs().rowwise().sum().maxCoeff();
  return (M * x - F).cwiseAbs().maxCoeff() / (nM * x.cwiseAbs().maxCoeff() + F.cwiseAbs().maxCoeff());
}

double max_rel(const VectorXd& a, const VectorXd& ref) {
  const double scale = ref.cwiseAbs().maxCoeff();
  return (a - ref).cwiseAbs().maxCoeff() / (scale > 0 ? scale : 1.0);
}

/// Median wall time of `repeats` runs of f (which returns the final error).
template <class F>
std::pair<double, double> timed(F&& f, int repeats) {
  std::vector<double> wall;
  double err = 0;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = Clock::now();
    err = f();
    wall.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
  }
  std::sort(wall.begin(), wall.end());
  return {err, wall[wall.size() / 2]};
}


int main(int argc, char** argv) {
  CLI::App app{"kanegen model -> MuJoCo 2.2: u-dot in kanegen conventions, check and timing"};
  Options opt;
  add_options(app, opt);
  std::string xml_out, wp_ref;
  bool with_kanegen = false, native = false, compact = false;
  int rounds = 31;
  double t_end = 10.0;
  app.add_option("--xml", xml_out, "also write the generated MJCF to this file");
  app.add_flag("--kanegen", with_kanegen, "also check and time kanegen's generated and generic engines, interleaved");
  app.add_flag("--native", native, "also time kanegen's generated code compiled with -march=native");
  app.add_flag("--compact", compact,
               "also time kanegen's u-dot as compact code (kernels shared by bodies, --udot-code compact), baseline ISA");
  std::string compact_form = "auto";
  app.add_option("--compact-form", compact_form, "the u-dot form of --compact's code (auto, composite, articulated)");
  app.add_option("--rounds", rounds, "interleaved timing rounds (default 31)");
  app.add_option("--work-precision", wp_ref, "reference end state (STATE.json): error against wall time")
      ->check(CLI::ExistingFile);
  app.add_option("--t-end", t_end, "simulated time of the work-precision runs (default 10)");
  CLI11_PARSE(app, argc, argv);
  try {
    const Model model = load_model(opt.model);
    const State s = load_state(model, opt.state);
    MujocoPeer peer(model);
    if (!xml_out.empty()) std::ofstream(xml_out) << peer.xml();
    peer.set_state(s);
    peer.forward();
    const VectorXd ud = peer.udot(s);
    std::cerr << fmt::format("mujoco_peer: {} (MuJoCo {}): compiled-model relative error {:.2e}\n", model.name,
                             mj_version(), peer.compile_error());
    if (!with_kanegen && wp_ref.empty()) return finish(opt, model, "mujoco", ud, [&] { peer.forward(); });

    auto j = report(model, "mujoco", ud);
    const kanegen::Model km = kanegen::load_model(opt.model);
    kanegen::GenericEngine generic(km);
    const auto jit_t0 = Clock::now();
    auto generated = kanegen::jit_load(km, kanegen::codegen::jit_code_generator());
    j["kanegen_jit_seconds"] = std::chrono::duration<double>(Clock::now() - jit_t0).count();
    // the baseline x86-64 code alone (no AVX2 clone): the instruction set of
    // Debian's MuJoCo build, what an outside harness compiling the header gets
    kanegen::JitOptions jb;
    jb.dispatch = false;
    auto generated_baseline = kanegen::jit_load(km, kanegen::codegen::jit_code_generator(), jb);
    std::unique_ptr<kanegen::GeneratedEngine> generated_compact;
    if (compact) {
      kanegen::codegen::GeneratorOptions go;
      go.udot_code = "compact";
      go.udot_form = compact_form;
      generated_compact = kanegen::jit_load(km, kanegen::codegen::jit_code_generator(go), jb);
    }
    std::unique_ptr<kanegen::GeneratedEngine> generated_native;
    if (native) {
      kanegen::JitOptions jn;
      jn.native = true;
      generated_native = kanegen::jit_load(km, kanegen::codegen::jit_code_generator(), jn);
    }
    const kanegen::VecX q = s.q, u = s.u, tau = kanegen::VecX::Zero(km.nu);
    kanegen::VecX ud_gen, ud_gen2;
    generated->udot(q, u, tau, ud_gen);
    generic.udot(q, u, tau, ud_gen2);
    j["max_rel_diff_generated"] = max_rel(ud_gen, ud);
    j["max_rel_diff_generic"] = max_rel(ud_gen2, ud);
    kanegen::MatX M;
    kanegen::VecX F;
    generic.mass_matrix(q, M);
    generic.forcing(q, u, tau, F);
    const double be = backward_error(M, F, ud);
    j["backward_error_mujoco"] = be;
    j["cond_M"] = [&] {
      const Eigen::SelfAdjointEigenSolver<kanegen::MatX> es(M, Eigen::EigenvaluesOnly);
      return es.eigenvalues().maxCoeff() / es.eigenvalues().minCoeff();
    }();
    const bool same = (max_rel(ud_gen, ud) <= opt.tol && max_rel(ud_gen2, ud) <= opt.tol) || be <= kBackwardTol;
    int status = 0;
    if (!same) {
      std::cerr << fmt::format("mujoco_peer: u-dot differs from kanegen's (generated {:.2e}, generic {:.2e}): "
                               "not timed\n", max_rel(ud_gen, ud), max_rel(ud_gen2, ud));
      status = 1;
    } else if (with_kanegen) {
      std::vector<std::function<void()>> engines{[&] { peer.forward(); },
                                                 [&] { generated->udot(q, u, tau, ud_gen); },
                                                 [&] { generic.udot(q, u, tau, ud_gen2); }};
      std::vector<std::string> names{"mujoco", "generated", "generic"};
      kanegen::VecX ud_base, ud_nat;
      generated_baseline->udot(q, u, tau, ud_base);
      j["max_rel_diff_generated_baseline"] = max_rel(ud_base, ud);
      if (!(max_rel(ud_base, ud) <= opt.tol || backward_error(M, F, ud_base) <= kBackwardTol)) {
        std::cerr << "mujoco_peer: baseline u-dot differs from MuJoCo's: not timed\n";
        status = 1;
      }
      engines.push_back([&] { generated_baseline->udot(q, u, tau, ud_base); });
      names.push_back("generated_baseline");
      // which u-dot is served (a candidate of engine/udot_candidates.hpp when it was measured faster:
      // clang++'s or compact code), and the library's own u-dot timed beside it then
      j["udot_compiler_generated"] = generated->udot_compiler().empty() ? "main" : generated->udot_compiler();
      j["udot_compiler_generated_baseline"] =
          generated_baseline->udot_compiler().empty() ? "main" : generated_baseline->udot_compiler();
      kanegen::VecX ud_own(km.nu);
      const KanegenFunctionPtr own_udot = generated_baseline->function("udot");
      if (!generated_baseline->udot_compiler().empty()) {
        generated_baseline->call_udot(own_udot, 0.0, q, u, tau, ud_own.data());
        j["max_rel_diff_generated_baseline_own"] = max_rel(ud_own, ud);
        engines.push_back([&] { generated_baseline->call_udot(own_udot, 0.0, q, u, tau, ud_own.data()); });
        names.push_back("generated_baseline_own");
      }
      kanegen::VecX ud_compact;
      if (generated_compact) {
        generated_compact->udot(q, u, tau, ud_compact);
        j["max_rel_diff_generated_compact_baseline"] = max_rel(ud_compact, ud);
        j["max_rel_diff_compact_vs_baseline"] = max_rel(ud_compact, ud_base);  // the baseline may be compact too
        if (!(max_rel(ud_compact, ud) <= opt.tol || backward_error(M, F, ud_compact) <= kBackwardTol)) {
          std::cerr << "mujoco_peer: compact u-dot differs from MuJoCo's: not timed\n";
          status = 1;
        } else {
          engines.push_back([&] { generated_compact->udot(q, u, tau, ud_compact); });
          names.push_back("generated_compact_baseline");
        }
      }
      if (generated_native) {
        generated_native->udot(q, u, tau, ud_nat);
        j["max_rel_diff_generated_native"] = max_rel(ud_nat, ud);
        if (!(max_rel(ud_nat, ud) <= opt.tol || backward_error(M, F, ud_nat) <= kBackwardTol)) {
          std::cerr << "mujoco_peer: -march=native u-dot differs from MuJoCo's: not timed\n";
          status = 1;
        } else {
          engines.push_back([&] { generated_native->udot(q, u, tau, ud_nat); });
          names.push_back("generated_native");
        }
      }
      const auto times = kanegen::bench::interleaved_times(engines, rounds, 1e-3);
      for (std::size_t k = 0; k < names.size(); ++k) {
        j["ns_" + names[k]] = times.median[k];      // median of the slices
        j["min_ns_" + names[k]] = times.min[k];     // the least slice
      }
    }
    if (status == 0 && !wp_ref.empty()) {
      const kanegen::State ref = kanegen::load_state(km, wp_ref);
      auto err_of = [&](const VectorXd& qf, const VectorXd& uf) {
        return std::max((qf - ref.q).cwiseAbs().maxCoeff(), (uf - ref.u).cwiseAbs().maxCoeff());
      };
      nlohmann::ordered_json wp;
      std::vector<std::pair<double, double>> curve;
      for (double h : {2e-2, 1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4}) {
        const auto [err, wall] = timed([&] { auto [qf, uf] = peer.rk4(s, h, t_end); return err_of(qf, uf); }, 3);
        wp["mujoco_rk4"].push_back({{"h", h}, {"error", err}, {"wall", wall}});
        curve.emplace_back(err, wall);
      }
      std::map<std::string, std::vector<std::pair<double, double>>> curves{{"mujoco_rk4", curve}};
      const kanegen::State s0 = kanegen::initial_state(km);
      kanegen::VecX x0(km.nq + km.nu);
      x0 << s.q, s.u;
      for (const std::string name : {"cvode-adams", "arkode-erk", "dopri5", "rkf78"}) {
        kanegen::IntegratorKind kind;
        try {
          kind = kanegen::integrator_from_string(name);
        } catch (const std::invalid_argument&) {
          continue;  // not in this build
        }
        std::vector<std::pair<double, double>> c;
        for (double rtol : {1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12}) {
          std::string failure;
          const kanegen::OdeProblem prob = kanegen::make_ode_problem(*generated, tau, &failure);
          kanegen::IntegratorOptions io;
          io.kind = kind;
          io.rtol = rtol;
          io.atol = rtol * 1e-2;
          const auto [err, wall] = timed(
              [&] {
                kanegen::VecX xf;
                kanegen::integrate(prob, io, 0.0, x0, t_end, t_end, [&](double, const kanegen::VecX& x) {
                  xf = x;
                  return true;
                });
                return err_of(xf.head(km.nq), xf.tail(km.nu));
              },
              3);
          wp["kanegen_" + name].push_back({{"rtol", rtol}, {"error", err}, {"wall", wall}});
          c.emplace_back(err, wall);
        }
        curves["kanegen_" + name] = c;
      }
      for (const auto& [name, c] : curves)
        for (double target : {1e-6, 1e-8}) {
          const auto w = kanegen::bench::time_to_reach(c, target);
          wp["wall_to_reach"][name][fmt::format("{:g}", target)] = w ? nlohmann::json(*w) : nlohmann::json(nullptr);
        }
      j["work_precision"] = wp;
    }
    std::cout << j.dump(1) << "\n";
    return status;
  } catch (const Refused& e) {
    std::cerr << "mujoco_peer: refused: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "mujoco_peer: error: " << e.what() << "\n";
    return 1;
  }
}
