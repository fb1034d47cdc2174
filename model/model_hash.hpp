// A canonical fingerprint of a Model and its hash. Generated code carries the
// hash of the model it was generated from (KanegenGeneratedApi::model_hash);
// the runtime refuses generated code whose hash differs from the model it is
// given, and the JIT cache is keyed by it.
//
// The fingerprint covers everything that changes the generated equations or
// the outputs: names, topology, joints (with their prescribed motion), mass
// data, flexible data (nodes, shapes, second-order data, frequencies, damping,
// modal stiffness), gravity, state layout and the requested outputs. It leaves out what generated code does not depend
// on: the description, the source path and the initial state. Numbers are
// printed with 17 significant digits (-0 printed as 0), so equal models give
// equal text on every platform.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "model/model.hpp"

namespace kanegen {

/// Canonical, line-oriented text of every dynamics-relevant field of the model.
std::string model_fingerprint(const Model& model);

/// 16 lower-case hex digits: FNV-1a-64 of model_fingerprint(model).
std::string model_hash(const Model& model);

/// FNV-1a-64 of arbitrary bytes, and its 16-digit lower-case hex form.
std::uint64_t fnv1a64(std::string_view bytes);
std::string fnv1a64_hex(std::string_view bytes);

}  // namespace kanegen
