// cmake --install puts kanegen, its headers, templates and a CMake package in
// a prefix; a separate project with no kanegen checkout does
// find_package(kanegen) and kanegen_add_model(), and its simulator (which
// links no GiNaC) runs and agrees with the kanegen in the build tree.
#include <catch2/catch.hpp>
#include <fmt/format.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "tests/support/test_support.hpp"

namespace fs = std::filesystem;

namespace {

int sh(const std::string& cmd, std::string* out = nullptr) {
  const std::string full = cmd + " 2>&1";
  FILE* p = popen(full.c_str(), "r");
  std::string text;
  char buf[4096];
  for (std::size_t n; (n = fread(buf, 1, sizeof buf, p)) > 0;) text.append(buf, n);
  const int st = pclose(p);
  if (out) *out = text;
  if (st != 0) UNSCOPED_INFO(cmd << "\n" << text);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

}  // namespace

TEST_CASE("install into a prefix, an outside project builds a simulator with find_package(kanegen)",
          "[install][slow]") {
  const fs::path tmp = fs::temp_directory_path() / fmt::format("kanegen-install-test-{}", getpid());
  fs::remove_all(tmp);
  fs::create_directories(tmp / "project");
  const fs::path prefix = tmp / "prefix";
  REQUIRE(sh(fmt::format("cmake --install {} --prefix {}", kanegen::test::build_dir(), prefix.string())) == 0);
  CHECK(fs::exists(prefix / "bin" / "kanegen"));
  CHECK(fs::exists(prefix / "share" / "kanegen" / "templates" / "model.hpp.in"));
  CHECK(fs::exists(prefix / "include" / "kanegen" / "engine" / "generated_api.h"));
  CHECK(fs::exists(prefix / "lib" / "cmake" / "kanegen" / "kanegenConfig.cmake"));

  // The outside project: a model file copied in, nothing else of kanegen.
  fs::copy_file(kanegen::test::source_path("models/double_pendulum.yaml"), tmp / "project" / "dp.yaml");
  std::ofstream(tmp / "project" / "CMakeLists.txt") << "cmake_minimum_required(VERSION 3.22)\n"
                                                       "project(outside LANGUAGES CXX)\n"
                                                       "find_package(kanegen REQUIRED)\n"
                                                       "kanegen_add_model(dp_sim dp.yaml)\n";
  const fs::path build = tmp / "build";
  // Release as a user configures it, compiled at -O0: what is checked is the package, the build and the answer,
  // not the speed (the simulator's compile at -O3 was 23 CPU-s of the suite, measured 2026-12-05)
  REQUIRE(sh(fmt::format("cmake -S {} -B {} -DCMAKE_BUILD_TYPE=Release '-DCMAKE_CXX_FLAGS_RELEASE=-O0 -DNDEBUG' "
                         "-DCMAKE_PREFIX_PATH={} > /dev/null",
                         (tmp / "project").string(), build.string(), prefix.string())) == 0);
  REQUIRE(sh(fmt::format("cmake --build {} -j2", build.string())) == 0);
  const fs::path sim = build / "dp_sim";
  REQUIRE(fs::exists(sim));

  // No GiNaC in the simulator.
  std::string ldd;
  REQUIRE(sh("ldd " + sim.string(), &ldd) == 0);
  CHECK(ldd.find("ginac") == std::string::npos);
  CHECK(ldd.find("cln") == std::string::npos);

  // The installed kanegen runs from its prefix (templates found beside it),
  // and the outside simulator agrees with it.
  const std::string cache = (tmp / "cache").string();
  std::string a, b;
  REQUIRE(sh(fmt::format("KANEGEN_CACHE_DIR={} {} eval {}", cache, (prefix / "bin" / "kanegen").string(),
                         (tmp / "project" / "dp.yaml").string()),
             &a) == 0);
  REQUIRE(sh(sim.string() + " --eval", &b) == 0);
  const auto ja = nlohmann::json::parse(a.substr(a.find('{'))), jb = nlohmann::json::parse(b.substr(b.find('{')));
  const auto ua = ja["udot"].get<std::vector<double>>(), ub = jb["udot"].get<std::vector<double>>();
  REQUIRE(ua.size() == ub.size());
  for (std::size_t i = 0; i < ua.size(); ++i) CHECK(ua[i] == Approx(ub[i]).epsilon(1e-13));
  fs::remove_all(tmp);
}
