#include "model/modal_data.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>

#include "model/output_file.hpp"
#include "model/yaml_check.hpp"

namespace kanegen {

using yamlcheck::Checker;
using yamlcheck::key_line;
using yamlcheck::line_of;
using yamlcheck::num;

namespace {

// One mode as read from the file (before selection).
struct RawMode {
  int line = 0;         // the mode's first line
  int shapes_line = 0;  // line of its `shapes:` key
  double frequency = 0.0;
  bool ok = true;
  Eigen::VectorXd t, r;  // 3 * nodes
  double scale = 1.0;    // normalization factor applied to t and r
};

}  // namespace

FlexibleData load_modal_file(const std::string& path, const std::vector<int>& keep,
                             std::vector<Diagnostic>& diagnostics) {
  FlexibleData flex;
  flex.source = path;
  bool parsed = false;
  const YAML::Node root = yamlcheck::parse_file(path, kMaxModalFileBytes, diagnostics, parsed);
  if (!parsed) return flex;
  Checker ck(path, diagnostics);
  if (!root.IsDefined() || root.IsNull()) {
    ck.error(1, "(document)", "empty file; expected modal data (a mapping with nodes, modes, mass_normalized)");
    return flex;
  }
  if (!ck.expect_map(root, 1, "(document)")) return flex;
  ck.check_keys(root, "", {"nodes", "modes", "mass_normalized", "second_order"});

  // ---- nodes
  const YAML::Node nodes = root["nodes"];
  std::map<int, int> index_of_id;  // id -> index in flex.nodes
  bool nodes_ok = true;
  if (!nodes.IsDefined()) {
    ck.error(1, "nodes", "missing; expected a list of nodes {id, position, mass, inertia}");
    nodes_ok = false;
  } else if (!ck.expect_seq(nodes, 1, "nodes")) {
    nodes_ok = false;
  } else if (nodes.size() == 0) {
    ck.error(nodes, 1, "nodes", "empty; expected at least one node");
    nodes_ok = false;
  } else if (nodes.size() > kMaxModalNodes) {
    ck.error(nodes, 1, "nodes",
             fmt::format("{} nodes; expected at most {} (docs/limits.md)", nodes.size(), kMaxModalNodes));
    nodes_ok = false;
  } else {
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      const YAML::Node nd = nodes[k];
      const std::string f = fmt::format("nodes[{}]", k);
      const int l = line_of(nd) ? line_of(nd) : line_of(nodes);
      ModalNode node;
      if (!ck.expect_map(nd, l, f)) {
        nodes_ok = false;
        flex.nodes.push_back(node);  // keep flex.nodes[k] aligned with nodes[k]
        continue;
      }
      ck.check_keys(nd, f, {"id", "position", "mass", "inertia"});
      bool ok = true;
      if (!nd["id"].IsDefined()) {
        ck.error(l, f + ".id", "missing; expected an integer node id");
        ok = false;
      } else if (auto id = ck.integer(nd["id"], l, f + ".id")) {
        node.id = static_cast<int>(*id);
        if (index_of_id.count(node.id)) {
          ck.error(nd["id"], l, f + ".id",
                   fmt::format("duplicate node id {} (also nodes[{}]); expected unique ids", node.id,
                               index_of_id[node.id]));
          ok = false;
        } else {
          index_of_id[node.id] = static_cast<int>(k);
        }
      } else {
        ok = false;
      }
      if (!nd["position"].IsDefined()) {
        ck.error(l, f + ".position", "missing; expected the node position [x, y, z] in the body frame");
        ok = false;
      } else if (auto p = ck.vec3(nd["position"], l, f + ".position")) {
        node.rho_B = *p;
      } else {
        ok = false;
      }
      if (!nd["mass"].IsDefined()) {
        ck.error(l, f + ".mass", "missing; expected the node mass in kg (>= 0)");
        ok = false;
      } else if (auto m = ck.nonneg(nd["mass"], l, f + ".mass", "a mass")) {
        node.mass = *m;
      } else {
        ok = false;
      }
      if (nd["inertia"].IsDefined()) {
        if (auto I = ck.inertia(nd["inertia"], l, f + ".inertia", /*rigid_body=*/false))
          node.J_B = *I;
        else
          ok = false;
      }
      nodes_ok = nodes_ok && ok;
      flex.nodes.push_back(node);
    }
  }
  const int nn = static_cast<int>(flex.nodes.size());

  // ---- mass_normalized
  bool mass_normalized = true;
  if (root["mass_normalized"].IsDefined()) {
    const YAML::Node mn = root["mass_normalized"];
    try {
      if (!mn.IsScalar()) throw YAML::Exception(mn.Mark(), "not a scalar");
      mass_normalized = mn.as<bool>();
    } catch (const YAML::Exception&) {
      ck.error(mn, 1, "mass_normalized", fmt::format("got {}; expected true or false", yamlcheck::describe(mn)));
    }
  }

  // ---- modes
  std::vector<RawMode> modes;
  const YAML::Node ms = root["modes"];
  if (!ms.IsDefined()) {
    ck.error(1, "modes", "missing; expected a list of modes {frequency, shapes}");
  } else if (!ck.expect_seq(ms, 1, "modes")) {
  } else if (ms.size() == 0) {
    ck.error(ms, 1, "modes", "empty; expected at least one mode");
  } else if (ms.size() > kMaxFileModes || 3.0 * static_cast<double>(nn) * static_cast<double>(ms.size()) > kMaxShapeEntries) {
    ck.error(ms, 1, "modes",
             fmt::format("{} modes of {} nodes; expected at most {} modes and at most {:.0e} shape entries "
                         "(3 x nodes x modes; docs/limits.md)",
                         ms.size(), nn, kMaxFileModes, kMaxShapeEntries));
  } else {
    for (std::size_t i = 0; i < ms.size(); ++i) {
      const YAML::Node md = ms[i];
      const std::string f = fmt::format("modes[{}]", i);
      RawMode mode;
      mode.line = line_of(md) ? line_of(md) : line_of(ms);
      const int l = mode.line;
      mode.t = Eigen::VectorXd::Zero(3 * nn);
      mode.r = Eigen::VectorXd::Zero(3 * nn);
      if (!ck.expect_map(md, l, f)) {
        mode.ok = false;
        modes.push_back(mode);
        continue;
      }
      ck.check_keys(md, f, {"frequency", "shapes"});
      if (!md["frequency"].IsDefined()) {
        ck.error(l, f + ".frequency", "missing; expected the natural frequency in Hz (> 0)");
        mode.ok = false;
      } else if (auto fr = ck.positive(md["frequency"], l, f + ".frequency", "a frequency in Hz")) {
        mode.frequency = *fr;
      } else {
        mode.ok = false;
      }
      const YAML::Node sh = md["shapes"];
      mode.shapes_line = key_line(md, "shapes") ? key_line(md, "shapes") : l;
      const std::string fs = f + ".shapes";
      if (!sh.IsDefined()) {
        ck.error(l, fs, "missing; expected a mapping node id: [tx, ty, tz, rx, ry, rz]");
        mode.ok = false;
      } else if (!ck.expect_map(sh, l, fs)) {
        mode.ok = false;
      } else {
        std::set<int> given;
        for (auto it = sh.begin(); it != sh.end(); ++it) {
          const YAML::Node key = it->first;
          const int kl = line_of(key) ? line_of(key) : line_of(sh);
          auto id = ck.integer(key, kl, fs);
          if (!id) {
            mode.ok = false;
            continue;
          }
          const int nid = static_cast<int>(*id);
          const std::string fk = fmt::format("{}.{}", fs, nid);
          if (given.count(nid)) {
            ck.error(kl, fk, fmt::format("shape of node {} given twice; expected it once", nid));
            mode.ok = false;
            continue;
          }
          given.insert(nid);
          auto v = ck.vector(it->second, kl, fk, 6);
          if (!v) {
            mode.ok = false;
            continue;
          }
          if (!nodes_ok && !index_of_id.count(nid)) continue;  // node list already faulty
          auto found = index_of_id.find(nid);
          if (found == index_of_id.end()) {
            ck.error(kl, fk,
                     fmt::format("no node with id {} in nodes; expected shapes only for listed nodes", nid));
            mode.ok = false;
            continue;
          }
          const int k = found->second;
          mode.t.segment<3>(3 * k) = v->head<3>();
          mode.r.segment<3>(3 * k) = v->tail<3>();
        }
        if (nodes_ok) {
          std::vector<std::string> missing;
          // A node that carries no mass or rotary inertia (a clamp or reference
          // point) may omit its shape, which is then zero: the reference data
          // does so (docs/decisions.md). A node with mass may not.
          for (const auto& node : flex.nodes)
            if (!given.count(node.id) && (node.mass != 0.0 || !node.J_B.isZero()))
              missing.push_back(std::to_string(node.id));
          if (!missing.empty()) {
            ck.error(mode.shapes_line, fs,
                     fmt::format("no shape for node{} {}; expected a shape for every node that carries mass",
                                 missing.size() > 1 ? "s" : "", yamlcheck::join(missing)));
            mode.ok = false;
          }
        }
      }
      modes.push_back(mode);
    }
  }

  // ---- mass normalization
  if (nodes_ok) {
    for (std::size_t i = 0; i < modes.size(); ++i) {
      RawMode& mode = modes[i];
      if (!mode.ok) continue;
      // modal mass: translations with the node masses, rotations with the node inertias
      double mm = 0.0;
      for (int k = 0; k < nn; ++k) {
        const Eigen::Vector3d r = mode.r.segment<3>(3 * k);
        mm += flex.nodes[k].mass * mode.t.segment<3>(3 * k).squaredNorm() + r.dot(flex.nodes[k].J_B * r);
      }
      const std::string f = fmt::format("modes[{}].shapes", i);
      if (mass_normalized) {
        if (std::abs(mm - 1.0) > 1e-6) {
          ck.error(mode.shapes_line, f,
                   fmt::format("modal mass sum_k (m_k t_k.t_k + r_k.J_k r_k) = {} is not 1 (to within 1e-6); expected "
                               "mass-normalized shapes, or set 'mass_normalized: false' to normalize them on load",
                               num(mm)));
          mode.ok = false;
        }
      } else if (!(mm > 0.0)) {
        ck.error(mode.shapes_line, f,
                 "zero modal mass (the mode moves no node mass or inertia); expected a mode with "
                 "sum_k (m_k t_k.t_k + r_k.J_k r_k) > 0");
        mode.ok = false;
      } else {
        mode.scale = 1.0 / std::sqrt(mm);
        mode.t *= mode.scale;
        mode.r *= mode.scale;
      }
    }
  }

  // ---- second order (foreshortening): node id -> {x, y, z: M x M symmetric}
  const int M = static_cast<int>(modes.size());
  flex.Gamma.assign(nn, {});
  const YAML::Node so = root["second_order"];
  bool so_ok = true;
  if (so.IsDefined() && nodes_ok && M > 0) {
    if (!ck.expect_map(so, 1, "second_order")) {
      so_ok = false;
    } else if (3.0 * static_cast<double>(so.size()) * M * M > kMaxSecondOrderEntries) {
      ck.error(so, 1, "second_order",
               fmt::format("{} nodes x 3 axes x {}^2 modes is more than {:.0e} entries; expected fewer nodes or "
                           "modes (docs/limits.md)",
                           so.size(), M, kMaxSecondOrderEntries));
      so_ok = false;
    } else {
      for (auto it = so.begin(); it != so.end(); ++it) {
        const int kl = line_of(it->first) ? line_of(it->first) : line_of(so);
        auto id = ck.integer(it->first, kl, "second_order");
        if (!id) {
          so_ok = false;
          continue;
        }
        const std::string f = fmt::format("second_order.{}", *id);
        auto found = index_of_id.find(static_cast<int>(*id));
        if (found == index_of_id.end()) {
          ck.error(kl, f, fmt::format("no node with id {} in nodes; expected second-order data only for listed nodes",
                                      *id));
          so_ok = false;
          continue;
        }
        const YAML::Node axes = it->second;
        if (!ck.expect_map(axes, kl, f)) {
          so_ok = false;
          continue;
        }
        ck.check_keys(axes, f, {"x", "y", "z"});
        auto& G = flex.Gamma[found->second];
        for (int a = 0; a < 3; ++a) {
          const char* axis = a == 0 ? "x" : a == 1 ? "y" : "z";
          const YAML::Node mat = axes[axis];
          if (!mat.IsDefined()) continue;
          const std::string fa = f + "." + axis;
          const int al = line_of(mat) ? line_of(mat) : kl;
          if (!mat.IsSequence() || static_cast<int>(mat.size()) != M) {
            ck.error(mat, al, fa,
                     fmt::format("got {}; expected a {} x {} matrix (one row and column per mode of the file)",
                                 yamlcheck::describe(mat), M, M));
            so_ok = false;
            continue;
          }
          Eigen::MatrixXd Gm(M, M);
          bool rows_ok = true;
          for (int r = 0; r < M; ++r) {
            auto row = ck.vector(mat[r], al, fmt::format("{}[{}]", fa, r), M);
            if (row)
              Gm.row(r) = row->transpose();
            else
              rows_ok = false;
          }
          if (!rows_ok) {
            so_ok = false;
            continue;
          }
          const double scale = Gm.cwiseAbs().maxCoeff();
          const double asym = (Gm - Gm.transpose()).cwiseAbs().maxCoeff();
          if (asym > 1e-9 * scale) {
            ck.error(mat, al, fa,
                     fmt::format("not symmetric (largest |G - G^T| entry {}); expected a symmetric matrix", num(asym)));
            so_ok = false;
            continue;
          }
          Gm = 0.5 * (Gm + Gm.transpose());
          // Shapes normalized on load: Gamma_ij scales with modes i's and j's factors.
          for (int r = 0; r < M; ++r)
            for (int c = 0; c < M; ++c) Gm(r, c) *= modes[r].scale * modes[c].scale;
          G[a] = Gm;
        }
      }
    }
  }
  if (!so_ok) flex.Gamma.assign(nn, {});

  // ---- all modes, then the selection
  flex.Phi = Eigen::MatrixXd::Zero(3 * nn, M);
  flex.Psi = Eigen::MatrixXd::Zero(3 * nn, M);
  flex.frequency_hz = Eigen::VectorXd::Zero(M);
  for (int j = 0; j < M; ++j) {
    flex.Phi.col(j) = modes[j].t;
    flex.Psi.col(j) = modes[j].r;
    flex.frequency_hz(j) = modes[j].frequency;
  }
  flex.damping_ratio = Eigen::VectorXd::Zero(M);
  flex.K = Eigen::VectorXd::Zero(M);
  flex.D = Eigen::VectorXd::Zero(M);
  if (keep.empty()) return flex;
  std::vector<int> sel;
  for (int k : keep) {
    if (k < 1 || k > M)
      ck.error(0, "modes",
               fmt::format("mode {} requested, but the file has {} modes; expected 1-based mode numbers in 1..{}", k,
                           M, M));
    else
      sel.push_back(k - 1);
  }
  return select_modes(flex, sel);
}

FlexibleData select_modes(const FlexibleData& in, const std::vector<int>& sel) {
  FlexibleData s = in;
  const int m = static_cast<int>(sel.size());
  s.Phi.resize(in.Phi.rows(), m);
  s.Psi.resize(in.Psi.rows(), m);
  s.frequency_hz.resize(m);
  s.damping_ratio = Eigen::VectorXd::Zero(m);
  s.K = Eigen::VectorXd::Zero(m);
  s.D = Eigen::VectorXd::Zero(m);
  for (int c = 0; c < m; ++c) {
    s.Phi.col(c) = in.Phi.col(sel[c]);
    s.Psi.col(c) = in.Psi.col(sel[c]);
    s.frequency_hz(c) = in.frequency_hz(sel[c]);
  }
  for (std::size_t k = 0; k < in.Gamma.size(); ++k)
    for (int a = 0; a < 3; ++a) {
      const Eigen::MatrixXd& G = in.Gamma[k][a];
      if (G.size() == 0) continue;
      Eigen::MatrixXd g(m, m);
      for (int r = 0; r < m; ++r)
        for (int c = 0; c < m; ++c) g(r, c) = G(sel[r], sel[c]);
      s.Gamma[k][a] = g.isZero(0.0) ? Eigen::MatrixXd() : g;
    }
  return s;
}

Eigen::VectorXd modal_masses(const FlexibleData& f) {
  Eigen::VectorXd Y = Eigen::VectorXd::Zero(f.modes());
  for (int c = 0; c < f.modes(); ++c)
    for (std::size_t k = 0; k < f.nodes.size(); ++k) {
      const Eigen::Vector3d r = f.Psi.block<3, 1>(3 * k, c);
      Y(c) += f.nodes[k].mass * f.Phi.block<3, 1>(3 * k, c).squaredNorm() + r.dot(f.nodes[k].J_B * r);
    }
  return Y;
}

static std::string lossless(double x) { return fmt::format("{}", x); }

static std::string vec_str(std::initializer_list<double> xs) {
  std::string s = "[";
  bool first = true;
  for (double x : xs) {
    s += (first ? "" : ", ") + lossless(x);
    first = false;
  }
  return s + "]";
}

void write_modal_file(const FlexibleData& flex, const std::string& path) {
  std::string out;
  out += "# modal data written by kanegen";
  if (!flex.source.empty()) out += " from " + flex.source;
  out += "\nnodes:\n";
  for (const auto& n : flex.nodes) {
    const Mat3& J = n.J_B;
    out += fmt::format("  - {{id: {}, position: {}, mass: {}", n.id, vec_str({n.rho_B(0), n.rho_B(1), n.rho_B(2)}),
                       lossless(n.mass));
    if (!J.isZero(0.0))
      out += fmt::format(", inertia: {}", vec_str({J(0, 0), J(1, 1), J(2, 2), J(0, 1), J(0, 2), J(1, 2)}));
    out += "}\n";
  }
  out += "modes:\n";
  for (int j = 0; j < flex.modes(); ++j) {
    out += fmt::format("  - frequency: {}\n    shapes:\n", lossless(flex.frequency_hz(j)));
    for (std::size_t k = 0; k < flex.nodes.size(); ++k) {
      const auto t = flex.Phi.block<3, 1>(3 * k, j);
      const auto r = flex.Psi.block<3, 1>(3 * k, j);
      out += fmt::format("      {}: {}\n", flex.nodes[k].id, vec_str({t(0), t(1), t(2), r(0), r(1), r(2)}));
    }
  }
  out += "mass_normalized: true\n";
  bool any = false;
  for (std::size_t k = 0; k < flex.nodes.size(); ++k) {
    if (!flex.has_second_order(static_cast<int>(k))) continue;
    if (!any) out += "second_order:\n";
    any = true;
    out += fmt::format("  {}:\n", flex.nodes[k].id);
    for (int a = 0; a < 3; ++a) {
      const Eigen::MatrixXd& G = flex.Gamma[k][a];
      if (G.size() == 0) continue;
      std::string rows;
      for (Eigen::Index r = 0; r < G.rows(); ++r) {
        std::string row;
        for (Eigen::Index c = 0; c < G.cols(); ++c) row += (c ? ", " : "") + lossless(G(r, c));
        rows += (r ? ", [" : "[") + row + "]";
      }
      out += fmt::format("    {}: [{}]\n", a == 0 ? "x" : a == 1 ? "y" : "z", rows);
    }
  }
  write_file_atomically(path, out);
}

}  // namespace kanegen
