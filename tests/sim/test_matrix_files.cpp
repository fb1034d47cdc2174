// Named-matrix files (sim/matrix_files.hpp) read back by independent readers:
// numpy.load (.npz), scipy.io.loadmat (.mat) and Python's csv module, run with
// Debian's /usr/bin/python3 (the first python3 on PATH may lack numpy). The
// readers print JSON (floats by repr, which round-trips); doubles are compared
// bit for bit, shapes (a 0-row and a 0-column matrix among them) and names exactly.
#include <catch2/catch.hpp>
#include <fmt/format.h>
#include <stdlib.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "sim/matrix_files.hpp"

namespace fs = std::filesystem;
using namespace kanegen;
using nlohmann::json;

namespace {

/// A fresh directory of its own for each test (ctest runs test cases in parallel), removed at the end.
struct TempDir {
  fs::path path;
  TempDir() {
    std::string t = (fs::temp_directory_path() / "kanegen_matrix_files_XXXXXX").string();
    if (!mkdtemp(t.data())) throw std::runtime_error("mkdtemp failed");
    path = t;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string operator/(const std::string& name) const { return (path / name).string(); }
  std::vector<std::string> files() const {
    std::vector<std::string> f;
    for (const auto& e : fs::directory_iterator(path)) f.push_back(e.path().filename().string());
    std::sort(f.begin(), f.end());
    return f;
  }
};

std::string quoted(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

/// Runs `script` with /usr/bin/python3 and the arguments; its last line of output is JSON.
json python(const TempDir& dir, const std::string& script, std::vector<std::string> args) {
  const std::string py = dir / "reader.py";
  std::ofstream(py) << "import json, sys, warnings\nwarnings.simplefilter('error')\n" << script;
  args.insert(args.begin(), py);
  std::string cmd = "/usr/bin/python3";
  for (const auto& a : args) cmd.append(" ").append(quoted(a));
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  REQUIRE(p);
  std::string out;
  char buf[4096];
  for (std::size_t n; (n = fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
  const int st = pclose(p);
  INFO(cmd << "\n" << out);
  REQUIRE((WIFEXITED(st) && WEXITSTATUS(st) == 0));
  while (!out.empty() && out.back() == '\n') out.pop_back();
  return json::parse(out.substr(out.rfind('\n') + 1));
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// `values`: the matrix in C order (row after row).
void check_values(const std::string& key, const json& values, const Eigen::MatrixXd& want) {
  REQUIRE(values.size() == std::size_t(want.size()));
  for (Eigen::Index i = 0; i < want.rows(); ++i)
    for (Eigen::Index j = 0; j < want.cols(); ++j) {
      const double got = values[std::size_t(i * want.cols() + j)].get<double>();
      INFO(fmt::format("{}({}, {}): got {:.17g}, want {:.17g}", key, i, j, got, want(i, j)));
      CHECK(same_bits(got, want(i, j)));
    }
}

/// A small linear model: distinct non-integer entries (1/3, -2.5e-7, a subnormal, -0, 1e300), a
/// 0 x 3 C and a 2 x 0 K; names of differing lengths, non-ASCII (a Greek and a non-BMP letter),
/// empty, with a comma and quotes; an empty name list.
NamedMatrices model() {
  NamedMatrices m;
  Eigen::MatrixXd A(3, 3), B(3, 2);
  A << 1.0 / 3, -2.5e-7, 0.1,  //
      -1e300, 5e-324, 2.0 / 7,  //
      -0.0, 12345.678901234567, -1.0 / 3;
  B << 2.5, -1.0 / 7,  //
      1e-17, 3.141592653589793,  //
      -6.02214076e23, 0.2;
  m.matrices = {{"A", A}, {"B", B}, {"C", Eigen::MatrixXd(0, 3)}, {"K", Eigen::MatrixXd(2, 0)}};
  m.names = {{"state_names", {"θ.x", "q1", "pendulum.angle_long_name"}},
             {"input_names", {"tau", "f,\"x\""}},
             {"output_names", {}},
             {"misc", {"", "\xF0\x9D\x9B\xBC_alpha"}}};  // U+1D6FC
  return m;
}

const std::map<std::string, std::pair<std::string, std::string>> kLabels = {
    {"A", {"state_names", "state_names"}},
    {"B", {"state_names", "input_names"}},
    {"C", {"output_names", "state_names"}},
    {"K", {"input_names", "output_names"}}};

const std::vector<std::string>& names_of(const NamedMatrices& m, const std::string& key) {
  for (const auto& [k, n] : m.names)
    if (k == key) return n;
  throw std::logic_error(key);
}

}  // namespace

TEST_CASE("npz: numpy.load reads the matrices bit-exact with their shapes, the names as <U arrays",
          "[linearize][files]") {
  TempDir dir;
  const NamedMatrices m = model();
  const std::string path = dir / "model.npz";
  write_npz(path, m);
  CHECK(dir.files() == std::vector<std::string>{"model.npz"});  // no .tmp left

  const json r = python(dir, R"(
import zipfile, numpy
z = zipfile.ZipFile(sys.argv[1])
out = {"bad_crc": z.testzip(), "methods": sorted({i.compress_type for i in z.infolist()}),
       "versions": sorted({numpy.lib.format.read_magic(z.open(n)) for n in z.namelist()}), "arrays": {}}
with numpy.load(sys.argv[1]) as d:
    for k in d.files:
        a = d[k]
        v = [float(x) for x in a.ravel()] if a.dtype.kind == "f" else [str(x) for x in a.ravel()]
        out["arrays"][k] = {"dtype": a.dtype.str, "shape": list(a.shape), "values": v}
print(json.dumps(out))
)",
                        {path});
  CHECK(r["bad_crc"].is_null());
  CHECK(r["methods"] == json::array({0}));  // stored
  CHECK(r["versions"] == json::array({json::array({1, 0})}));
  const json& arrays = r["arrays"];
  CHECK(arrays.size() == m.matrices.size() + m.names.size());
  for (const auto& [k, a] : m.matrices) {
    INFO(k);
    REQUIRE(arrays.contains(k));
    CHECK(arrays[k]["dtype"] == "<f8");
    CHECK(arrays[k]["shape"] == json::array({a.rows(), a.cols()}));
    check_values(k, arrays[k]["values"], a);
  }
  const std::map<std::string, std::string> dtypes = {
      {"state_names", "<U24"}, {"input_names", "<U5"}, {"output_names", "<U1"}, {"misc", "<U7"}};
  for (const auto& [k, n] : m.names) {
    INFO(k);
    REQUIRE(arrays.contains(k));
    CHECK(arrays[k]["dtype"] == dtypes.at(k));  // width in characters: "𝛼_alpha" is 7
    CHECK(arrays[k]["shape"] == json::array({n.size()}));
    CHECK(arrays[k]["values"].get<std::vector<std::string>>() == n);
  }
}

TEST_CASE("mat: scipy.io.loadmat reads double arrays bit-exact with their shapes, cell arrays of names",
          "[linearize][files]") {
  TempDir dir;
  const NamedMatrices m = model();
  const std::string path = dir / "model.mat";
  write_mat(path, m);
  CHECK(dir.files() == std::vector<std::string>{"model.mat"});

  const json r = python(dir, R"(
import numpy, scipy.io
d = scipy.io.loadmat(sys.argv[1])
out = {"version": d["__version__"], "whos": {n: [list(s), c] for n, s, c in scipy.io.whosmat(sys.argv[1])}, "arrays": {}}
for k, a in d.items():
    if k.startswith("__"):
        continue
    if a.dtype == object:  # a cell: each element a char array
        v = ["".join(str(c) for c in numpy.asarray(e).ravel()) for e in a.ravel(order="F")]
    else:
        v = [float(x) for x in a.ravel()]
    out["arrays"][k] = {"dtype": a.dtype.str, "shape": list(a.shape), "values": v}
print(json.dumps(out))
)",
                        {path});
  CHECK(r["version"] == "1.0");
  const json &whos = r["whos"], &arrays = r["arrays"];
  CHECK(arrays.size() == m.matrices.size() + m.names.size());
  for (const auto& [k, a] : m.matrices) {
    INFO(k);
    REQUIRE(arrays.contains(k));
    CHECK(whos[k] == json::array({json::array({a.rows(), a.cols()}), "double"}));
    CHECK(arrays[k]["dtype"] == "<f8");
    CHECK(arrays[k]["shape"] == json::array({a.rows(), a.cols()}));
    check_values(k, arrays[k]["values"], a);
  }
  for (const auto& [k, n] : m.names) {
    INFO(k);
    REQUIRE(arrays.contains(k));
    CHECK(whos[k] == json::array({json::array({n.size(), 1}), "cell"}));
    CHECK(arrays[k]["values"].get<std::vector<std::string>>() == n);
  }
}

TEST_CASE("csv: Python's csv module reads 17-digit values exactly, with row and column labels where given",
          "[linearize][files]") {
  TempDir dir;
  NamedMatrices m = model();
  m.matrices.emplace_back("P", m.matrices[0].second.topRows(2));  // no labels
  const std::string prefix = dir / "model";
  const std::vector<std::string> paths = write_csv(prefix, m, kLabels);
  CHECK(paths == std::vector<std::string>{prefix + "_A.csv", prefix + "_B.csv", prefix + "_C.csv", prefix + "_K.csv",
                                          prefix + "_P.csv"});
  CHECK(dir.files() == std::vector<std::string>{"model_A.csv", "model_B.csv", "model_C.csv", "model_K.csv",
                                                "model_P.csv"});

  for (std::size_t f = 0; f < paths.size(); ++f) {
    const auto& [key, a] = m.matrices[f];
    const auto lab = kLabels.find(key);
    const bool labelled = lab != kLabels.end();
    INFO(paths[f]);
    const json r = python(dir, R"(
import csv
with open(sys.argv[1], newline="", encoding="utf-8") as f:
    rows = list(csv.reader(f))
out = {"header": None, "row_labels": []}
if sys.argv[2] == "labelled":
    out["header"], rows = rows[0], rows[1:]
    out["row_labels"], rows = [r[0] for r in rows], [r[1:] for r in rows]
out["shape"] = [len(rows), len(rows[0]) if rows else 0]
out["values"] = [float(x) for r in rows for x in r]
print(json.dumps(out))
)",
                          {paths[f], labelled ? "labelled" : "plain"});
    check_values(key, r["values"], a);
    if (labelled) {
      std::vector<std::string> header{""};
      for (const auto& c : names_of(m, lab->second.second)) header.push_back(c);
      CHECK(r["header"].get<std::vector<std::string>>() == header);
      CHECK(r["row_labels"].get<std::vector<std::string>>() == names_of(m, lab->second.first));
      CHECK(r["row_labels"].size() == std::size_t(a.rows()));
      if (a.rows() > 0) CHECK(r["shape"] == json::array({a.rows(), a.cols()}));
    } else {
      CHECK(r["header"].is_null());
      CHECK(r["shape"] == json::array({a.rows(), a.cols()}));
    }
  }
  // 17 significant digits, as written.
  std::ifstream in(prefix + "_A.csv");
  std::string header, row1;
  std::getline(in, header);
  std::getline(in, row1);
  CHECK(row1 == "θ.x,0.33333333333333331,-2.4999999999999999e-07,0.10000000000000001");
}

TEST_CASE("matrix files: keys that are not identifiers, repeated keys and mismatched labels are refused",
          "[linearize][files]") {
  TempDir dir;
  for (const std::string bad : {"1bad", "", "a-b", "A.x", "θ"}) {
    INFO("key '" << bad << "'");
    NamedMatrices m;
    m.matrices = {{bad, Eigen::MatrixXd::Identity(2, 2)}};
    CHECK_THROWS_AS(write_npz(dir / "m.npz", m), std::invalid_argument);
    CHECK_THROWS_AS(write_mat(dir / "m.mat", m), std::invalid_argument);
    CHECK_THROWS_AS(write_csv(dir / "m", m, {}), std::invalid_argument);
    NamedMatrices n;
    n.names = {{bad, {"x"}}};
    CHECK_THROWS_AS(write_npz(dir / "m.npz", n), std::invalid_argument);
    CHECK_THROWS_AS(write_mat(dir / "m.mat", n), std::invalid_argument);
  }
  CHECK_THROWS_WITH(write_npz(dir / "m.npz", NamedMatrices{{{"1bad", Eigen::MatrixXd(1, 1)}}, {}}),
                    Catch::Contains("1bad"));
  NamedMatrices twice = model();
  twice.names.push_back({"A", {"x"}});  // the same key as a matrix
  CHECK_THROWS_AS(write_npz(dir / "m.npz", twice), std::invalid_argument);
  CHECK_THROWS_AS(write_mat(dir / "m.mat", twice), std::invalid_argument);
  // MATLAB variable names start with a letter; identifiers otherwise fine elsewhere.
  CHECK_THROWS_AS(write_mat(dir / "m.mat", NamedMatrices{{{"_x", Eigen::MatrixXd(1, 1)}}, {}}), std::invalid_argument);
  // Names must be UTF-8.
  CHECK_THROWS_AS(write_npz(dir / "m.npz", NamedMatrices{{}, {{"n", {"\xff"}}}}), std::invalid_argument);
  // Labels: unknown matrix, unknown name list, wrong count.
  const NamedMatrices m = model();
  using Labels = std::map<std::string, std::pair<std::string, std::string>>;
  CHECK_THROWS_AS(write_csv(dir / "m", m, Labels{{"Z", {"state_names", "state_names"}}}), std::invalid_argument);
  CHECK_THROWS_AS(write_csv(dir / "m", m, Labels{{"A", {"state_names", "nope"}}}), std::invalid_argument);
  CHECK_THROWS_AS(write_csv(dir / "m", m, Labels{{"B", {"state_names", "state_names"}}}), std::invalid_argument);
  CHECK(dir.files().empty());  // nothing written by any refused call
}

TEST_CASE("matrix files: a failed write throws naming the path and leaves no file, a rewrite replaces the file",
          "[linearize][files]") {
  TempDir dir;
  const NamedMatrices m = model();
  const std::string missing = dir / "no_such_dir";
  CHECK_THROWS_WITH(write_npz(missing + "/m.npz", m), Catch::Contains(missing + "/m.npz"));
  CHECK_THROWS_AS(write_npz(missing + "/m.npz", m), std::runtime_error);
  CHECK_THROWS_WITH(write_mat(missing + "/m.mat", m), Catch::Contains(missing + "/m.mat"));
  CHECK_THROWS_WITH(write_csv(missing + "/m", m, kLabels), Catch::Contains(missing + "/m_A.csv"));
  CHECK(dir.files().empty());
  // The target is a directory: the rename fails and the temporary file goes.
  fs::create_directory(dir / "taken.npz");
  CHECK_THROWS_AS(write_npz(dir / "taken.npz", m), std::runtime_error);
  CHECK(dir.files() == std::vector<std::string>{"taken.npz"});
  // Writing over an existing file replaces it.
  std::ofstream(dir / "m.mat") << "old";
  write_mat(dir / "m.mat", m);
  CHECK(fs::file_size(dir / "m.mat") > 128);
  CHECK(dir.files() == std::vector<std::string>{"m.mat", "taken.npz"});
}
