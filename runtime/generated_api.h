/* The C interface between generated model code and the runtime.
 * A generated model header (generator/, templates/model.hpp.in) is wrapped by
 * templates/entry.cpp.in into one function, kanegen_generated_api(), which
 * returns this table. The JIT path dlopen()s a shared library exporting it;
 * AOT simulators (kanegen_add_model) link it directly. Nothing else in the
 * runtime depends on generated names.
 *
 * Arrays: q[nq], u[nu], tau[nu]; M row-major nu x nu; wrenches 6 per body
 * ([force; torque about O_B], body components, bodies in model order);
 * Jacobian column-major (nq+nu) x (nq+nu) of x' = [q_dot; u_dot] w.r.t. x = [q; u].
 * Optional entries (energy, momentum, reactions) are NULL when the model's
 * `outputs:` did not ask for them.
 */
#ifndef KANEGEN_GENERATED_API_H
#define KANEGEN_GENERATED_API_H

#ifdef __cplusplus
extern "C" {
#endif

#define KANEGEN_GENERATED_API_VERSION 1

typedef struct KanegenGeneratedApi {
  int api_version;               /* KANEGEN_GENERATED_API_VERSION */
  const char* model_name;
  const char* model_hash;        /* hex fingerprint of the model (generator/model_hash) */
  const char* generator_version;
  int nq, nu, nbodies;
  void (*qdot)(const double* q, const double* u, double* qdot);
  void (*mass_matrix)(const double* q, double* M);
  void (*forcing)(const double* q, const double* u, const double* tau, double* F);
  /* returns 0, or the 1-based index of the first non-positive pivot of M */
  int (*udot)(const double* q, const double* u, const double* tau, double* udot);
  /* returns like udot */
  int (*jacobian)(const double* q, const double* u, const double* tau, double* J);
  void (*energy)(const double* q, const double* u, double* TV);       /* T, V */
  void (*momentum)(const double* q, const double* u, double* pH);     /* p_N[3], H_N[3] */
  void (*reactions)(const double* q, const double* u, const double* udot, double* wrenches);
} KanegenGeneratedApi;

typedef const KanegenGeneratedApi* (*KanegenGeneratedApiFn)(void);

#ifdef __cplusplus
}
#endif

#endif
