#pragma once
// The pressure of a rigid cone pressed point-first into the sensor's pad, on the forward
// model's load grid: the forward model's box corner (ContactShape::kCorner, SplatCone).
//
// A rigid cone whose surface makes the angle beta with the pad, pressed into an elastic
// half-space (Sneddon's cone; Johnson, Contact Mechanics, section 5.3), touches a disc of
// radius a with
//   p(r) = (E* tan(beta) / 2) arccosh(a / r)   (r < a: a logarithmic peak at the tip)
//   F    = (pi / 2) a^2 E* tan(beta)           (so a = sqrt(2 F / (pi E* tan beta)))
// and the force within r is F [t^2 arccosh(1/t) + 1 - sqrt(1 - t^2)], t = r / a (the rings'
// exact shares below). A box corner pointing into the pad is a three-sided pyramid whose
// faces stand at acos(1/sqrt(3)) = 54.7 deg to the pad; its section at a depth z is an
// equilateral triangle (inradius z / sqrt(2)) of area 3 sqrt(3) z^2 / 2. The cone of the same
// section area has cot^2(beta) = 3 sqrt(3) / (2 pi), tan(beta) = 1.0996 (kCubeCornerConeTan):
// the sensor, its taxels 4.7 mm apart, sees the corner's sub-millimetre patch only through
// its spread, not its three-fold shape.

#include <Eigen/Core>
#include <vector>

#include "sensors/tactile_forward_model.h"

namespace sedbridge::sensors {

/// tan(beta) of the cone with a cube corner's section area (see above).
constexpr double kCubeCornerConeTan = 1.0996361;

/// The contact radius a [mm] of the cone of slope tan_beta at force_N on a half-space of
/// contact modulus E_kPa: a = sqrt(2 F / (pi E* tan beta)).
double ConeContactRadius_mm(double force_N, double contact_modulus_kPa, double tan_beta);

/// The share of a cone's force within r of its tip: t^2 arccosh(1/t) + 1 - sqrt(1 - t^2),
/// t = r / a clamped to [0, 1].
double ConeForceShareWithin(double r_mm, double a_mm);

/// A cone's pressure (tip at (x, y), contact radius a_mm, force_N) for a fit: rings of the
/// law's exact share of the force, each spread over sectors and bilinearly over the four
/// cells around each sector's centre (as SplatFlatPunch's round face), so the loads move
/// smoothly with the tip and the radius. Grid: n x n cells of side h, cell 0's centre at
/// `origin`; cells off it get nothing. Appended to `loads` (normal only), in cell order.
void SplatCone(double x_mm, double y_mm, double a_mm, double force_N, const Eigen::Vector2d& origin, double h, int n,
               std::vector<SurfaceLoad>* loads);

}  // namespace sedbridge::sensors
