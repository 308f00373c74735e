#pragma once
// The pressure of a rigid flat-faced punch on the sensor's pad, on the forward model's load
// grid: the forward model's punches (ContactShape::kPunch and kRoundPunch, SplatFlatPunch) and
// the rig check (FlatPunchLoads).
//
// A rigid flat punch on an elastic half-space loads its edges most:
//   round (radius a):        p(r) = F / (2 pi a sqrt(a^2 - r^2))          (Boussinesq)
//   rectangle (a x b halves): p(u, v) = F / (pi^2 sqrt((a^2 - u^2)(b^2 - v^2)))
// The rectangle has no closed form; the product of the two strip solutions is the law the
// rig's punches follow best of those tried, all sharp (the exponent 0.5 on each axis; 0.4
// alike; 0.6: worst axis 1.2-11 sigma, 0.7: 1.9-18; p ~ 1/sqrt(1 - max(|u|/a, |v|/b)^2): 1.6-5.9;
// the sum of the axes' factors: 2.4-10).
// A real edge is rounded: within rounding_mm of an edge the pressure stays at its value there
// (the factor of each axis is capped), and the whole is scaled back to F. Through the shipped
// kernels the rig's four punches and bars (presses 21-23, 29) are explained best with 0.05 mm:
// 0.20-0.89 single-scan sigma on every axis (0.03 mm: up to 1.65; 0.1: 1.83; 0.2, the most
// their README allows: 4.8; sharp: 4.6; a uniform face: 2.0-25). A calibration parameter, as
// the rod's band width is; fitted here by hand over 0, 0.01, 0.03, 0.05, 0.1, 0.2 mm.

#include <vector>

#include "sensors/tactile_forward_model.h"

namespace sedbridge::sensors {

struct FlatPunch {
  double x_mm = 0, y_mm = 0;  ///< centre of the face, pad frame
  bool round = false;         ///< round (radius half_size_mm[0]) or rectangular
  double half_size_mm[2] = {1, 1};  ///< rectangle: along (cos yaw, sin yaw) and across it
  double yaw_deg = 0;
  double rounding_mm = 0.05;  ///< edge rounding that caps the pressure (>= 0): the rig's fit
  double normal_force_N = 0;
};

/// The punch's pressure on `model`'s load grid (the face carries the force; what of it lies
/// off the grid is dropped): each axis (or ring) integrated exactly over strips of at most a
/// quarter cell, so the edge's concentration is kept where a sampled law would miss it.
/// rounding_mm at or above the half size gives a uniform face.
std::vector<SurfaceLoad> FlatPunchLoads(const TactileForwardModel& model, const FlatPunch& punch);

/// A punch primitive as the forward model presses it: its pose, half sizes and force, with the
/// rig's rounding (FlatPunch's default); rectangular (ContactShape::kPunch) or round
/// (kRoundPunch: radius_mm, the same rounding caps its rim's 1 / sqrt(1 - (r/a)^2)).
FlatPunch FlatPunchOf(const ContactPrimitive& punch);

/// Strips a side of the rectangle (SplatFlatPunch): a fixed count, so that the loads do not
/// jump as the half sizes change (a fit differences them).
constexpr int kPunchStripsPerSide = 24;
/// The same pressure (rectangle, or round: rings) for a fit: each strip's exact share of the
/// force, spread bilinearly over the four cells around its centre, so the loads move smoothly
/// with the pose and size (FlatPunchLoads' nearest cell moves them in jumps). Grid: n x n
/// cells of side h, cell 0's centre at `origin`, cell = row * n + column; cells off it get
/// nothing (the pad ends there), and the rest is not scaled back (as FlatPunchLoads). The
/// loads are appended to `loads` (normal only), in cell order. About 10 us.
void SplatFlatPunch(const FlatPunch& punch, const Eigen::Vector2d& origin, double h, int n,
                    std::vector<SurfaceLoad>* loads);

}  // namespace sedbridge::sensors
