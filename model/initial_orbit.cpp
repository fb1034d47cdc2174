#include "model/initial_orbit.hpp"

namespace kanegen {

OrbitSetNames orbit_set_names(const std::string& root, bool lvlh) {
  OrbitSetNames n{{root + ".x", root + ".y", root + ".z"}, {root + ".vx", root + ".vy", root + ".vz"}};
  if (lvlh) {
    for (const char* c : {".qw", ".qx", ".qy", ".qz"}) n.q.push_back(root + c);
    for (const char* c : {".wx", ".wy", ".wz"}) n.u.push_back(root + c);
  }
  return n;
}

}  // namespace kanegen
