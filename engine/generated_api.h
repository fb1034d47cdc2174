/* The C interface between generated model code and the runtime.
 * The assembler (codegen/assembler.hpp) wraps every function of a generated
 * model header into a C function of one signature,
 *     int f(const KanegenArgs* args, double* out),
 * and lists them by name in a table returned by kanegen_api_<model>(). The
 * JIT dlopen()s a shared library exporting it (the symbol's name is in the
 * model's manifest); ahead-of-time simulators link it directly. The runtime
 * looks functions up by name (engine/generated_engine.hpp): nothing else in
 * it depends on generated names.
 *
 * Arrays: q[nq], u[nu], tau[nu], udot[nu], inputs[nw]; each function's `out` holds
 * out_size doubles (M row-major nu x nu; wrenches 6 per body, [force; torque
 * about O_B], body components; Jacobian column-major (nq+nu)^2; outputs
 * y[ny]; input_jacobian du_dot/dw column-major nu x nw; output_jacobian
 * dy/d[q; u; w; tau] column-major ny x (nq+2nu+nw)).
 * Return value: 0, or for udot and jacobian the 1-based index of the speed
 * whose pivot in the factorization of M is not positive.
 */
#ifndef KANEGEN_GENERATED_API_H
#define KANEGEN_GENERATED_API_H

#ifdef __cplusplus
extern "C" {
#endif

#define KANEGEN_GENERATED_API_VERSION 4

typedef struct KanegenArgs {
  double t;             /* time: used by models with prescribed motion */
  const double* q;
  const double* u;
  const double* tau;
  const double* udot;   /* accelerations: input of reactions */
  const double* inputs; /* the named inputs w[nw] (models that declare inputs) */
  const double* params; /* the runtime parameters prm[np] (models that declare some) */
} KanegenArgs;

typedef int (*KanegenFunctionPtr)(const KanegenArgs* args, double* out);

typedef struct KanegenFunction {
  const char* name;     /* "qdot", "mass_matrix", "forcing", "udot", "jacobian", "energy", ... */
  KanegenFunctionPtr fn;
  int out_size;
} KanegenFunction;

typedef struct KanegenGeneratedApi {
  int api_version;               /* KANEGEN_GENERATED_API_VERSION */
  const char* model_name;
  const char* model_hash;        /* model/model_hash.hpp */
  const char* generator_hash;    /* hash of the generator that wrote the code */
  int nq, nu, nbodies;
  int nw, ny;                    /* named inputs and outputs */
  int np;                        /* runtime parameters */
  int n_functions;
  const KanegenFunction* functions;
} KanegenGeneratedApi;

typedef const KanegenGeneratedApi* (*KanegenGeneratedApiFn)(void);

#ifdef __cplusplus
}
#endif

#endif
