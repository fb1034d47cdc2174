#include "codegen/joint_frames.hpp"

#include <algorithm>
#include <cmath>

namespace kanegen::codegen {

namespace {

/// A body whose frame the generator may re-choose: rigid (a flexible body's
/// modal data are given in its frame) on a revolute or prismatic joint.
bool reframable(const Body& b) {
  return !b.flex && (b.joint.type == JointType::revolute || b.joint.type == JointType::prismatic);
}

/// A unit vector perpendicular to unit z: `hint`'s component across z when it
/// has one, else the model axis least aligned with z crossed with z.
Vec3 perpendicular(const Vec3& z, const Vec3& hint) {
  const Vec3 h = hint - z * z.dot(hint);
  if (h.norm() > 1e-9 * std::max(1.0, hint.norm())) return h.normalized();
  Eigen::Index k = 0;
  z.cwiseAbs().minCoeff(&k);
  return z.cross(Vec3::Unit(k)).normalized();
}

/// Where along its axis z (through the origin) body j's frame origin goes: the foot of the common normal
/// to the child's axis, through p with direction a (unit vectors); for parallel axes, the foot of the
/// perpendicular from p (the offset is then across the axis alone).
/// Nearly parallel axes put that foot far away (r / theta for axes theta apart): there, and wherever it lies
/// more than 4 |p| along the axis from the perpendicular's foot, the latter is taken (the offset then has three
/// components, as before; the origin stays near the body).
double common_normal_foot(const Vec3& z, const Vec3& p, const Vec3& a) {
  const double b = z.dot(a), denom = 1.0 - b * b, perpendicular = z.dot(p);
  if (denom < 1e-12) return perpendicular;
  // closest points O + t z and p + s a: (t z - p - s a) . z = 0 and . a = 0
  const double t = (z.dot(p) - b * a.dot(p)) / denom;
  return std::abs(t - perpendicular) <= 4.0 * p.norm() ? t : perpendicular;
}

/// Whether body j's origin stays where the model puts it: its joint at a flexible parent's node, or
/// parameters that fix it: its centre of mass, its joint's position or misalignment
/// (given in the model's frames at run time), or a child joint's position (given from O_B).
bool origin_pinned(const Model& m, int j) {
  if (m.bodies[j].joint.node >= 0) return true;  // a joint at a flexible parent's node turns with the node
  return std::any_of(m.parameters.begin(), m.parameters.end(), [&](const RuntimeParameter& p) {
    if (p.body == j)
      return p.kind == ParameterKind::com || p.kind == ParameterKind::position ||
             p.kind == ParameterKind::misalignment;
    return p.body >= 0 && m.bodies[p.body].parent == j && p.kind == ParameterKind::position;
  });
}

/// Exact zeros of v, a sum of terms of magnitude up to `scale` (to kRoundoffResidue of it).
int zeros(const Vec3& v, double scale) {
  int k = 0;
  for (int a = 0; a < 3; ++a) k += std::abs(v(a)) <= kRoundoffResidue * scale ? 1 : 0;
  return k;
}

/// Where along its axis z a leaf's origin goes (its frame's x axis x; nothing below it depends on the
/// choice): where the model has it, at the foot of the perpendicular from its parent's new origin (no offset
/// along the axis; (a, 0, 0) from the parent of a main child) or level with its centre of mass (no first
/// moment along the axis), whichever leaves most zeros in the offset from the parent (the parent's and the
/// joint's components) and the first moment, but none of the model's zeros of the first moment (a wheel
/// keeps its origin at its centre); the model's place on a tie, then the perpendicular's.
double leaf_origin(const Model& in, const FramedModel& out, int j, const Vec3& z, const Vec3& x) {
  const Body& b = in.bodies[j];
  const Vec3 o_P = b.parent >= 0 ? out.o_B[b.parent] : Vec3::Zero();
  const Mat3 Qp = b.parent >= 0 ? out.R_BBp[b.parent] : Mat3::Identity();
  // the axes the generator uses for the offset: the joint's, x along the common normal to the parent's
  // axis where the parent's frame is re-chosen (its Rz(delta) joined to the joint angle), else the body's
  Vec3 x_J = x;
  if (b.parent >= 0 && reframable(in.bodies[b.parent]) && b.joint.type == JointType::revolute) {
    const Vec3 n = (b.joint.R_PJ.transpose() * in.bodies[b.parent].joint.axis_J.normalized()).cross(z);
    if (n.norm() > 1e-9) x_J = n.normalized();
  }
  const Vec3 y = z.cross(x), y_J = z.cross(x_J);
  const double candidates[3] = {0.0, -(b.joint.R_PJ * z).dot(b.joint.p_PJ - o_P), z.dot(b.rigid.com_B)};
  double best = 0.0;
  int most = -1, zeros_S0 = -1;
  for (const double t : candidates) {
    const Vec3 d = b.joint.p_PJ + b.joint.R_PJ * (z * t) - o_P;  // O_B' from O_P', the parent's model axes
    const Vec3 d_J = b.joint.R_PJ.transpose() * d, c = b.rigid.com_B - z * t;
    const double scale_d = b.joint.p_PJ.norm() + std::abs(t) + o_P.norm(),
                 scale_c = b.rigid.com_B.norm() + std::abs(t);
    const int zeros_S = zeros(Vec3(x.dot(c), y.dot(c), z.dot(c)), scale_c);
    if (zeros_S0 < 0) zeros_S0 = zeros_S;
    if (zeros_S < zeros_S0) continue;  // the first moment enters more products than the offset
    const int k = zeros(Qp.transpose() * d, scale_d) +
                  zeros(Vec3(x_J.dot(d_J), y_J.dot(d_J), z.dot(d_J)), scale_d) + zeros_S;
    if (k > most) most = k, best = t;
  }
  return best;
}

}  // namespace

Mat3 rot_x(double a) {
  Mat3 R = Mat3::Identity();
  const double c = std::cos(a), s = std::sin(a);
  R(1, 1) = c, R(1, 2) = -s, R(2, 1) = s, R(2, 2) = c;
  snap_unit_residues(R);  // a quarter turn's cos(pi/2) = 6e-17 is 0
  return R;
}

Mat3 rot_z(double a) {
  Mat3 R = Mat3::Identity();
  const double c = std::cos(a), s = std::sin(a);
  R(0, 0) = c, R(0, 1) = -s, R(1, 0) = s, R(1, 1) = c;
  snap_unit_residues(R);
  return R;
}

FramedModel keep_joint_frames(const Model& model) {
  FramedModel f{model, std::vector<Mat3>(model.bodies.size(), Mat3::Identity()),
                std::vector<double>(model.bodies.size(), 0.0), std::vector<Vec3>(model.bodies.size(), Vec3::Zero()),
                std::vector<double>(model.bodies.size(), 0.0)};
  return f;
}

FramedModel choose_joint_frames(const Model& in) {
  const int nb = static_cast<int>(in.bodies.size());
  FramedModel out = keep_joint_frames(in);
  // subtree sizes, to pick each body's main child (the one with most descendants)
  std::vector<int> size(nb, 1);
  for (int j = nb - 1; j >= 0; --j)
    if (in.bodies[j].parent >= 0) size[in.bodies[j].parent] += size[j];
  std::vector<int> main_child(nb, -1);
  for (int j = 0; j < nb; ++j) {
    const int p = in.bodies[j].parent;
    if (p < 0 || !reframable(in.bodies[j])) continue;
    if (main_child[p] < 0 || size[j] > size[main_child[p]]) main_child[p] = j;
  }

  // 1. The new frames: z along the joint axis, x along the common normal to
  //    the main child's axis (or across the centre of mass when there is none).
  for (int j = 0; j < nb; ++j) {
    const Body& b = in.bodies[j];
    if (!reframable(b)) continue;
    const Vec3 z = b.joint.axis_J.normalized();  // in B (= J at q = 0)
    Vec3 x;
    if (const int c = main_child[j]; c >= 0) {
      const Body& cb = in.bodies[c];
      const Vec3 a_c = (cb.joint.R_PJ * cb.joint.axis_J).normalized();  // the child's axis in B
      const Vec3 n = z.cross(a_c);
      x = n.norm() > 1e-9 ? Vec3(n.normalized()) : perpendicular(z, cb.joint.p_PJ);
      if (!origin_pinned(in, j)) out.o_B[j] = z * common_normal_foot(z, cb.joint.p_PJ, a_c);
    } else {
      x = perpendicular(z, b.rigid.com_B);
      if (size[j] == 1 && !origin_pinned(in, j)) out.o_B[j] = z * leaf_origin(in, out, j, z, x);
    }
    Mat3 Q;
    Q.col(0) = x;
    Q.col(1) = z.cross(x);
    Q.col(2) = z;
    out.R_BBp[j] = Q;
  }

  // 2. Everything given in a body's frame, re-expressed in B'.
  for (int j = 0; j < nb; ++j) {
    const Body& b = in.bodies[j];
    Body& o = out.model.bodies[j];
    const Mat3& Q = out.R_BBp[j];
    const Mat3 Qp = b.parent >= 0 ? out.R_BBp[b.parent] : Mat3::Identity();
    const Vec3 o_P = b.parent >= 0 ? out.o_B[b.parent] : Vec3::Zero();
    o.joint.R_PJ = Qp.transpose() * b.joint.R_PJ * Q;
    // O_B' = O_B + o_B (o_B along the joint axis: the same point for every q), from O_P' = O_P + o_P
    o.joint.p_PJ = Qp.transpose() * (b.joint.p_PJ + b.joint.R_PJ * out.o_B[j] - o_P);
    // round-off of the terms (a short offset between long ones: the common normal's a) is no component
    const double terms = b.joint.p_PJ.norm() + out.o_B[j].norm() + o_P.norm();
    snap_roundoff_residues(o.joint.p_PJ, terms);
    if (reframable(b)) o.joint.axis_J = Vec3::UnitZ();
    move_ports(out.model.inputs, out.model.sensors, j, j, -(Q.transpose() * out.o_B[j]), Q.transpose());
    o.rigid.com_B = Q.transpose() * (b.rigid.com_B - out.o_B[j]);
    o.rigid.I_c_B = Q.transpose() * b.rigid.I_c_B * Q;
    o.rigid.I_c_B = 0.5 * (o.rigid.I_c_B + o.rigid.I_c_B.transpose()).eval();
    // Denavit-Hartenberg: when the parent's x axis is normal to this revolute
    // axis, R_PJ = Rx(alpha) Rz(delta), and Rz(delta) joins the joint rotation.
    // Otherwise (not the main child) the parent's axes turned by beta about z
    // first have their x axis normal to it: R_PJ = Rz(beta) Rx(alpha) Rz(delta).
    const Mat3 C = o.joint.R_PJ;
    const bool misaligned = std::any_of(in.parameters.begin(), in.parameters.end(), [j](const RuntimeParameter& p) {
      return p.body == j && p.kind == ParameterKind::misalignment;
    });
    if (reframable(b) && b.joint.type == JointType::revolute && b.parent >= 0 && reframable(in.bodies[b.parent]) &&
        !misaligned) {
      // beta puts x along z x axis (the axis is C's last column, in P'), as a main child's common normal
      const double beta = std::abs(C(0, 2)) < 1e-12 ? 0.0 : std::atan2(C(0, 2), -C(1, 2));
      Mat3 Cs = rot_z(beta).transpose() * C;
      Cs(0, 2) = 0.0;  // by construction, to rounding
      const double alpha = std::atan2(-Cs(1, 2), Cs(2, 2));
      const Mat3 Rz = rot_x(alpha).transpose() * Cs;
      out.angle_offset[j] = std::atan2(Rz(1, 0), Rz(0, 0));
      out.screw_angle[j] = beta;
      o.joint.R_PJ = beta == 0.0 ? rot_x(alpha) : Mat3(rot_z(beta) * rot_x(alpha));
    }
    // likewise the offset in the joint's axes (which the generator uses): a zero there is exact
    Vec3 p_J = o.joint.R_PJ.transpose() * o.joint.p_PJ;
    if (zeros(p_J, terms) > zeros(p_J, p_J.cwiseAbs().maxCoeff())) {
      snap_roundoff_residues(p_J, terms);
      o.joint.p_PJ = o.joint.R_PJ * p_J;
      snap_roundoff_residues(o.joint.p_PJ, terms);
    }
    snap_roundoff_residues(o);
  }
  const VecX q0 = in.q0, u0 = in.u0;
  finalize_model(out.model);
  out.model.q0 = q0;
  out.model.u0 = u0;
  return out;
}

}  // namespace kanegen::codegen
