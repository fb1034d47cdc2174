// Model loading and validation (model-format.md): every refused model names
// file, line and field; good models load with the documented layout.
#include <catch2/catch.hpp>

#include "tests/support/test_support.hpp"
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "engine/load_model.hpp"
#include "model/rotation.hpp"

using namespace kanegen;
using Catch::Matchers::Contains;

namespace {

using test::data_path;

std::vector<Diagnostic> refusal(const std::string& path) {
  try {
    load_model(path);
  } catch (const InputError& e) {
    return e.diagnostics();
  }
  FAIL("model was accepted: " << path);
  return {};
}

using test::dump;

/// The diagnostic for `field`; fails the test if there is none.
Diagnostic diag_for(const std::vector<Diagnostic>& ds, const std::string& field) {
  for (const auto& d : ds)
    if (d.field == field) return d;
  FAIL("no diagnostic for " << field << "; got:\n" << dump(ds));
  return {};
}

/// Exactly one diagnostic, at file:line: field, whose message contains `text`.
void check_single(const std::string& path, int line, const std::string& field, const std::string& text) {
  const auto ds = refusal(path);
  INFO(dump(ds));
  REQUIRE(ds.size() == 1);
  CHECK(ds[0].file == path);
  CHECK(ds[0].line == line);
  CHECK(ds[0].field == field);
  CHECK_THAT(ds[0].message, Contains(text));
}

}  // namespace

TEST_CASE("loader: unknown key with a did-you-mean hint", "[loader]") {
  check_single(data_path("bad/unknown_key.yaml"), 9, "bodies[0].inertai", "did you mean 'inertia'");
}

TEST_CASE("loader: axis whose norm is not 1", "[loader]") {
  check_single(data_path("bad/axis_not_unit.yaml"), 13, "bodies[1].joint.axis", "norm 2 is not 1");
}

TEST_CASE("loader: zero axis", "[loader]") {
  const std::string p = data_path("bad/axis_zero.yaml");
  check_single(p, 8, "bodies[0].joint.axis", "zero vector; expected a unit 3-vector");
  // the CLI line format of the spec
  const auto ds = refusal(p);
  CHECK_THAT(ds[0].str(), Contains("axis_zero.yaml:8: bodies[0].joint.axis: zero vector"));
}

TEST_CASE("loader: rotation matrix not orthonormal, or a reflection", "[loader]") {
  const std::string p = data_path("bad/bad_matrix.yaml");
  const auto ds = refusal(p);
  INFO(dump(ds));
  REQUIRE(ds.size() == 2);
  const auto a = diag_for(ds, "bodies[0].joint.rotation.matrix");
  CHECK(a.line == 7);
  CHECK_THAT(a.message, Contains("not orthonormal"));
  const auto b = diag_for(ds, "bodies[1].joint.rotation.matrix");
  CHECK(b.line == 12);
  CHECK_THAT(b.message, Contains("determinant"));
}

TEST_CASE("loader: quaternion given in part in initial:", "[loader]") {
  check_single(data_path("bad/partial_quaternion.yaml"), 10, "initial.q.bus.qw", "given in part");
}

TEST_CASE("loader: parent listed after its child", "[loader]") {
  check_single(data_path("bad/parent_order.yaml"), 5, "bodies[0].parent", "parents-first");
}

TEST_CASE("loader: duplicate body names", "[loader]") {
  check_single(data_path("bad/duplicate_name.yaml"), 8, "bodies[1].name", "duplicate body name 'link1'");
}

TEST_CASE("loader: massless leaf with degrees of freedom", "[loader]") {
  // the massless gimbal ring (has children) and the massless fixed marker are allowed
  check_single(data_path("bad/massless_leaf.yaml"), 12, "bodies[1].mass", "zero mass and no children");
}

TEST_CASE("loader: node attachment on a rigid parent", "[loader]") {
  check_single(data_path("bad/node_rigid_parent.yaml"), 11, "bodies[1].joint.node", "rigid");
}

TEST_CASE("loader: node id not in the parent's modal data", "[loader]") {
  check_single(data_path("bad/node_missing.yaml"), 13, "bodies[1].joint.node", "no node 99");
}

TEST_CASE("loader: missing modal file", "[loader]") {
  check_single(data_path("bad/modal_missing.yaml"), 9, "bodies[0].flexible.modal", "no_such_file.modal.yaml");
}

TEST_CASE("loader: missing model file", "[loader]") {
  const std::string p = data_path("bad/does_not_exist.yaml");
  const auto ds = refusal(p);
  REQUIRE(ds.size() == 1);
  CHECK(ds[0].file == p);
  CHECK(ds[0].line == 0);
  CHECK_THAT(ds[0].message, Contains("cannot open"));
}

TEST_CASE("loader: YAML syntax error", "[loader]") {
  const std::string p = data_path("bad/syntax_error.yaml");
  const auto ds = refusal(p);
  INFO(dump(ds));
  REQUIRE(ds.size() == 1);
  CHECK(ds[0].file == p);
  CHECK(ds[0].line == 6);
  CHECK_THAT(ds[0].message, Contains("YAML syntax error"));
}

TEST_CASE("loader: all faults are reported together", "[loader]") {
  const std::string p = data_path("bad/multiple_faults.yaml");
  const auto ds = refusal(p);
  INFO(dump(ds));
  struct Expect {
    int line;
    const char* field;
    const char* text;
  };
  const std::vector<Expect> expected = {
      {2, "name", "not a valid model name"},
      {3, "gravty", "did you mean 'gravity'"},
      {7, "bodies[0].joint.type", "did you mean 'revolute'"},
      {8, "bodies[0].mass", "negative"},
      {11, "bodies[1].joint.axis", "not allowed on a fixed joint"},
      {11, "bodies[1].joint.stiffness", "not allowed on a fixed joint"},
      {13, "bodies[1].inertia", "triangle inequality"},
      {14, "bodies[2].name", "reserved"},
      {16, "bodies[2].joint.rotation", "exactly one of"},
      {18, "bodies[2].inertia", "not symmetric"},
      {21, "bodies[3].joint.damping", "negative"},
      {23, "bodies[3].inertia", "not positive semi-definite"},
      {25, "initial.q.pod.dsip", "did you mean 'pod.disp'"},
      {26, "initial.u.pod.disp", "not a number"},
      {27, "outputs[1]", "did you mean 'momentum'"},
  };
  CHECK(ds.size() == expected.size());
  for (const auto& e : expected) {
    const auto d = diag_for(ds, e.field);
    CHECK(d.file == p);
    CHECK(d.line == e.line);
    CHECK_THAT(d.message, Contains(e.text));
  }
}

TEST_CASE("loader: faults of a flexible block and a missing mass", "[loader]") {
  const std::string p = data_path("bad/flexible_faults.yaml");
  const auto ds = refusal(p);
  INFO(dump(ds));
  struct Expect {
    int line;
    const char* field;
    const char* text;
  };
  const std::vector<Expect> expected = {
      {9, "bodies[0].flexible.modes[1]", "mode 3 does not exist"},
      {15, "bodies[1].flexible.damping_ratio", "3 values for 2 kept modes"},
      {21, "bodies[2].flexible.beam", "both modal and beam"},
      {26, "bodies[3].flexible.beam.mode", "did you mean 'modes'"},
      {26, "bodies[3].flexible.beam.length", "not positive"},
      {26, "bodies[3].flexible.beam.direction", "'w' is not a direction"},
      {26, "bodies[3].flexible.beam.EI[1]", "not positive"},
      {26, "bodies[3].flexible.beam.modes", "missing"},
      {27, "bodies[4].mass", "missing"},
  };
  CHECK(ds.size() == expected.size());
  for (const auto& e : expected) {
    const auto d = diag_for(ds, e.field);
    CHECK(d.line == e.line);
    CHECK_THAT(d.message, Contains(e.text));
  }
}

TEST_CASE("loader: a fault in a modal file names the modal file and its line", "[loader]") {
  const auto ds = refusal(data_path("bad/uses_bad_modal.yaml"));
  INFO(dump(ds));
  REQUIRE(ds.size() == 1);
  CHECK(ds[0].file == data_path("bad/modal_negative_frequency.modal.yaml"));
  CHECK(ds[0].line == 7);
  CHECK(ds[0].field == "modes[0].frequency");
}

// ---------------------------------------------------------------- good models

namespace {

nlohmann::json read_json(const std::string& path) {
  std::ifstream f(path);
  REQUIRE(f.good());
  return nlohmann::json::parse(f);
}

}  // namespace

// The reference modal file v_flex_hub.modal.yaml (used by v_flex and
// v_flex_free) gives no shape for its massless node 1 in mode 3: the loader
// takes a massless node's missing shape as zero (docs/decisions.md), so the
// reference models load as they are. Shared with test_state_io.cpp.
Model load_reference_model(const std::string& name) {
  const auto dir = std::filesystem::path(kanegen::test::source_dir()) / "tests" / "reference" / name;
  return load_model((dir / (name + ".yaml")).string());
}

TEST_CASE("modal: a massless node may omit its shape, which is then zero", "[modal][loader]") {
  const Model m = load_reference_model("v_flex_free");
  const FlexibleData& f = *m.bodies[0].flex;
  const int k = f.node_index(1);
  REQUIRE(k >= 0);
  CHECK(f.nodes[k].mass == 0.0);
  CHECK(f.Phi.block(3 * k, 2, 3, 1).isZero(0.0));
  CHECK(f.Psi.block(3 * k, 2, 3, 1).isZero(0.0));
}

namespace {

std::vector<std::string> reference_models() {
  std::vector<std::string> out;
  for (const auto& dir : std::filesystem::directory_iterator(std::string(kanegen::test::source_dir()) + "/tests/reference"))
    if (dir.is_directory()) out.push_back(dir.path().filename().string());
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

TEST_CASE("loader: reference models load with the documented q/u layout", "[loader]") {
  const auto names = reference_models();
  REQUIRE(names.size() == 9);
  for (const auto& n : names) {
    const std::string dir = std::string(kanegen::test::source_dir()) + "/tests/reference/" + n + "/";
    INFO(n);
    const Model m = load_reference_model(n);
    const auto expected = read_json(dir + "state1.expected.json");
    CHECK(m.name == expected["model"].get<std::string>());
    CHECK(m.q_names == expected["q_names"].get<std::vector<std::string>>());
    // the vectors keep the older speed names: each is the legacy name of the speed in its place
    const auto old_u = expected["u_names"].get<std::vector<std::string>>();
    REQUIRE(old_u.size() == m.u_names.size());
    for (std::size_t k = 0; k < old_u.size(); ++k) {
      CHECK(m.speed_index(old_u[k]) == static_cast<int>(k));
      CHECK((m.u_names[k] == old_u[k] || m.u_names[k] == old_u[k] + "_rate"));
    }
    CHECK(m.nq == static_cast<int>(m.q_names.size()));
    CHECK(m.nu == static_cast<int>(m.u_names.size()));
    CHECK(m.q0.size() == m.nq);
    CHECK(m.u0.size() == m.nu);
    CHECK(m.outputs.energy);
    CHECK(m.outputs.momentum);
    CHECK(m.outputs.reactions);
    for (const auto& [body, _] : expected["reactions"].items()) CHECK(m.body_index(body) >= 0);
  }
}

TEST_CASE("loader: reference v_flex details (modal subset, normalization, K, D, node)", "[loader]") {
  const Model m = load_reference_model("v_flex");
  REQUIRE(m.bodies.size() == 2);
  const Body& hub = m.bodies[0];
  REQUIRE(hub.flex);
  const FlexibleData& f = *hub.flex;
  REQUIRE(f.modes() == 2);
  CHECK(f.nodes.size() == 4);
  CHECK(f.frequency_hz(0) == 2.5);
  CHECK(f.frequency_hz(1) == 7.0);
  CHECK(f.damping_ratio(0) == 0.01);
  CHECK(f.damping_ratio(1) == 0.03);
  for (int c = 0; c < 2; ++c) {
    // the modal mass includes the nodes' rotary inertia (dynamics.md, "Forces")
    double Y = 0;
    for (std::size_t k = 0; k < f.nodes.size(); ++k) {
      const Vec3 r = f.Psi.block<3, 1>(3 * k, c);
      Y += f.nodes[k].mass * f.Phi.block<3, 1>(3 * k, c).squaredNorm() + r.dot(f.nodes[k].J_B * r);
    }
    CHECK(Y == Approx(1.0).epsilon(1e-14));
    const double w = 2 * M_PI * f.frequency_hz(c);
    CHECK(f.K(c) == Approx(w * w * Y).epsilon(1e-14));
    CHECK(f.D(c) == Approx(2 * f.damping_ratio(c) * w * Y).epsilon(1e-14));
  }
  // rotations scaled with the translations: ratio of a rotation to a translation entry is preserved
  // (mode 1, node id 5 = index 2: t = [-0.02, 0.8, 0.1], r = [0.3, 0.1, 1.1])
  CHECK(f.Psi(3 * 2 + 2, 0) / f.Phi(3 * 2 + 1, 0) == Approx(1.1 / 0.8));
  // node inertia 6-number form
  CHECK(f.nodes[1].J_B(0, 1) == 0.0001);
  CHECK(f.nodes[1].J_B(1, 2) == -0.0002);
  // rigid hub part and the tip attached at node id 5 (index 2)
  CHECK(hub.rigid.mass == 2.0);
  CHECK(m.bodies[1].joint.node == 2);
  CHECK(m.bodies[1].joint.R_PJ.isApprox(rpy_R(0.2, -0.1, 0.3), 1e-15));
  CHECK(m.bodies[1].parent == 0);
}

TEST_CASE("loader: rotation forms and inertia forms of the reference models", "[loader]") {
  const std::string ref = std::string(kanegen::test::source_dir()) + "/tests/reference/";
  {
    const Model m = load_model(ref + "v_prismatic_chain/v_prismatic_chain.yaml");
    Mat3 R;
    R << 0, 0, 1, 1, 0, 0, 0, 1, 0;
    CHECK(m.bodies[2].joint.R_PJ == R);  // matrix: used as given
    CHECK(m.bodies[1].joint.type == JointType::prismatic);
    CHECK(m.bodies[1].joint.stiffness[0] == 40.0);
    CHECK(m.bodies[1].joint.damping[0] == 1.2);
    CHECK(m.bodies[1].joint.rest[0] == 0.15);
    CHECK(m.bodies[1].joint.p_PJ == Vec3(0.3, 0.0, 0.1));
    CHECK(m.g_N == Vec3(0, 0, -9.81));
  }
  {
    const Model m = load_model(ref + "v_double3d/v_double3d.yaml");
    CHECK(m.bodies[1].joint.R_PJ.isApprox(axis_angle_R<double>(Vec3(0, 0.6, 0.8), 0.7), 1e-15));
    Mat3 I;
    I << 0.011, 0.002, -0.001, 0.002, 0.041, 0.003, -0.001, 0.003, 0.037;
    CHECK(m.bodies[1].rigid.I_c_B == I);
    Mat3 I0;  // [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] = [0.021, 0.093, 0.087, 0.004, -0.006, 0.002]
    I0 << 0.021, 0.004, -0.006, 0.004, 0.093, 0.002, -0.006, 0.002, 0.087;
    CHECK(m.bodies[0].rigid.I_c_B == I0);
    CHECK(m.bodies[0].rigid.com_B == Vec3(0.45, 0.05, -0.08));
  }
  {
    const Model m = load_model(ref + "v_branched/v_branched.yaml");
    const Body& w = m.bodies[3];
    CHECK(w.joint.type == JointType::fixed);
    Eigen::Vector4d q(0.9233805168766387, 0.10259783520851541, -0.3077935056255462, 0.20519567041703082);
    CHECK(w.joint.R_PJ.isApprox(quat_to_R<double>(q.normalized()), 1e-15));
    CHECK(m.bodies[0].joint.axis_J == Vec3(0, 0.8, 0.6));
    CHECK(m.bodies[0].children == std::vector<int>{1, 2});
  }
}

TEST_CASE("loader: initial state, normalization of nearly-unit axes and quaternions", "[loader]") {
  const Model m = load_model(data_path("good/initial.yaml"));
  CHECK(m.name == "initial_state_1");
  CHECK(m.outputs.energy);
  CHECK_FALSE(m.outputs.momentum);
  CHECK(m.outputs.reactions);
  // axis [0, 1.0000004, 0] normalized
  CHECK(m.bodies[1].joint.axis_J.norm() == Approx(1.0).epsilon(1e-15));
  CHECK(m.bodies[1].joint.axis_J(1) == Approx(1.0).epsilon(1e-15));
  // quaternion [1.0000005, 0, 0, 0] normalized -> identity
  CHECK(m.bodies[0].joint.R_PJ.isApprox(Mat3::Identity(), 1e-15));
  CHECK(m.bodies[1].joint.R_PJ.isApprox(rpy_R(0.1, 0.2, 0.3), 1e-15));
  CHECK(m.bodies[2].joint.R_PJ.isApprox(axis_angle_R<double>(Vec3::UnitZ(), 0.5), 1e-15));
  // q0 from initial:, quaternion normalized, other free joint at identity
  const double n = std::sqrt(0.36 + 0.8000004 * 0.8000004);
  CHECK(m.q0(m.q_index("bus.x")) == 1.5);
  CHECK(m.q0(m.q_index("bus.qw")) == Approx(0.6 / n).epsilon(1e-15));
  CHECK(m.q0(m.q_index("bus.qy")) == Approx(0.8000004 / n).epsilon(1e-15));
  CHECK(m.q0(m.q_index("a.angle")) == 0.25);
  CHECK(m.q0(m.q_index("rotor.qw")) == 1.0);
  CHECK(m.q0(m.q_index("rotor.qx")) == 0.0);
  CHECK(m.u0(m.u_index("bus.wz")) == 0.1);
  CHECK(m.u0(m.u_index("b.disp_rate")) == -0.2);
  CHECK(m.u0(m.u_index("rotor.vx")) == 0.0);
  CHECK(m.nq == 7 + 1 + 1 + 0 + 1 + 7);
  CHECK(m.nu == 6 + 1 + 1 + 0 + 1 + 6);
  CHECK(m.g_N == Vec3(0, 0, -9.81));
}

TEST_CASE("loader: flexible body from a modal file with a child at a node", "[loader]") {
  const Model m = load_model(data_path("good/flex_hub.yaml"));
  const Body& hub = m.bodies[0];
  REQUIRE(hub.flex);
  REQUIRE(hub.flex->modes() == 1);
  CHECK(hub.flex->frequency_hz(0) == 11.0);  // the file's mode 2
  CHECK(hub.flex->Phi(3 * 1 + 2, 0) == 0.8);
  CHECK(hub.flex->Psi(3 * 1 + 1, 0) == -1.5);
  CHECK(hub.rigid.mass == 0.0);
  CHECK(m.bodies[1].joint.node == 2);
  CHECK(m.q_names == std::vector<std::string>{"hub.angle", "hub.eta1", "tip.angle"});
  CHECK(m.q0(1) == 0.01);
  CHECK(m.q0(2) == 0.2);
  CHECK(m.u0(1) == -0.5);
  const double w = 2 * M_PI * 11.0;
  CHECK(hub.flex->K(0) == Approx(w * w));
  CHECK(hub.flex->D(0) == Approx(2 * 0.05 * w));
}

TEST_CASE("loader: built-in beam", "[loader]") {
  const Model m = load_model(data_path("good/beam.yaml"));
  const Body& boom = m.bodies[0];
  REQUIRE(boom.flex);
  CHECK(boom.flex->modes() == 4);
  CHECK(boom.flex->nodes.size() == 31);
  CHECK(m.bodies[1].joint.node == 30);
  CHECK(boom.flex->damping_ratio(3) == 0.01);
  CHECK(m.q_names.size() == 5);
}
