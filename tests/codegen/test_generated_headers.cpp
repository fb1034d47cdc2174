// generated/ holds the header of every model in models/: regenerating each
// with `kanegen generate` must give the committed bytes (the generator is
// deterministic: no timestamp, output independent of process state), and
// each header must compile on its own with nothing but <cmath>.
#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <unistd.h>

#include "tests/support/test_support.hpp"

namespace fs = std::filesystem;

namespace {

using kanegen::test::slurp;

std::vector<fs::path> model_files() {
  const auto names = kanegen::test::models_under_test(kanegen::test::model_files());
  return {names.begin(), names.end()};
}

}  // namespace

// Both hidden ([.]): ctest runs them once per model ("headers regenerate: <model>",
// "header standalone: <model>", tests/CMakeLists.txt).
TEST_CASE("generated/ headers regenerate byte-identically", "[.][generated][generator][per-model]") {
  const fs::path tmp = fs::temp_directory_path() / ("kanegen_regen_" + std::to_string(getpid()));
  fs::create_directories(tmp);
  for (const auto& m : model_files()) {
    const std::string name = m.stem().string();
    INFO(name);
    const fs::path committed = kanegen::test::source_path("generated/" + name + ".hpp");
    REQUIRE(fs::exists(committed));
    const fs::path fresh = tmp / (name + ".hpp");
    const std::string cmd = std::string(kanegen::test::kanegen_binary()) + " generate " + m.string() + " -o " + fresh.string() + " 2>/dev/null";
    REQUIRE(std::system(cmd.c_str()) == 0);
    CHECK(slurp(fresh) == slurp(committed));
  }
  fs::remove_all(tmp);
}

TEST_CASE("generated headers compile standalone with only <cmath>, every function instantiated, calling no "
          "allocation and holding no thread-local state",
          "[.][generated][generator][per-model]") {
  // -fsyntax-only alone would leave the function templates uninstantiated:
  // each is explicitly instantiated for double and for the dual numbers.
  const std::regex ns_re(R"(namespace (kanegen_gen::[A-Za-z0-9_]+) \{)");
  const std::regex fn_re(R"(template <class T>\n(void|int) ([a-z_]+)\(([^)]*)\) \{)");
  for (const auto& m : model_files()) {
    const std::string name = m.stem().string();
    INFO(name);
    const std::string header = kanegen::test::source_path("generated/" + name + ".hpp");
    const std::string text = slurp(header);
    std::smatch ns;
    REQUIRE(std::regex_search(text, ns, ns_re));
    std::string tu = "#include \"" + header + "\"\n";
    int functions = 0;
    for (std::sregex_iterator it(text.begin(), text.end(), fn_re), end; it != end; ++it) {
      for (const std::string& scalar : {std::string("double"), ns[1].str() + "::Dual<1>"}) {
        const std::string params = std::regex_replace((*it)[3].str(), std::regex(R"(\bT\b)"), scalar);
        tu += "template " + (*it)[1].str() + " " + ns[1].str() + "::" + (*it)[2].str() + "<" + scalar + ">(" + params +
              ");\n";
      }
      ++functions;
    }
    CHECK(functions >= 4);  // qdot, mass_matrix, forcing, udot (and the requested outputs)
    const fs::path src = fs::temp_directory_path() / ("kanegen_instantiate_" + std::to_string(getpid()) + ".cpp");
    std::ofstream(src) << tu;
    // the one include
    for (std::size_t at = text.find("#include"); at != std::string::npos; at = text.find("#include", at + 1))
      CHECK(text.compare(at, 17, "#include <cmath>\n") == 0);
    // compiled without exceptions; the object's undefined symbols name no
    // allocation function and no thread-local storage
    const fs::path obj = fs::path(src).replace_extension(".o");
    const std::string cmd = "c++ -std=c++17 -O0 -g0 -fno-exceptions -DKANEGEN_NO_DISPATCH -c -Wall -Wextra -Werror " + src.string() + " -o " +
                            obj.string() + " 2>&1";
    REQUIRE(std::system(cmd.c_str()) == 0);
    const fs::path syms = fs::path(src).replace_extension(".syms");
    REQUIRE(std::system(("nm -u " + obj.string() + " > " + syms.string()).c_str()) == 0);
    const std::string undefined = slurp(syms.string());
    for (const char* bad : {"malloc", "calloc", "realloc", "_Znwm", "_Znam", "_ZdlPv", "_ZdaPv", "__tls_get_addr",
                            "__cxa_thread_atexit", "__cxa_allocate_exception", "aligned_alloc", "posix_memalign"}) {
      INFO(bad << " in\n" << undefined);
      CHECK(undefined.find(bad) == std::string::npos);
    }
    fs::remove(src);
    fs::remove(obj);
    fs::remove(syms);
  }
}

TEST_CASE("generated code takes one sin and one cos per joint angle in each function and shares them among every use",
          "[generated][generator]") {
  // Each generated function evaluates sin(a) and cos(a) of an angle a once: the joint angles in one batch,
  // kanegen_sincos_n (templates/joint_sincos.inc; its accuracy: test_joint_sincos.cpp), into arrays every use
  // reads; any other angle into a temporary every use reads (GCC then fuses the pair into one sincos call at
  // -O1 and above). Checked on every committed header (generated/, which "headers regenerate" keeps equal to
  // the generator's output).
  // functions, split parts (KANEGEN_NOINLINE ... void udot_part0(...)) too; a function and its parts are one
  // evaluation, so an angle's sin is taken once among them
  const std::regex fn_re(R"(\n(?:template <class T>\n)?(?:[A-Z_]+ )*(?:void|int) ([a-z_0-9]+)\([^)]*\) \{\n)");
  const std::regex part_re(R"(_part[0-9]+$)");
  const std::regex any_call_re(R"(\b(sin|cos)\()");
  const std::regex call_re(R"(\b(sin|cos)\(([^()]*(?:\([^()]*\))?[^()]*)\))");
  const std::regex batch_re(R"(kanegen_sincos_n\(angle_x, angle_s, angle_c, ([0-9]+)\);)");
  int headers = 0, calls = 0;
  for (const auto& m : kanegen::test::model_files()) {
    const std::string name = fs::path(m).stem().string();
    const std::string text = slurp(kanegen::test::source_path("generated/" + name + ".hpp"));
    ++headers;
    std::vector<std::pair<std::string, std::size_t>> starts;  // function name, body start
    for (std::sregex_iterator it(text.begin(), text.end(), fn_re), end; it != end; ++it)
      starts.emplace_back((*it)[1].str(), static_cast<std::size_t>(it->position() + it->length()));
    std::map<std::string, std::map<std::string, int>> seen;  // function (parts joined) -> call -> count
    std::map<std::string, int> batches;                      // function (parts joined) -> batches
    for (std::size_t f = 0; f < starts.size(); ++f) {
      const std::size_t stop = text.find("\n}\n", starts[f].second);
      const std::string body = text.substr(starts[f].second, stop - starts[f].second);
      auto& in_function = seen[std::regex_replace(starts[f].first, part_re, "")];
      int matched = 0, all = 0;
      for (std::sregex_iterator it(body.begin(), body.end(), call_re), end; it != end; ++it) {
        // skip the dual numbers' own definitions (std::sin of a.v)
        if (it->position() > 0 && body[static_cast<std::size_t>(it->position()) - 1] == ':') continue;
        ++in_function[(*it)[1].str() + "(" + (*it)[2].str() + ")"];
        ++matched;
      }
      for (std::sregex_iterator it(body.begin(), body.end(), any_call_re), end; it != end; ++it)
        if (it->position() == 0 || body[static_cast<std::size_t>(it->position()) - 1] != ':') ++all;
      for (std::sregex_iterator it(body.begin(), body.end(), batch_re), end; it != end; ++it) {
        ++batches[std::regex_replace(starts[f].first, part_re, "")];
        calls += 2 * std::stoi((*it)[1].str());
      }
      INFO(name << ": " << starts[f].first);
      CHECK(matched == all);  // no call the pattern above could not read
      calls += matched;
    }
    CHECK(seen.count("udot") == 1);
    for (const auto& [function, n] : batches) {
      INFO(name << ": " << function);
      CHECK(n == 1);  // one batch per function, its parts included (the first part computes it)
    }
    for (const auto& [function, in_function] : seen)
      for (const auto& [call, count] : in_function) {
        INFO(name << ": " << function << ": " << call);
        CHECK(count == 1);
      }
  }
  CHECK(headers >= 20);
  CHECK(calls >= 500);  // the headers do evaluate them (1,037 sin and cos in 26 headers on 2026-12-06)
}
