#include "fea/nastran_bulk.hpp"

#include <fmt/format.h>

#include <cmath>
#include <functional>
#include <numbers>
#include <optional>
#include <set>

#include "model/diagnostics.hpp"

namespace kanegen::nastran {

namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

Mat3 skew(const Vec3& v) {
  Mat3 K;
  K << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return K;
}

/// Cards that carry mass (or define geometry the importer would need) and are not read: refused, not skipped.
const std::set<std::string>& refused_cards() {
  static const std::set<std::string> s = {
      "CQUAD4", "CQUAD8", "CQUADR", "CTRIA3", "CTRIA6", "CTRIAR", "CSHEAR", "CHEXA",  "CPENTA", "CTETRA",
      "CPYRAM", "CONM1",  "CMASS1", "CMASS2", "CMASS3", "CMASS4", "PMASS",  "CTUBE",  "CBEND",  "CORD2C",
      "CORD2S", "CORD1C", "CORD1S", "CORD3G", "CBEAM3", "CVISC",  "CTRIAX", "CQUADX",
      "GRIDB",  "SPOINT", "EPOINT", "CWELD",  "CFAST",  "CSEAM",  "CPLSTN3", "CPLSTS3"};
  return s;
}

struct Frame {  ///< a rectangular coordinate system: x_basic = origin + R x_local
  Vec3 origin = Vec3::Zero();
  Mat3 R = Mat3::Identity();
};

/// Orthonormal axes from A (origin), B (on z), C (in the x-z plane).
Frame frame_from_points(const Vec3& A, const Vec3& B, const Vec3& C, const Card& card) {
  const Vec3 z = B - A;
  const Vec3 y = z.cross(C - A);
  if (z.norm() <= 1e-12 * std::max(1.0, A.norm()) || y.norm() <= 1e-12 * std::max(1.0, z.squaredNorm()))
    card.refuse(-1, "its points A, B, C do not define axes (coincident or collinear)");
  Frame f;
  f.origin = A;
  f.R.col(2) = z.normalized();
  f.R.col(1) = y.normalized();
  f.R.col(0) = f.R.col(1).cross(f.R.col(2));
  return f;
}

struct Section {  ///< a property's mass data
  std::string card;
  int mid = 0;
  double area = 0.0, J = 0.0, nsm = 0.0;
  const Card* source = nullptr;
};

/// A and J of a PBARL/PBEAML cross-section by its TYPE (MSC/NX QRG figures); `need_J`: the torsion constant is
/// used (a CBEAM's torsional inertia) and must be one NASTRAN computes exactly as here.
void section_of_shape(const std::string& type, const std::vector<double>& d, bool need_J, const Card& c, Section& s) {
  const double pi = std::numbers::pi;
  auto dims = [&](std::size_t n) {
    if (d.size() < n) c.refuse(-1, fmt::format("{} needs {} dimensions; {} given", type, n, d.size()));
    for (std::size_t k = 0; k < n; ++k)
      if (!(d[k] >= 0.0)) c.refuse(-1, fmt::format("{} dimension {} is {}; expected >= 0", type, k + 1, d[k]));
  };
  if (type == "ROD") {
    dims(1);
    s.area = pi * d[0] * d[0];
    s.J = pi * std::pow(d[0], 4) / 2.0;
  } else if (type == "TUBE") {
    dims(2);
    if (!(d[1] < d[0])) c.refuse(-1, "TUBE: the inner radius (DIM2) must be below the outer (DIM1)");
    s.area = pi * (d[0] * d[0] - d[1] * d[1]);
    s.J = pi * (std::pow(d[0], 4) - std::pow(d[1], 4)) / 2.0;
  } else if (type == "BAR") {
    dims(2);
    s.area = d[0] * d[1];
  } else if (type == "BOX") {
    dims(4);  // width, height, top and bottom wall thickness, side wall thickness
    s.area = d[0] * d[1] - (d[0] - 2.0 * d[3]) * (d[1] - 2.0 * d[2]);
  } else if (type == "I") {
    dims(6);  // height, bottom and top flange widths, web, bottom and top flange thicknesses
    s.area = d[1] * d[4] + d[2] * d[5] + (d[0] - d[4] - d[5]) * d[3];
  } else {
    c.refuse(-1, fmt::format("section TYPE '{}' is not supported; expected ROD, TUBE, BAR, BOX or I (or a PBAR/PBEAM "
                             "with A and J)",
                             type));
  }
  if (need_J && type != "ROD" && type != "TUBE")
    c.refuse(-1, fmt::format("a CBEAM's torsional inertia needs the torsion constant NASTRAN computes for TYPE {}, "
                             "which is not reproduced here; give the section as PBEAM with A and J",
                             type));
  if (!(s.area > 0.0)) c.refuse(-1, fmt::format("{}: the section's area is {}; expected > 0", type, s.area));
}

}  // namespace

Bulk read_bulk(const std::string& path) {
  const std::vector<Card> cards = read_cards(path);
  Bulk bulk;
  std::map<int, const Card*> coord_cards, grid_cards, prop_cards, mat_cards;
  std::vector<const Card*> element_cards, conm2_cards, spc_cards;
  std::set<int> beam_pids;  // properties a CBEAM uses (their J counts)
  for (const Card& c : cards) {
    const std::string& n = c.name;
    if (refused_cards().count(n))
      c.refuse(-1, fmt::format("{} is not supported by the modal importer (its mass would be left out); supported: "
                               "GRID, CORD2R, CORD1R, CBAR, CBEAM, CROD, CONROD, CONM2, PBAR, PBARL, PBEAM, PBEAML, "
                               "PROD, MAT1, SPC, SPC1, PARAM",
                               n));
    if (n == "GRID") {
      if (!grid_cards.emplace(c.integer(0), &c).second) c.refuse(0, "a second GRID with this id");
    } else if (n == "CORD2R") {
      if (!coord_cards.emplace(c.integer(0), &c).second) c.refuse(0, "a second coordinate system with this id");
    } else if (n == "CORD1R") {
      coord_cards.emplace(c.integer(0), &c);
      if (!c.blank(4)) coord_cards.emplace(c.integer(4), &c);
    } else if (n == "CBAR" || n == "CBEAM" || n == "CROD" || n == "CONROD") {
      element_cards.push_back(&c);
      if (n == "CBEAM") beam_pids.insert(c.integer(1, c.integer(0)));
    } else if (n == "PBAR" || n == "PBARL" || n == "PBEAM" || n == "PBEAML" || n == "PROD") {
      if (!prop_cards.emplace(c.integer(0), &c).second) c.refuse(0, "a second property with this id");
    } else if (n == "MAT1") {
      if (!mat_cards.emplace(c.integer(0), &c).second) c.refuse(0, "a second material with this id");
    } else if (n == "CONM2") {
      conm2_cards.push_back(&c);
    } else if (n == "SPC" || n == "SPC1") {
      spc_cards.push_back(&c);
    } else if (n == "PARAM") {
      const std::string name = c.text(0);
      if (name == "WTMASS") {
        bulk.wtmass = c.real(1);
        if (!(bulk.wtmass > 0.0)) c.refuse(1, "WTMASS must be > 0");
      } else if (name == "COUPMASS") {
        if (c.integer(1) > 0)
          c.refuse(1, "coupled mass (COUPMASS > 0) is not reproduced: the importer lumps the mass as NASTRAN's default; "
                      "run NASTRAN without PARAM COUPMASS (or with -1)");
      } else if (name == "GRDPNT") {
        bulk.grdpnt = c.integer(1);
      }
    }
  }

  // coordinate systems (rectangular), resolved through their reference systems
  std::map<int, Frame> frames{{0, Frame{}}};
  std::set<int> resolving;
  std::function<Vec3(int, const Card&)> grid_basic;  // defined below (CORD1R refers to grids)
  std::function<const Frame&(int, const Card&, int)> frame = [&](int cid, const Card& user, int field) -> const Frame& {
    if (auto it = frames.find(cid); it != frames.end()) return it->second;
    const auto ci = coord_cards.find(cid);
    if (ci == coord_cards.end()) user.refuse(field, fmt::format("coordinate system {} is not defined", cid));
    if (!resolving.insert(cid).second) ci->second->refuse(0, "its reference systems form a loop");
    const Card& c = *ci->second;
    Frame f;
    if (c.name == "CORD2R") {
      const Frame& ref = frame(c.integer(1, 0), c, 1);
      Vec3 p[3];
      for (int k = 0; k < 3; ++k)
        p[k] = ref.origin + ref.R * Vec3(c.real(2 + 3 * k, 0.0), c.real(3 + 3 * k, 0.0), c.real(4 + 3 * k, 0.0));
      f = frame_from_points(p[0], p[1], p[2], c);
    } else {  // CORD1R: CID G1 G2 G3 (and a second system in fields 5-8)
      const int at = c.integer(0) == cid ? 0 : 4;
      f = frame_from_points(grid_basic(c.integer(at + 1), c), grid_basic(c.integer(at + 2), c),
                            grid_basic(c.integer(at + 3), c), c);
    }
    resolving.erase(cid);
    return frames.emplace(cid, f).first->second;
  };
  std::set<int> placing;
  grid_basic = [&](int id, const Card& user) -> Vec3 {
    if (auto it = bulk.grids.find(id); it != bulk.grids.end()) return it->second.x_basic;
    const auto gi = grid_cards.find(id);
    if (gi == grid_cards.end()) user.refuse(-1, fmt::format("grid {} is not defined", id));
    if (!placing.insert(id).second) gi->second->refuse(1, "its position's frame depends on this grid itself");
    const Card& c = *gi->second;
    Grid g;
    g.id = id;
    const Frame& cp = frame(c.integer(1, 0), c, 1);
    g.x_basic = cp.origin + cp.R * Vec3(c.real(2, 0.0), c.real(3, 0.0), c.real(4, 0.0));
    g.cd = c.integer(5, 0);
    g.R_basic_cd = g.cd == 0 ? Mat3::Identity() : frame(g.cd, c, 5).R;
    g.spc = c.text(6);
    g.file = c.file;
    g.line = c.line;
    placing.erase(id);
    bulk.grids[id] = g;
    return g.x_basic;
  };
  for (const auto& [id, c] : grid_cards) grid_basic(id, *c);

  // single-point constraints: the components constrained per grid
  auto constrain = [&](int grid, const std::string& comps, const Card& c, int field) {
    auto it = bulk.grids.find(grid);
    if (it == bulk.grids.end()) c.refuse(field, fmt::format("grid {} is not defined", grid));
    for (char ch : comps) {
      if (ch < '1' || ch > '6') c.refuse(field, fmt::format("component '{}'; expected digits 1 to 6", comps));
      if (it->second.spc.find(ch) == std::string::npos) it->second.spc += ch;
    }
  };
  for (const Card* c : spc_cards) {
    if (c->name == "SPC") {
      for (int k = 1; k + 1 < static_cast<int>(c->fields.size()) && k <= 4; k += 3)
        if (!c->blank(k)) constrain(c->integer(k), c->text(k + 1), *c, k);
    } else {  // SPC1 SID C G1 G2 ... or G1 THRU G2
      const std::string comps = c->text(1);
      std::vector<int> ids;
      for (int k = 2; k < static_cast<int>(c->fields.size()); ++k) {
        if (c->blank(k)) continue;
        if (c->text(k) == "THRU") {
          if (ids.empty() || c->blank(k + 1)) c->refuse(k, "THRU needs a grid before and after it");
          for (int g = ids.back() + 1, e = c->integer(k + 1); g <= e; ++g)
            if (bulk.grids.count(g)) ids.push_back(g);
          ++k;
          continue;
        }
        ids.push_back(c->integer(k));
      }
      for (int g : ids) constrain(g, comps, *c, 2);
    }
  }

  // materials and properties
  auto density = [&](int mid, const Card& user, int field) {
    const auto mi = mat_cards.find(mid);
    if (mi == mat_cards.end()) user.refuse(field, fmt::format("material {} is not defined (MAT1 expected)", mid));
    const double rho = mi->second->real(4, 0.0);
    if (!(rho >= 0.0)) mi->second->refuse(4, "RHO must be >= 0");
    return rho;
  };
  std::map<int, Section> sections;
  for (const auto& [pid, cp] : prop_cards) {
    const Card& c = *cp;
    Section s;
    s.card = c.name;
    s.source = cp;
    s.mid = c.integer(1);
    if (c.name == "PBAR") {
      s.area = c.real(2, 0.0), s.J = c.real(5, 0.0), s.nsm = c.real(6, 0.0);
    } else if (c.name == "PROD") {
      s.area = c.real(2, 0.0), s.J = c.real(3, 0.0), s.nsm = c.real(5, 0.0);
    } else if (c.name == "PBEAM") {
      s.area = c.real(2, 0.0), s.J = c.real(6, 0.0), s.nsm = c.real(7, 0.0);
      // a later station (SO = YES, YESA, NO) with another section is a tapered beam
      for (int k = 8; k < static_cast<int>(c.fields.size()); ++k) {
        const std::string so = c.text(k);
        if (so != "YES" && so != "YESA" && so != "NO") continue;
        const double a = c.real(k + 2, s.area), j = c.real(k + 6, s.J), m = c.real(k + 7, s.nsm);
        if (a != s.area || j != s.J || m != s.nsm)
          c.refuse(k, "a tapered PBEAM (another A, J or NSM at a later station) is not supported");
        k += 7;
      }
    } else {  // PBARL, PBEAML: PID MID GROUP TYPE; then DIM1 .. DIMn NSM
      const std::string type = c.text(3);
      std::vector<double> d;
      for (int k = 8; k < static_cast<int>(c.fields.size()) && !c.blank(k); ++k) {
        if (c.name == "PBEAML" && (c.text(k) == "YES" || c.text(k) == "YESA" || c.text(k) == "NO"))
          c.refuse(k, "a PBEAML with intermediate or end-B stations (tapered) is not supported");
        d.push_back(c.real(k));
      }
      static const std::map<std::string, std::size_t> n_dims = {{"ROD", 1}, {"TUBE", 2}, {"BAR", 2}, {"BOX", 4}, {"I", 6}};
      const auto nd = n_dims.find(type);
      if (nd != n_dims.end() && d.size() > nd->second) {  // the field after the dimensions is NSM
        s.nsm = d[nd->second];
        d.resize(nd->second);
      }
      section_of_shape(type, d, c.name == "PBEAML" || beam_pids.count(pid), c, s);
    }
    if (!(s.area >= 0.0)) c.refuse(2, "the area must be >= 0");
    sections[pid] = s;
  }

  // elements
  for (const Card* cp : element_cards) {
    const Card& c = *cp;
    LineElement e;
    e.type = c.name;
    e.id = c.integer(0);
    e.file = c.file;
    e.line = c.line;
    if (c.name == "CONROD") {  // EID G1 G2 MID A J C NSM
      e.ga = c.integer(1), e.gb = c.integer(2);
      e.rho = density(c.integer(3), c, 3);
      e.area = c.real(4), e.J = c.real(5, 0.0), e.nsm = c.real(7, 0.0);
    } else {
      const int pid = c.integer(1, e.id);
      e.ga = c.integer(2), e.gb = c.integer(3);
      const auto si = sections.find(pid);
      if (si == sections.end()) c.refuse(1, fmt::format("property {} is not defined", pid));
      const Section& s = si->second;
      const bool ok = c.name == "CROD" ? s.card == "PROD" : c.name == "CBAR" ? (s.card == "PBAR" || s.card == "PBARL")
                                                                             : (s.card == "PBEAM" || s.card == "PBEAML");
      if (!ok) c.refuse(1, fmt::format("property {} is a {}, which a {} cannot use", pid, s.card, c.name));
      e.area = s.area, e.J = s.J, e.nsm = s.nsm;
      e.rho = density(s.mid, *s.source, 1);
      if (c.name != "CROD")  // offsets WA, WB: fields 3-8 of line 2
        for (int k = 10; k <= 15; ++k)
          if (c.real(k, 0.0) != 0.0) c.refuse(k, "an offset beam (WA, WB) is not supported");
    }
    for (int g : {e.ga, e.gb})
      if (!bulk.grids.count(g)) c.refuse(-1, fmt::format("grid {} is not defined", g));
    if (e.ga == e.gb) c.refuse(2, "both ends on one grid");
    bulk.elements.push_back(e);
  }

  // CONM2: EID G CID M X1 X2 X3; I11 I21 I22 I31 I32 I33
  for (const Card* cp : conm2_cards) {
    const Card& c = *cp;
    PointMass m;
    m.id = c.integer(0);
    m.grid = c.integer(1);
    m.file = c.file;
    m.line = c.line;
    const auto gi = bulk.grids.find(m.grid);
    if (gi == bulk.grids.end()) c.refuse(1, fmt::format("grid {} is not defined", m.grid));
    const int cid = c.integer(2, 0);
    m.mass = c.real(3, 0.0);
    if (!(m.mass >= 0.0)) c.refuse(3, "the mass must be >= 0");
    const Vec3 X(c.real(4, 0.0), c.real(5, 0.0), c.real(6, 0.0));
    Mat3 I;
    const double I11 = c.real(8, 0.0), I21 = c.real(9, 0.0), I22 = c.real(10, 0.0), I31 = c.real(11, 0.0),
                 I32 = c.real(12, 0.0), I33 = c.real(13, 0.0);
    I << I11, -I21, -I31, -I21, I22, -I32, -I31, -I32, I33;  // NASTRAN's products of inertia enter with a minus
    Mat3 R = Mat3::Identity();
    if (cid == -1) {  // X: the centre's basic coordinates; inertia in basic axes
      m.offset_basic = X - gi->second.x_basic;
    } else {
      R = frame(cid, c, 2).R;
      m.offset_basic = R * X;
    }
    m.inertia_basic = R * I * R.transpose();
    const Eigen::SelfAdjointEigenSolver<Mat3> es(0.5 * (m.inertia_basic + m.inertia_basic.transpose()));
    if (es.eigenvalues().minCoeff() < -1e-12 * std::max(1.0, es.eigenvalues().cwiseAbs().maxCoeff()))
      c.refuse(8, "the inertia matrix is not positive semi-definite");
    bulk.masses.push_back(m);
  }
  return bulk;
}

std::map<int, GridMass> lumped_masses(const Bulk& bulk) {
  std::map<int, GridMass> out;
  for (const LineElement& e : bulk.elements) {
    const Vec3 d = bulk.grids.at(e.gb).x_basic - bulk.grids.at(e.ga).x_basic;
    const double L = d.norm();
    const double half = 0.5 * (e.rho * e.area + e.nsm) * L;
    for (int g : {e.ga, e.gb}) out[g].mass += half;
    if (e.type == "CBEAM" && L > 0.0) {
      const Vec3 axis = d / L;
      const Mat3 torsion = 0.5 * e.rho * e.J * L * axis * axis.transpose();
      for (int g : {e.ga, e.gb}) out[g].inertia += torsion;
    }
  }
  for (const PointMass& m : bulk.masses) {
    GridMass& g = out[m.grid];
    const Mat3 D = skew(m.offset_basic);
    g.mass += m.mass;
    g.coupling += -m.mass * D;  // the centre moves t + r x d = t - [d]x r
    g.inertia += m.inertia_basic + m.mass * D.transpose() * D;
  }
  return out;
}

Eigen::Matrix<double, 6, 6> rigid_body_mass(const std::map<int, GridMass>& masses, const Bulk& bulk,
                                            const Eigen::Vector3d& x_ref) {
  Eigen::Matrix<double, 6, 6> MO = Eigen::Matrix<double, 6, 6>::Zero();
  for (const auto& [id, g] : masses) {
    const Mat3 X = skew(bulk.grids.at(id).x_basic - x_ref);
    MO.topLeftCorner<3, 3>() += g.mass * Mat3::Identity();
    MO.topRightCorner<3, 3>() += -g.mass * X + g.coupling;
    MO.bottomRightCorner<3, 3>() +=
        g.mass * X.transpose() * X + g.inertia - X.transpose() * g.coupling - g.coupling.transpose() * X;
  }
  MO.bottomLeftCorner<3, 3>() = MO.topRightCorner<3, 3>().transpose();
  return MO;
}

WeightSummary weight_summary(const std::map<int, GridMass>& masses, const Bulk& bulk) {
  return weight_summary(rigid_body_mass(masses, bulk), Vec3::Zero());
}

WeightSummary weight_summary(const Eigen::Matrix<double, 6, 6>& MO, const Eigen::Vector3d& x_ref) {
  WeightSummary w;
  w.mass = MO(0, 0);
  if (!(w.mass > 0.0)) return w;
  const Mat3 M_tr = MO.topRightCorner<3, 3>();
  const Vec3 S(-M_tr(2, 1), -M_tr(0, 2), -M_tr(1, 0));  // M_tr = -[S]x, S the first moment about x_ref
  const Vec3 d = S / w.mass;
  const Mat3 C = skew(d);
  w.inertia_cg = MO.bottomRightCorner<3, 3>() - w.mass * C.transpose() * C;
  w.cg = x_ref + d;
  return w;
}

}  // namespace kanegen::nastran
