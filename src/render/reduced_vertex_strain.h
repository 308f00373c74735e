#pragma once
// A smaller description of the display's influence for the renderer's fit, per Merkel
// vertex: the vertex's SED is 1/2 |y|^2 with y = L^T eps the stacked strains of its elements
// scaled by the square roots of their elastic matrices and weights (W = 1/2 eps^T D eps).
// The commands move y only within the span of their strain changes; that span's leading
// directions (principal components of every actuator's change over every segment) and the
// preload's own direction carry almost all of it. y in that basis is the new description,
// six coordinates to a "pseudo-element" (mu 1/2, lambda 0, the shear coordinates halved so
// that its SED is 1/2 |z|^2), so the influence, its kernel and its segments are used as
// they are, on fewer rows.

#include "render/display_influence.h"

namespace sedbridge::render {

struct ReducedVertexStrainStats {
  /// The largest share of a vertex's command-strain energy left out (sum of the dropped
  /// squared singular values over the total).
  double largest_dropped_share = 0;
};

/// `in` described per vertex in the leading directions of its commands' strain changes.
/// @param dropped_share a vertex keeps directions until the share of its commands' strain
///        energy (squared singular values) left out is at most this (0: keep every direction)
/// Offsets and knots are kept. Throws std::invalid_argument for an inconsistent `in`
/// (CheckElementStrainInfluence) or a share outside [0, 1).
ElementStrainInfluence ReduceStrainPerVertex(const ElementStrainInfluence& in, double dropped_share,
                                             ReducedVertexStrainStats* stats = nullptr);

}  // namespace sedbridge::render
