// Catch2 checks of a cross-check's result (sim/crosscheck.hpp), and the
// cross-check of an engine at changed runtime parameters against the generic
// engine of the model with those values written in (model/parameters.hpp).
#pragma once

#include <catch2/catch.hpp>

#include "engine/generic_engine.hpp"
#include "model/parameters.hpp"
#include "sim/crosscheck.hpp"

namespace kanegen::test {

/// Every quantity of r within its tolerance: one CHECK each, the quantity named in a failure.
inline void check_within_tolerances(const CrosscheckResult& r) {
  for (const auto& [q, v] : r.worst) {
    INFO(q << " " << v);
    CHECK(v <= CrosscheckResult::tolerance(q));
  }
}

/// `e` at parameter values p against the generic engine of `model` changed in place (as a new file would be).
inline CrosscheckResult crosscheck_at_parameters(Engine& e, const Model& model, const VecX& p, int samples,
                                                 unsigned seed) {
  e.set_parameters(p);
  Model changed = model;
  apply_parameters(changed, model.parameters, p);
  changed.parameters.clear();
  GenericEngine reference(changed);
  return crosscheck(e, reference, samples, seed);
}

}  // namespace kanegen::test
