#pragma once
// Where the display stage's requests come from, when not from the per-site curve: an
// injected source (the bridge's inverse FE renderer, src/bridge/inverse_display_requests.h).
// Defined here because display/ includes nothing from src/ but src/common: the source is
// handed in, display/ never sees how it is computed.

#include <functional>
#include <vector>

#include "display/sed_field.h"

namespace sedbridge::display {

/// Fills `requested` (one value per actuator, the profile's unit, before the safety limiter)
/// for a field that passed the whole-field check (finite, consistent lengths). Called only
/// for such fields: a rejected field keeps NaN requests, which the limiter answers with 0 and
/// the fault flag. A source may write NaN itself to fault the command. Empty: the curve.
using CommandRequestSource = std::function<void(const SedField& field, std::vector<double>* requested)>;

}  // namespace sedbridge::display
