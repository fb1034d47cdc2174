// Hand-written stand-in for a generated entry file (templates/entry.cpp.in):
// wraps pendulum_handwritten.hpp (included as "model.hpp") into the table of
// engine/generated_api.h. No reactions (not requested by the model).
// "@MODEL_HASH@" and "@GENERATOR_HASH@" are replaced by the test.
#include "model.hpp"

#include "engine/generated_api.h"

namespace ns = kanegen_gen::pendulum_handwritten;

extern "C" {
static int f_qdot(const KanegenArgs* a, double* out) {
  ns::qdot<double>(a->q, a->u, out);
  return 0;
}
static int f_mass_matrix(const KanegenArgs* a, double* out) {
  ns::mass_matrix<double>(a->q, out);
  return 0;
}
static int f_forcing(const KanegenArgs* a, double* out) {
  ns::forcing<double>(a->q, a->u, a->tau, out);
  return 0;
}
static int f_udot(const KanegenArgs* a, double* out) { return ns::udot<double>(a->q, a->u, a->tau, out); }
static int f_jacobian(const KanegenArgs* a, double* out) { return ns::jacobian(a->q, a->u, a->tau, out); }
static int f_energy(const KanegenArgs* a, double* out) {
  ns::energy<double>(a->q, a->u, out);
  return 0;
}
static int f_momentum(const KanegenArgs* a, double* out) {
  ns::momentum<double>(a->q, a->u, out);
  return 0;
}
}

#if !defined(KANEGEN_PART_qdot) && !defined(KANEGEN_PART_udot) && !defined(KANEGEN_PART_forcing) && \
    !defined(KANEGEN_PART_mass_matrix) && !defined(KANEGEN_PART_jacobian) && !defined(KANEGEN_PART_energy) && \
    !defined(KANEGEN_PART_momentum)
namespace {
const KanegenFunction kFunctions[] = {
    {"qdot", &f_qdot, 1},         {"mass_matrix", &f_mass_matrix, 1}, {"forcing", &f_forcing, 1},
    {"udot", &f_udot, 1},         {"jacobian", &f_jacobian, 4},       {"energy", &f_energy, 2},
    {"momentum", &f_momentum, 6},
};
const KanegenGeneratedApi kApi = {KANEGEN_GENERATED_API_VERSION, "pendulum_handwritten", "@MODEL_HASH@", "@GENERATOR_HASH@",
                                  1, 1, 1, 0, 0, 0, 7, kFunctions};
}  // namespace
extern "C" __attribute__((visibility("default"))) const KanegenGeneratedApi* kanegen_api_pendulum_handwritten(void) {
  return &kApi;
}
#endif
