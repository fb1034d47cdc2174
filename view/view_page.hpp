// The self-contained HTML page of `kanegen view` (issue 37): the page
// template (share/kanegen/view/view.html.in) with three.js and its
// OrbitControls inlined (Debian's libjs-three, r111: one file that opens
// offline in any current browser, no server, no network) and the data of
// view_data() as a JSON literal. The page only draws.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace kanegen {

/// Where three.js is read from: $KANEGEN_THREE_JS_DIR, else Debian's /usr/share/javascript/three.
std::string three_js_dir();

/// The page. Throws std::runtime_error when three.js or the page template cannot be read (saying what to install).
std::string view_page(const nlohmann::json& data);

}  // namespace kanegen
