#pragma once
// The parameterisation of the contact models: each model's unknowns as the fitter
// (contact_fitter.h) moves them, and back. Logs keep radii, lengths and forces positive and
// make their steps relative; a rod's position is its axis's offset across itself (and, a
// finite rod, its centre along it), so that sliding along an infinite rod is no unknown.
//   sphere:      x, y, log R, log F
//   rod:         offset of the axis from the pad centre along its normal, yaw, log R, log F
//   finite rod:  offset, yaw, log R, centre along the axis, log half-length, log F
//   flat:        log F
//   punch:       x, y (the face's centre), log a, log b (half sizes), yaw, log F
//   round punch: x, y (the face's centre), log a (its radius), log F
//   corner:      x, y (its tip), log F (its angle is the box's: sensors/cone_pressure.h)
//   pair:        two spheres' (8), the second's after the first's
// then, with shear, T_x, T_y [N] (the whole tangential force).

#include <Eigen/Core>

#include "sensors/contact_primitive.h"

namespace sedbridge::contact {

/// One model's parameters: a primitive, or (pair) two spheres.
struct Hypothesis {
  sensors::ContactPrimitive first;
  bool pair = false;
  sensors::ContactPrimitive second;  ///< pair only: a sphere, no shear
};

/// Index of log R among a sphere's or rod's unknowns (ToUnknowns); a pair's second sphere
/// has its unknowns kSphereUnknowns further on.
constexpr int kLogRadius = 2;
constexpr int kSphereUnknowns = 4;

/// A finite rod's half-length stays within these [mm] (longer crosses the pad anyway).
constexpr double kMinHalfLength_mm = 0.25, kMaxHalfLength_mm = 15;
/// A punch's half sizes (a round one's radius) stay within these [mm]: narrower is a rod's
/// edge to the sensor (its taxels 4.7 mm apart), wider covers the pad.
constexpr double kMinPunchHalfSize_mm = 0.25, kMaxPunchHalfSize_mm = 8;
constexpr int kPunchUnknowns = 6;
constexpr int kRoundPunchUnknowns = 4;
constexpr int kCornerUnknowns = 3;

/// A cylinder of finite length (an edge), not one across the pad.
bool IsFiniteRod(const sensors::ContactPrimitive& p);
/// Unknowns of a model: the shape's (a pair's two spheres'), then the shear's two.
int UnknownCount(sensors::ContactShape s, bool pair, bool finite, bool shear);
/// The primitive of one shape's unknowns at u (no shear); logs clamped to finite ranges.
sensors::ContactPrimitive ShapeFromUnknowns(sensors::ContactShape shape, bool finite, const double* u);
/// Hypothesis -> unknowns (layout above).
Eigen::VectorXd ToUnknowns(const Hypothesis& h, bool shear);
/// Unknowns -> hypothesis; the shear goes with the first primitive.
Hypothesis FromUnknowns(sensors::ContactShape shape, bool pair, bool finite, const Eigen::VectorXd& u, bool shear);

}  // namespace sedbridge::contact
