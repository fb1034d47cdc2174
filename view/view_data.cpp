#include "view/view_data.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "dynamics/body_inertia.hpp"
#include "dynamics/body_terms.hpp"
#include "dynamics/kinematics.hpp"
#include "dynamics/sensors.hpp"
#include "dynamics/workspace.hpp"
#include "model/diagnostics.hpp"
#include "model/joints/joint_traits.hpp"
#include "model/orbit.hpp"
#include "model/state_io.hpp"
#include "sim/mass_properties.hpp"

namespace kanegen {

namespace {

using json = nlohmann::json;

json vec(const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); }

/// [x, y, z, qw, qx, qy, qz] appended: a pose in N.
void append_pose(json& out, const Vec3& p, const Mat3& R) {
  const Eigen::Vector4d q = attitude_quaternion(R);
  for (int i = 0; i < 3; ++i) out.push_back(p(i));
  for (int i = 0; i < 4; ++i) out.push_back(q(i));
}

/// The uniform box of the rigid part's mass and principal inertia, at its centre of mass in its principal axes;
/// a point for a rigid part without inertia; null without mass.
json body_shape(const RigidPart& r) {
  if (!(r.mass > 0.0)) return nullptr;
  Eigen::SelfAdjointEigenSolver<Mat3> es(r.I_c_B);
  const Vec3 l = es.eigenvalues();
  Mat3 V = es.eigenvectors();
  if (V.determinant() < 0) V.col(2) *= -1.0;
  Vec3 size;
  for (int i = 0; i < 3; ++i)  // I_x = m (b^2 + c^2) / 12: b^2 = 6 (I_y + I_z - I_x) / m
    size(i) = std::sqrt(std::max(0.0, 6.0 * (l((i + 1) % 3) + l((i + 2) % 3) - l(i)) / r.mass));
  if (!(size.maxCoeff() > 0.0)) return json{{"kind", "point"}, {"center_B", vec(r.com_B)}};
  const Eigen::Vector4d q = attitude_quaternion(V);
  return json{{"kind", "box"},
              {"center_B", vec(r.com_B)},
              {"quat_BP", json::array({q(0), q(1), q(2), q(3)})},
              {"size", vec(size)}};
}

/// The joint's axes in J (at q = 0 for the turned axes of a universal or gimbal joint): arrows to draw.
json joint_axes(const Joint& j) {
  json axes = json::array();
  switch (j.type) {
    case JointType::revolute:
    case JointType::prismatic:
    case JointType::cylindrical: axes.push_back(vec(j.axis_J)); break;
    case JointType::universal:
    case JointType::gimbal:
      for (const Vec3& a : j.axes_J) axes.push_back(vec(a));
      break;
    case JointType::planar:
      for (int i = 0; i < 3; ++i) axes.push_back(vec(Vec3::Unit(i)));
      break;
    default: break;
  }
  return axes;
}

}  // namespace

std::vector<int> view_rows(const RunTable& run, int frames) {
  const int n = static_cast<int>(run.rows.rows());
  std::vector<int> rows;
  if (n <= frames) {
    for (int r = 0; r < n; ++r) rows.push_back(r);
    return rows;
  }
  const double t0 = run.rows(0, 0), t1 = run.rows(n - 1, 0);
  int r = 0;
  for (int k = 0; k < frames; ++k) {
    const double t = frames > 1 ? t0 + (t1 - t0) * k / (frames - 1) : t0;
    while (r + 1 < n && run.rows(r + 1, 0) <= t) ++r;
    const int best = (r + 1 < n && run.rows(r + 1, 0) - t < t - run.rows(r, 0)) ? r + 1 : r;
    rows.push_back(best);
  }
  for (int i = 1; i < n; ++i)  // an event: two rows at one time, both kept
    if (run.rows(i, 0) == run.rows(i - 1, 0)) rows.insert(rows.end(), {i - 1, i});
  std::sort(rows.begin(), rows.end());
  rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
  return rows;
}

json view_data(const Model& model, const RunTable* run, const ViewOptions& options, const std::string& events_path) {
  json d;
  d["model"] = model.name;
  d["description"] = model.description;
  d["source"] = run ? run->path : std::string("the model's initial state");

  // What does not move: bodies, shapes, joints, node rest positions.
  json bodies = json::array();
  double extent = 0.0;
  for (const Body& b : model.bodies) {
    json jb;
    jb["name"] = b.name;
    jb["parent"] = b.parent;
    jb["mass"] = b.total_mass;
    jb["joint"] = {{"type", to_string(b.joint.type)},
                   {"locked", b.joint.locked},
                   {"node", b.joint.node},
                   {"axes_J", joint_axes(b.joint)}};
    jb["shape"] = body_shape(b.rigid);
    if (b.flex) {
      json ids = json::array(), rest = json::array();
      double length = 0.0;
      for (const ModalNode& n : b.flex->nodes) {
        ids.push_back(n.id);
        for (int i = 0; i < 3; ++i) rest.push_back(n.rho_B(i));
        length = std::max(length, n.rho_B.norm());
      }
      jb["nodes"] = {{"ids", ids}, {"rest_B", rest}, {"length", length}};
    }
    bodies.push_back(jb);
  }
  d["bodies"] = bodies;

  // The frames: the run's kept rows, or the initial state.
  std::vector<State> states;
  std::vector<int> rows;
  if (run) {
    const std::vector<int> cols = state_columns(*run, model);
    rows = view_rows(*run, std::max(1, options.frames));
    for (int r : rows) states.push_back(run_state(*run, model, cols, r));
  } else {
    states.push_back(initial_state(model));
  }
  std::vector<double> times;
  for (const State& s : states) times.push_back(s.t);
  Workspace<double> ws(model);
  json poses = json::array(), joints = json::array(), nodes = json::array();
  json com = json::array(), lvlh = json::array(), attitude = json::array();  // in orbit
  const int root = model.orbit_root >= 0 ? model.orbit_root : 0;  // the body whose attitude is told against LVLH
  for (std::size_t f = 0; f < states.size(); ++f) {
    compute_kinematics(model, ws, states[f].t, states[f].q, states[f].u);
    if (model.central) {  // the system's centre of mass, its LVLH frame, the root's attitude in it
      compute_body_terms(model, ws);
      const OrbitState c = system_centre_of_mass(model, ws);
      const Mat3 R_NL = lvlh_frame(c);
      com.push_back(vec(c.r_N));
      const Eigen::Vector4d qL = attitude_quaternion(R_NL);
      lvlh.push_back(json::array({qL(0), qL(1), qL(2), qL(3)}));
      const Eigen::Matrix<double, 7, 1> a = attitude_lvlh(c, ws.body[root].R_NB);
      const double deg = 180.0 / std::numbers::pi;
      attitude.push_back(json::array({a(4) * deg, a(5) * deg, a(6) * deg}));
    }
    json pf = json::array(), jf = json::array(), nf = json::array();
    for (std::size_t i = 0; i < model.bodies.size(); ++i) {
      const Body& b = model.bodies[i];
      const BodyWorkspace<double>& s = ws.body[i];
      append_pose(pf, s.r_NO_N, s.R_NB);
      const Mat3 R_NP = b.parent >= 0 ? ws.body[b.parent].R_NB : Mat3::Identity();
      const Vec3 r_NP = b.parent >= 0 ? ws.body[b.parent].r_NO_N : Vec3::Zero();
      append_pose(jf, r_NP + R_NP * s.p_PJ_P, R_NP * s.R_PJ);
      json nb = json::array();
      if (b.flex) {
        Eigen::Matrix<double, 3, Eigen::Dynamic> Phi_t(3, b.n_modes());
        VecX tmp(b.n_modes());
        for (int k = 0; k < static_cast<int>(b.flex->nodes.size()); ++k) {
          const Vec3 s_k = node_position<double>(*b.flex, k, s.eta, Phi_t, tmp);
          const Vec3 x = s.r_NO_N + s.R_NB * s_k;
          for (int a = 0; a < 3; ++a) nb.push_back(x(a));
        }
      }
      nf.push_back(nb);
      if (f == 0) {  // the size of the system: body origins, centres and nodes from the root's origin
        const Vec3& o = ws.body[0].r_NO_N;
        extent = std::max({extent, (s.r_NO_N - o).norm(), (s.r_NO_N + s.R_NB * b.rigid.com_B - o).norm()});
        if (b.rigid.mass > 0.0) extent = std::max(extent, std::sqrt(b.rigid.I_c_B.trace() / b.rigid.mass));
        for (std::size_t k = 0; k + 2 < nb.size(); k += 3)
          extent = std::max(extent, (Vec3(nb[k].get<double>(), nb[k + 1].get<double>(), nb[k + 2].get<double>()) - o).norm());
      }
    }
    poses.push_back(pf);
    joints.push_back(jf);
    nodes.push_back(nf);
  }
  {  // the whole spacecraft's mass properties at the first frame, as `kanegen check` prints them
    const SystemMassProperties mp = system_mass_properties(model, states[0]);
    d["mass_properties"] = {{"t", times[0]},
                            {"mass", mp.mass},
                            {"com_N", vec(mp.com_N)},
                            {"principal_moments", vec(mp.principal_moments)}};
  }
  d["t"] = times;
  d["rows"] = rows;
  d["poses"] = poses;
  d["joints"] = joints;
  d["nodes"] = nodes;
  d["scale"] = extent > 0.0 ? extent : 1.0;
  if (model.central) {
    // the central body's radius: as given, else Earth's (WGS 84) for Earth's mu, else unknown (not drawn)
    double radius = model.central->radius;
    std::string radius_source = "the model's";
    if (!(radius > 0.0) && std::abs(model.central->mu / 3.986004418e14 - 1.0) < 1e-3) {
      radius = 6378137.0;
      radius_source = "Earth's (WGS 84), from mu";
    }
    d["orbit"] = {{"mu", model.central->mu},
                  {"radius", radius > 0.0 ? radius : 0.0},
                  {"radius_source", radius > 0.0 ? radius_source : std::string("not given: not drawn")},
                  {"root", model.bodies[root].name},
                  {"com_N", com},
                  {"quat_NL", lvlh},
                  {"attitude_lvlh_deg", attitude}};
  }

  // Events (two rows at one time) and the plotted columns.
  json events = json::array(), columns = json::object();
  if (run) {
    // the timeline's marks: two rows at one time; named from the events table where one is at that time
    for (Eigen::Index i = 1; i < run->rows.rows(); ++i) {
      if (run->rows(i, 0) != run->rows(i - 1, 0)) continue;
      const double t = run->rows(i, 0);
      std::string name;
      if (options.events)
        for (const RunEvent& e : *options.events)
          if (std::abs(e.t - t) <= 1e-9 * std::max(1.0, std::abs(t)))
            name += (name.empty() ? "" : ", ") + e.name + " (" + e.action + ")";
      events.push_back({{"t", t}, {"name", name}});
    }
    // each frame's locked joints, by body index
    if (options.events) {
      std::vector<char> locked(model.bodies.size(), 0);
      for (std::size_t i = 0; i < model.bodies.size(); ++i) locked[i] = model.bodies[i].joint.locked;
      std::vector<RunEvent> by_time = *options.events;
      std::stable_sort(by_time.begin(), by_time.end(), [](const RunEvent& a, const RunEvent& b) { return a.t < b.t; });
      json per_frame = json::array();
      std::size_t next = 0;
      for (std::size_t f = 0; f < rows.size(); ++f) {
        // a row after an event (the second of its two rows, or any later time) has its locks applied
        const double t = times[f];
        const bool after = rows[f] > 0 && run->rows(rows[f] - 1, 0) == t;
        while (next < by_time.size() &&
               (by_time[next].t < t || (after && std::abs(by_time[next].t - t) <= 1e-9 * std::max(1.0, std::abs(t))))) {
          const RunEvent& e = by_time[next++];
          for (const std::string& name : e.bodies) {
            const int i = model.body_index(name);
            if (i < 0)
              throw InputError(Diagnostic{events_path, 0, "bodies",
                                          fmt::format("event {}: no body '{}' in model {}", e.name, name, model.name)});
            // the table lists the bodies whose lock changed (sim/event_run.cpp): a lock+release flips each
            if (e.action == "lock") locked[i] = 1;
            else if (e.action == "release") locked[i] = 0;
            else if (e.action == "lock+release") locked[i] = !locked[i];
          }
        }
        json l = json::array();
        for (std::size_t i = 0; i < locked.size(); ++i)
          if (locked[i]) l.push_back(i);
        per_frame.push_back(l);
      }
      d["locked"] = per_frame;
    }
    std::vector<std::string> names = options.columns;
    if (names.empty()) {
      if (!model.central)  // in orbit T and V are the orbit's (1e10 J): the attitude is told beside the view
        for (const char* n : {"T", "V"})
          if (run->column(n) >= 0) names.push_back(n);
      if (!model.bodies.empty() && !model.bodies[0].joint.prescribed()) {  // the root's speeds: a free root's rates
        const Body& b0 = model.bodies[0];
        const int nu = joint_traits(b0.joint.type).nu();
        const int first = b0.joint.type == JointType::free ? 3 : 0;
        for (int i = first; i < nu && names.size() < 5; ++i) names.push_back(model.u_names[b0.u_joint + i]);
      }
    }
    for (const std::string& n : names) {
      const int c = run->column(n);
      if (c < 0)
        throw InputError(Diagnostic{run->path, 1, "--columns", fmt::format("no column '{}' in the run", n)});
      std::vector<double> v;
      for (int r : rows) v.push_back(run->rows(r, c));
      columns[n] = v;
    }
  }
  d["events"] = events;
  d["columns"] = columns;
  return d;
}

}  // namespace kanegen
