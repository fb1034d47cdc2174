// generated/ holds the header of every model in models/: regenerating each
// with `kanegen generate` must give the committed bytes (the generator is
// deterministic: no timestamp, output independent of process state), and
// each header must compile on its own with nothing but <cmath>.
#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>
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
