// The suite itself: ctest runs each Catch2 test case by its name, and a name
// holding ';' is split by CMake into fragments that match nothing (so the
// case "passes" without running: eight cases were silently skipped so).
#include <catch2/catch.hpp>

#include <cstdio>
#include <filesystem>
#include <string>

TEST_CASE("every test case name can be run by ctest (no semicolon)", "[suite]") {
  // this executable by its path (in popen's shell, /proc/self/exe would be the shell)
  const std::string cmd = std::filesystem::read_symlink("/proc/self/exe").string() + " --list-test-names-only 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  REQUIRE(p);
  char buf[4096];
  int names = 0;
  while (std::fgets(buf, sizeof buf, p)) {
    const std::string line(buf);
    if (line.empty() || line == "\n") continue;
    ++names;
    INFO(line);
    CHECK(line.find(';') == std::string::npos);
  }
  pclose(p);
  CHECK(names > 100);
}
