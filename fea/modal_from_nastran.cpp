#include "fea/modal_from_nastran.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <set>

#include "model/diagnostics.hpp"
#include "model/modal_data.hpp"
#include "model/rotation.hpp"

namespace kanegen::nastran {

namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

bool fully_clamped(const Grid& g) {
  for (char c : std::string("123456"))
    if (g.spc.find(c) == std::string::npos) return false;
  return true;
}

/// "grid 7", "grids 1, 2, 3" or "grids 1, 2, ... (40)" (`what`: "grid", "mode").
std::string id_list(const std::vector<int>& ids, const std::string& what = "grid") {
  const std::string name = ids.size() == 1 ? what : what + "s";
  if (ids.size() <= 12) return fmt::format("{} {}", name, fmt::join(ids, ", "));
  return fmt::format("{} {}, ... ({})", name, fmt::join(ids.begin(), ids.begin() + 10, ", "), ids.size());
}

/// Where a node's motion comes from: a grid, and the offset of the node from it (basic).
struct NodeSource {
  int grid = 0;
  Vec3 offset = Vec3::Zero();
};

}  // namespace

ModalImport import_modal_data(const Bulk& bulk, const std::string& bulk_path, const std::vector<Mode>& modes,
                              const std::string& modes_path, const std::optional<F06Weight>& weight,
                              const ModalImportOptions& options) {
  ModalImport out;

  // The root: named, or the single fully clamped grid.
  if (options.root != 0) {
    if (!bulk.grids.count(options.root))
      throw InputError(Diagnostic{bulk_path, 0, "--root", fmt::format("grid {} is not in the bulk data", options.root)});
    out.root = options.root;
  } else {
    std::vector<int> clamped;
    for (const auto& [id, g] : bulk.grids)
      if (fully_clamped(g)) clamped.push_back(id);
    if (clamped.empty())
      throw InputError(Diagnostic{bulk_path, 0, "--root",
                                  "no grid is clamped in all six components (SPC 123456): name the grid at the body's "
                                  "interface with --root (the modes must be those of the structure clamped there)"});
    if (clamped.size() > 1)
      throw InputError(Diagnostic{bulk_path, 0, "--root",
                                  fmt::format("{} are each clamped in all six components: name the one at the "
                                              "body's origin with --root",
                                              id_list(clamped))});
    out.root = clamped.front();
  }
  const Vec3 x_root = bulk.grids.at(out.root).x_basic;

  // The modes with a shape.
  std::vector<const Mode*> kept;
  std::vector<int> no_vector;
  for (const Mode& m : modes) {
    if (m.shapes.empty()) {
      no_vector.push_back(m.number);
      continue;
    }
    if (!(m.eigenvalue > 0.0) || !(m.cycles > 0.0))
      throw InputError(Diagnostic{modes_path, 0, "",
                                  fmt::format("mode {} has eigenvalue {:g}: a rigid-body mode; kanegen's modal data are "
                                              "the modes of the body clamped at its origin (a free-free run cannot be "
                                              "imported; run SOL 103 with the interface grid clamped)",
                                              m.number, m.eigenvalue)});
    kept.push_back(&m);
    out.modes.push_back(m.number);
  }
  if (kept.empty())
    throw InputError(Diagnostic{modes_path, 0, "", "no mode has an eigenvector (request DISP=ALL or VECTOR=ALL in the run)"});
  if (!no_vector.empty())
    out.notes.push_back(fmt::format("{}: no eigenvector printed; left out", id_list(no_vector, "mode")));

  // The nodes: every grid that carries mass or ends an element, and the root.
  const std::map<int, GridMass> masses = lumped_masses(bulk);
  std::set<int> connected;
  for (const LineElement& e : bulk.elements) connected.insert({e.ga, e.gb});
  auto carries_mass = [&](int id) {
    const auto it = masses.find(id);
    return it != masses.end() && (it->second.mass != 0.0 || !it->second.inertia.isZero(0.0));
  };
  std::vector<int> dropped, unprinted;
  std::vector<NodeSource> sources;
  FlexibleData& f = out.flex;
  int next_id = bulk.grids.empty() ? 1 : bulk.grids.rbegin()->first + 1;
  for (const auto& [id, g] : bulk.grids) {
    const bool massive = carries_mass(id);
    if (!massive && !connected.count(id) && id != out.root) {
      dropped.push_back(id);
      continue;
    }
    bool printed = true;
    for (const Mode* m : kept) printed = printed && m->shapes.count(id);
    if (!printed && id != out.root) {
      if (massive)
        throw InputError(Diagnostic{modes_path, 0, "",
                                    fmt::format("grid {} carries mass but not every mode gives its displacement: "
                                                "request the eigenvectors at every grid (DISP=ALL)",
                                                id)});
      unprinted.push_back(id);
      continue;
    }
    if (!printed) out.notes.push_back(fmt::format("grid {} (the root): no displacement printed; taken as clamped", id));
    ModalNode node;
    node.id = id;
    node.rho_B = g.x_basic - x_root;
    std::optional<ModalNode> centre;  // an offset mass's own node
    Vec3 d = Vec3::Zero();
    if (massive) {
      const GridMass& gm = masses.at(id);
      const double m = bulk.wtmass * gm.mass;
      const Mat3 J = bulk.wtmass * gm.inertia, C = bulk.wtmass * gm.coupling;
      if (C.isZero(0.0) || m == 0.0) {
        node.mass = m;
        node.J_B = J;
      } else {  // the grid's mass is off the grid: a node at its centre, d = S / m (C = -[S]x, S its first moment)
        d = Vec3(-C(2, 1), -C(0, 2), -C(1, 0)) / m;
        centre = ModalNode{};
        centre->id = next_id++;
        centre->rho_B = node.rho_B + d;
        centre->mass = m;
        const Mat3 Jc = J - m * kanegen::skew<double>(d).transpose() * kanegen::skew<double>(d);
        centre->J_B = 0.5 * (Jc + Jc.transpose());
        out.notes.push_back(fmt::format("grid {}: its mass centre is off the grid (an offset CONM2): node {} at "
                                        "[{:.6g}, {:.6g}, {:.6g}] from it carries its mass, moving rigidly with it",
                                        id, centre->id, d.x(), d.y(), d.z()));
      }
    }
    f.nodes.push_back(node);
    sources.push_back({id, Vec3::Zero()});
    if (centre) {
      f.nodes.push_back(*centre);
      sources.push_back({id, d});
    }
  }
  if (!dropped.empty())
    out.notes.push_back(fmt::format("{}: no mass and no element (e.g. removed by AUTOSPC); dropped",
                                    id_list(dropped)));
  if (!unprinted.empty())
    out.notes.push_back(fmt::format("{}: no mass and no displacement printed in every mode; dropped",
                                    id_list(unprinted)));

  // The shapes in basic axes, NASTRAN's normalization.
  const int n = static_cast<int>(f.nodes.size()), nm = static_cast<int>(kept.size());
  f.Phi = MatX::Zero(3 * n, nm);
  f.Psi = MatX::Zero(3 * n, nm);
  f.frequency_hz = VecX(nm);
  for (int j = 0; j < nm; ++j) {
    const Mode& m = *kept[j];
    f.frequency_hz(j) = m.cycles;
    double largest = 0.0, at_root = 0.0;
    for (int k = 0; k < n; ++k) {
      const NodeSource& s = sources[k];
      const auto it = m.shapes.find(s.grid);
      if (it == m.shapes.end()) continue;  // the unprinted root: clamped
      const Mat3& R = bulk.grids.at(s.grid).R_basic_cd;
      const Vec3 t = R * it->second.head<3>(), r = R * it->second.tail<3>();
      f.Phi.block<3, 1>(3 * k, j) = t + r.cross(s.offset);
      f.Psi.block<3, 1>(3 * k, j) = r;
      largest = std::max(largest, it->second.cwiseAbs().maxCoeff());
      if (s.grid == out.root) at_root = std::max(at_root, it->second.cwiseAbs().maxCoeff());
    }
    const double motion = largest > 0.0 ? at_root / largest : 0.0;
    out.root_motion = std::max(out.root_motion, motion);
    if (motion > 1e-6)
      throw InputError(Diagnostic{modes_path, 0, "",
                                  fmt::format("the root grid {} moves in mode {} ({:.3g} of the mode's largest entry): "
                                              "the modes are not those of the structure clamped there; name the "
                                              "clamped grid with --root",
                                              out.root, m.number, motion)});
  }

  // Generalized masses with the importer's mass, against NASTRAN's; then unit modal mass.
  const VecX Y = modal_masses(f);
  for (int j = 0; j < nm; ++j) {
    if (!(Y(j) > 0.0))
      throw InputError(Diagnostic{modes_path, 0, "",
                                  fmt::format("mode {} moves no mass of the lumped model (generalized mass {:g})",
                                              kept[j]->number, Y(j))});
    if (kept[j]->generalized_mass > 0.0)
      out.generalized_masses.push_back({kept[j]->number, kept[j]->generalized_mass, Y(j)});
    const double s = 1.0 / std::sqrt(Y(j));
    f.Phi.col(j) *= s;
    f.Psi.col(j) *= s;
  }
  f.damping_ratio = VecX::Zero(nm);
  for (const ModalNode& node : f.nodes) out.total_mass += node.mass;

  // The weight generator's MO, input units about its reference point.
  if (!weight) {
    out.weight_generator_note = "the modes' file prints no grid point weight generator (PARAM GRDPNT)";
  } else {
    Vec3 x_ref = Vec3::Zero();
    bool known = true;
    if (weight->reference_point != 0) {
      const auto it = bulk.grids.find(weight->reference_point);
      known = it != bulk.grids.end();
      if (known) x_ref = it->second.x_basic;
    }
    const double scale = weight->MO.cwiseAbs().maxCoeff();
    if (!known) {
      out.weight_generator_note =
          fmt::format("its reference point, grid {}, is not in the bulk data", weight->reference_point);
    } else if (!(scale > 0.0)) {
      out.weight_generator_note = "its MO is zero";
    } else {
      const Eigen::Matrix<double, 6, 6> MO = rigid_body_mass(masses, bulk, x_ref);
      out.weight_generator_error = (MO - weight->MO).cwiseAbs().maxCoeff() / scale;
      const WeightSummary p = weight_summary(weight->MO, x_ref), l = weight_summary(MO, x_ref);
      out.printed_weight = p;
      out.lumped_weight = l;
      out.mass_error = std::abs(l.mass - p.mass) / p.mass;
      const double gyration = std::sqrt(std::max(p.inertia_cg.trace(), 0.0) / p.mass);
      out.cg_error = (l.cg - p.cg).norm() / std::max(gyration, 1e-300);
      out.inertia_error = (l.inertia_cg - p.inertia_cg).cwiseAbs().maxCoeff() /
                          std::max(p.inertia_cg.cwiseAbs().maxCoeff(), 1e-300);
      if (out.mass_error > kMassCheckTolerance)
        out.mismatches.push_back(fmt::format("mass {:.7g} against the weight generator's {:.7g}", l.mass, p.mass));
      if (out.cg_error > kMassCheckTolerance)
        out.mismatches.push_back(fmt::format("centre of mass [{:.7g}, {:.7g}, {:.7g}] against [{:.7g}, {:.7g}, {:.7g}]",
                                             l.cg.x(), l.cg.y(), l.cg.z(), p.cg.x(), p.cg.y(), p.cg.z()));
      if (out.inertia_error > kMassCheckTolerance)
        out.mismatches.push_back(fmt::format("inertia about the centre of mass diag [{:.7g}, {:.7g}, {:.7g}] against "
                                             "[{:.7g}, {:.7g}, {:.7g}] ({:.2g} of its largest entry apart)",
                                             l.inertia_cg(0, 0), l.inertia_cg(1, 1), l.inertia_cg(2, 2),
                                             p.inertia_cg(0, 0), p.inertia_cg(1, 1), p.inertia_cg(2, 2),
                                             out.inertia_error));
    }
  }
  for (const GeneralizedMassCheck& g : out.generalized_masses)
    if (g.relative_error() > kMassCheckTolerance)
      out.mismatches.push_back(fmt::format("mode {}: generalized mass {:.7g} with the lumped mass against the "
                                           "printed {:.7g}",
                                           g.mode, g.computed, g.printed));
  if (!out.mismatches.empty() && !options.accept_mass_mismatch) {
    std::string what;
    for (const std::string& m : out.mismatches) what += (what.empty() ? "" : "; ") + m;
    throw InputError(Diagnostic{modes_path, 0, "",
                                fmt::format("the importer's lumped mass is not NASTRAN's (beyond {:g}): {}. A mass "
                                            "it lumps otherwise (e.g. MSC Nastran's CBEAM torsion, an unsupported "
                                            "mass formulation) or another deck than the run's; "
                                            "--accept-mass-mismatch writes the data anyway, normalized with the "
                                            "lumped mass",
                                            kMassCheckTolerance, what)});
  }

  // Degenerate pairs: any basis of their plane is as good as NASTRAN's.
  for (int j = 0; j + 1 < nm; ++j)
    if (std::abs(f.frequency_hz(j + 1) - f.frequency_hz(j)) <= 1e-6 * f.frequency_hz(j))
      out.notes.push_back(fmt::format("modes {} and {} have one frequency ({:.7g} Hz): their shapes are one basis of "
                                      "their plane (compare them as a subspace)",
                                      kept[j]->number, kept[j + 1]->number, f.frequency_hz(j)));
  f.source = fmt::format("NASTRAN bulk data {} and modes {}, root grid {}", bulk_path, modes_path, out.root);
  return out;
}

}  // namespace kanegen::nastran
