#include "view/view_page.hpp"

#include <fmt/format.h>

#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "engine/resources.hpp"

namespace kanegen {

namespace {

std::string read_file(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(fmt::format("cannot read {} ({})", path, what));
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// JSON safe inside <script>: every '<' written as \u003c (still JSON, still JavaScript), so that no text in
/// it ("</script>", "<!--") can end or change the element.
std::string script_safe(const std::string& json) {
  std::string out;
  out.reserve(json.size());
  for (char c : json) {
    if (c == '<')
      out += "\\u003c";
    else
      out += c;
  }
  return out;
}

}  // namespace

std::string three_js_dir() {
  if (const char* v = std::getenv("KANEGEN_THREE_JS_DIR"); v && *v) return v;
  return "/usr/share/javascript/three";
}

std::string view_page(const nlohmann::json& data) {
  const std::string dir = three_js_dir();
  const std::string install = "three.js r111 from Debian's libjs-three: apt-get install libjs-three "
                              "(scripts/install_deps.sh installs it), or set KANEGEN_THREE_JS_DIR";
  const std::map<std::string, std::string> parts = {
      {"{{THREE_JS}}", read_file(dir + "/three.min.js", install)},
      {"{{ORBIT_CONTROLS}}", read_file(dir + "/examples/js/controls/OrbitControls.js", install)},
      {"{{DATA}}", script_safe(data.dump())},
      {"{{TITLE}}", data.value("model", std::string("model"))},
  };
  const std::string page = read_file(data_dir() + "/view/view.html.in", "kanegen's page template");
  // one pass over the template: the inserted text is never scanned for placeholders
  std::string out;
  std::size_t at = 0;
  for (;;) {
    const std::size_t open = page.find("{{", at);
    if (open == std::string::npos) break;
    const std::size_t close = page.find("}}", open);
    if (close == std::string::npos) break;
    const auto it = parts.find(page.substr(open, close + 2 - open));
    if (it == parts.end()) {
      out += page.substr(at, close + 2 - at);
    } else {
      out += page.substr(at, open - at);
      out += it->second;
    }
    at = close + 2;
  }
  out += page.substr(at);
  return out;
}

}  // namespace kanegen
