// FEA modal data files (model-format.md, "Modal data file") and the built-in beam.
#include <catch2/catch.hpp>

#include "tests/support/test_support.hpp"

#include <cmath>
#include <filesystem>

#include "model/beam.hpp"
#include "model/modal_data.hpp"

using namespace kanegen;
using Catch::Matchers::Contains;

namespace {

using test::data_path;
const std::string kHub = std::string(kanegen::test::source_dir()) + "/tests/reference/v_flex/v_flex_hub.modal.yaml";

using test::dump;

std::vector<Diagnostic> faults(const std::string& path, const std::vector<int>& keep = {}) {
  std::vector<Diagnostic> ds;
  load_modal_file(path, keep, ds);
  return ds;
}

void check_single_fault(const std::string& path, int line, const std::string& field, const std::string& text) {
  const auto ds = faults(path);
  INFO(dump(ds));
  REQUIRE(ds.size() == 1);
  CHECK(ds[0].file == path);
  CHECK(ds[0].line == line);
  CHECK(ds[0].field == field);
  CHECK_THAT(ds[0].message, Contains(text));
}

/// Sum_k m_k t_k.t_k + r_k.J_k r_k (dynamics.md: rotary inertia included).
double modal_mass(const FlexibleData& f, int c) {
  double s = 0;
  for (std::size_t k = 0; k < f.nodes.size(); ++k) {
    const Vec3 r = f.Psi.block<3, 1>(3 * k, c);
    s += f.nodes[k].mass * f.Phi.block<3, 1>(3 * k, c).squaredNorm() + r.dot(f.nodes[k].J_B * r);
  }
  return s;
}

}  // namespace

TEST_CASE("modal: a mode without a shape for some node", "[modal]") {
  check_single_fault(data_path("bad/modal_missing_shape.modal.yaml"), 13, "modes[1].shapes", "no shape for node 4; expected a shape for every node that carries mass");
}

TEST_CASE("modal: a shape for a node that is not listed", "[modal]") {
  check_single_fault(data_path("bad/modal_extra_shape.modal.yaml"), 11, "modes[0].shapes.9", "no node with id 9");
}

TEST_CASE("modal: shapes not mass-normalized without the flag", "[modal]") {
  check_single_fault(data_path("bad/modal_not_normalized.modal.yaml"), 8, "modes[0].shapes", "mass_normalized: false");
}

TEST_CASE("modal: negative frequency", "[modal]") {
  check_single_fault(data_path("bad/modal_negative_frequency.modal.yaml"), 7, "modes[0].frequency", "not positive");
}

TEST_CASE("modal: duplicate node id", "[modal]") {
  check_single_fault(data_path("bad/modal_duplicate_id.modal.yaml"), 5, "nodes[2].id", "duplicate node id 3");
}

TEST_CASE("modal: zero modal mass with mass_normalized false", "[modal]") {
  check_single_fault(data_path("bad/zero_modal_mass.modal.yaml"), 7, "modes[0].shapes", "zero modal mass");
}

TEST_CASE("modal: several faults reported together, unknown keys with hints", "[modal]") {
  const std::string p = data_path("bad/modal_faults.modal.yaml");
  const auto ds = faults(p);
  INFO(dump(ds));
  auto has = [&](int line, const std::string& field, const std::string& text) {
    for (const auto& d : ds)
      if (d.file == p && d.line == line && d.field == field && d.message.find(text) != std::string::npos) return true;
    return false;
  };
  CHECK(has(3, "nodes[0].inertia", "not positive semi-definite"));  // a triangle violation is allowed (CHANGES.md 2026-12-01, 6)
  CHECK(has(4, "nodes[1].mas", "did you mean 'mass'"));
  CHECK(has(4, "nodes[1].mass", "missing"));
  CHECK(has(7, "modes[0].shape", "did you mean 'shapes'"));
  CHECK(has(6, "modes[0].shapes", "missing"));
  CHECK(has(9, "mass_normalised", "did you mean 'mass_normalized'"));
}

TEST_CASE("modal: missing file", "[modal]") {
  const auto ds = faults(data_path("bad/nothing_here.modal.yaml"));
  REQUIRE(ds.size() == 1);
  CHECK(ds[0].line == 0);
  CHECK_THAT(ds[0].message, Contains("cannot open"));
}

TEST_CASE("modal: normalization on load when mass_normalized is false", "[modal]") {
  std::vector<Diagnostic> ds;
  const FlexibleData f = load_modal_file(kHub, {}, ds);
  INFO(dump(ds));
  // The reference file omits node 1 (massless, at the origin) from mode 3's shapes,
  // which model-format.md refuses ("every mode gives a shape for every node").
  // Modes 1 and 2 are complete:
  std::vector<Diagnostic> ds12;
  const FlexibleData g = load_modal_file(kHub, {1, 2}, ds12);
  INFO(dump(ds12));
  // the fault in mode 3 is in the file, whatever the selection
  CHECK(ds12.size() == ds.size());
  REQUIRE(g.modes() == 2);
  REQUIRE(g.nodes.size() == 4);
  for (int c = 0; c < 2; ++c) CHECK(modal_mass(g, c) == Approx(1.0).epsilon(1e-14));
  // both translations and rotations scaled by 1/sqrt(sum m t.t + r.J r) of the file's shapes
  Eigen::Matrix3d J2, J7;
  J2 << 0.002, 0.0001, 0.0, 0.0001, 0.003, -0.0002, 0.0, -0.0002, 0.0025;
  J7 = Eigen::Vector3d(0.001, 0.0012, 0.0011).asDiagonal();
  const Eigen::Vector3d r2(0.1, -0.2, 0.6), r7(-0.1, 0.4, 1.3);
  const double mm1 = 0.4 * (0.01 * 0.01 + 0.3 * 0.3 + 0.05 * 0.05) + 0.3 * (0.02 * 0.02 + 0.8 * 0.8 + 0.1 * 0.1) +
                     0.25 * (0.03 * 0.03 + 1.2 * 1.2 + 0.2 * 0.2) + r2.dot(J2 * r2) + r7.dot(J7 * r7);
  const double s = 1.0 / std::sqrt(mm1);
  CHECK(g.Phi(3 * 3 + 1, 0) == Approx(1.2 * s).epsilon(1e-15));
  CHECK(g.Psi(3 * 3 + 2, 0) == Approx(1.3 * s).epsilon(1e-15));
  CHECK(g.Psi(3 * 1 + 0, 0) == Approx(0.1 * s).epsilon(1e-15));
  CHECK(g.frequency_hz(1) == 7.0);
  CHECK(g.nodes[2].id == 5);
  CHECK(g.nodes[2].rho_B == Vec3(0.6, -0.02, 0.03));
}

TEST_CASE("modal: good mass-normalized file and a subset", "[modal]") {
  std::vector<Diagnostic> ds;
  const FlexibleData f = load_modal_file(data_path("good/hub.modal.yaml"), {2}, ds);
  REQUIRE(ds.empty());
  REQUIRE(f.modes() == 1);
  CHECK(f.frequency_hz(0) == 11.0);
  CHECK(f.Phi(3 * 2 + 2, 0) == -0.6);  // used as given
  CHECK(f.nodes[2].J_B(1, 1) == 0.002);
  std::vector<Diagnostic> bad;
  load_modal_file(data_path("good/hub.modal.yaml"), {3}, bad);
  REQUIRE(bad.size() == 1);
  CHECK_THAT(bad[0].message, Contains("mode 3"));
}

TEST_CASE("modal: write_modal_file round trip is lossless", "[modal]") {
  std::vector<Diagnostic> ds;
  const FlexibleData f = load_modal_file(kHub, {1, 2}, ds);  // normalized on load: not round numbers
  const auto tmp = std::filesystem::temp_directory_path() / "kanegen_test_roundtrip.modal.yaml";
  write_modal_file(f, tmp.string());
  std::vector<Diagnostic> ds2;
  const FlexibleData g = load_modal_file(tmp.string(), {}, ds2);
  INFO(dump(ds2));
  REQUIRE(ds2.empty());
  REQUIRE(g.nodes.size() == f.nodes.size());
  for (std::size_t k = 0; k < f.nodes.size(); ++k) {
    CHECK(g.nodes[k].id == f.nodes[k].id);
    CHECK(g.nodes[k].mass == f.nodes[k].mass);
    CHECK(g.nodes[k].rho_B == f.nodes[k].rho_B);
    CHECK(g.nodes[k].J_B == f.nodes[k].J_B);
  }
  CHECK(g.Phi == f.Phi);
  CHECK(g.Psi == f.Psi);
  CHECK(g.frequency_hz == f.frequency_hz);
  std::filesystem::remove(tmp);

  // the beam's data too (3x3-free inertia, many nodes)
  BeamSpec b;
  b.length = 1.3;
  b.mass_per_length = 0.7;
  b.EI = {2.0, 3.0};
  b.elements = 7;
  b.modes = 3;
  const FlexibleData bf = beam_modal_data(b);
  write_modal_file(bf, tmp.string());
  std::vector<Diagnostic> ds3;
  const FlexibleData bg = load_modal_file(tmp.string(), {}, ds3);
  INFO(dump(ds3));
  REQUIRE(ds3.empty());
  CHECK(bg.Phi == bf.Phi);
  CHECK(bg.Psi == bf.Psi);
  CHECK(bg.frequency_hz == bf.frequency_hz);
  std::filesystem::remove(tmp);
}

TEST_CASE("modal: beam cantilever modes", "[modal]") {
  BeamSpec b;
  b.length = 2.0;
  b.axis = 0;
  b.sign = 1;
  b.mass_per_length = 0.5;
  b.EI = {4.0, 9.0};  // about y (deflection in z) and about z (deflection in y)
  b.elements = 40;
  b.modes = 4;
  const FlexibleData f = beam_modal_data(b);
  REQUIRE(f.modes() == 4);
  REQUIRE(f.nodes.size() == 41);
  double total = 0;
  for (const auto& n : f.nodes) total += n.mass;
  CHECK(total == Approx(1.0).epsilon(1e-14));
  // Euler-Bernoulli cantilever: w1 = 1.8751^2 sqrt(EI / (mu L^4)), w2 = 4.6941^2 ...
  auto f_exact = [&](double beta, double EI) {
    return beta * beta * std::sqrt(EI / (b.mass_per_length * std::pow(b.length, 4))) / (2 * M_PI);
  };
  CHECK(f.frequency_hz(0) == Approx(f_exact(1.875104, 4.0)).epsilon(2e-3));
  CHECK(f.frequency_hz(1) == Approx(f_exact(1.875104, 9.0)).epsilon(2e-3));
  CHECK(f.frequency_hz(2) == Approx(f_exact(4.694091, 4.0)).epsilon(5e-3));
  CHECK(f.frequency_hz(3) == Approx(f_exact(4.694091, 9.0)).epsilon(5e-3));
  for (int c = 0; c < 4; ++c) CHECK(modal_mass(f, c) == Approx(1.0).epsilon(1e-12));
  // first mode deflects along z only; tip rotation about y is -dw/dx direction-consistent:
  // a tip deflection +z comes with a rotation about -y (right-hand rule)
  const int tip = 40;
  const Vec3 t = f.Phi.block<3, 1>(3 * tip, 0), r = f.Psi.block<3, 1>(3 * tip, 0);
  CHECK(std::abs(t(2)) > 0);
  CHECK(t(0) == 0.0);
  CHECK(t(1) == 0.0);
  CHECK(r(1) * t(2) < 0);
  // clamped node does not move
  CHECK(f.Phi.block<3, 4>(0, 0).isZero(0.0));
  CHECK(f.Psi.block<3, 4>(0, 0).isZero(0.0));
  // tip slope of the first static-like shape: |r_tip| ~ 1.38 |w_tip| / L for mode 1
  CHECK(std::abs(r(1) / t(2)) == Approx(1.3765 / b.length).epsilon(5e-3));
}
