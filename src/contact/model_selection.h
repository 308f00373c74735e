#pragma once
// Model selection: which shape explains a scan. Starts of every shape (spheres, rods across
// the pad, rods that end on it, flats, two spheres at once) from the moments of the normal
// readings; the least penalized residual (chi^2 + 2 x #unknowns) wins. The selection itself
// (full: every start at once; amortized: one candidate at a time within a budget, continued
// by the next scan) runs in ContactReconstructor (model_selection.cpp).

#include "contact/contact_fitter.h"
#include "contact/contact_parameters.h"
#include "contact/reconstruction_options.h"

namespace sedbridge::contact {

/// Moments of the normal readings of a scan: their sum, centroid and spread.
struct NormalMoments {
  double sum_z = 0;             ///< sum of the normal readings [N]
  double mx = 0, my = 0;        ///< centroid [mm]
  double principal_yaw_deg = 0;  ///< direction of the largest spread
  double principal_var_mm2 = 0;  ///< spread along it [mm^2]
  double minor_var_mm2 = 0;      ///< spread across it [mm^2]
};

/// One start of the selection: a shape, its radius and yaw (the rest from the moments).
struct SelectionStart {
  sensors::ContactShape shape;
  double radius_mm, yaw_deg;
  bool pair = false, finite = false;
};
/// A punch start's half size across its principal direction [mm] (a round punch's radius).
constexpr double kPunchStartHalfSize_mm = 1.5;
/// The round punch's check waits for a hold's mean of this many scans (CheckRoundPunch).
constexpr int kRoundPunchHoldScans = 8;
/// ... and replaces the answer when Better by strong evidence: its data chi^2 lower by at
/// least this (a likelihood ratio of e^4.5, about 90: between Kass and Raftery's "strong" 6 and
/// "very strong" 10 in 2 ln B). The sphere it competes with has as many unknowns, so Better's
/// AIC alone lets noise decide between a small dome and a small face.
constexpr double kRoundPunchMarginChi2 = 9;
/// The box corner's check waits for a hold's mean of this many scans (CheckCorner) ...
constexpr int kCornerHoldScans = 8;
/// ... read as a sphere smaller than this [mm]: a corner's patch (sensors/cone_pressure.h: a =
/// sqrt(2 F / (pi E* tan beta))) is a sphere's of R = 4 E* a^3 / (3 F), about 1.05 mm at
/// 1 N and 1.5 at 2 N on the uSkin pad (E* 313 kPa); the rig's and the synthetic sets'
/// spheres are read at 1.99 mm and more.
constexpr double kCornerSphereRadius_mm = 1.5;
/// A fit read as one sphere smaller than kCornerSphereRadius_mm.
bool ReadAsSmallSphere(const Fit& fit);
/// The corner's start: the sphere's tip and force.
Hypothesis CornerStart(const sensors::ContactPrimitive& sphere);
/// The round punch's start: kPunchStartHalfSize_mm in radius at the centroid.
constexpr SelectionStart kRoundPunchStart{sensors::ContactShape::kRoundPunch, kPunchStartHalfSize_mm, 0};

/// A scan's starts: spheres of 3 and 10 mm, rods of 1, 1.5 (across) and 3 mm along the
/// principal direction, the flat; then the finite rod (fit_finite_rods), the pair
/// (fit_pairs) and the punch (fit_punches) last. The round punch is no start of the
/// amortized rotation: it gets a check of its own on the hold's mean (CheckRoundPunch in
/// contact_reconstruction.h); kFull tries it after these (fit_round_punches).
struct SelectionStarts {
  SelectionStart start[9];
  int count = 0;
  int pair = 0;  ///< index of the pair's start (== count without fit_pairs)
};
SelectionStarts MakeStarts(const ReconstructionOptions& options, const NormalMoments& moments);

/// A start's first guess: `guess` (centroid, force) with the start's shape, radius and yaw. A
/// finite rod: centred on the centroid, as long as the readings spread. A pair: two 3 mm
/// spheres, each with half the force, on the principal axis either side of the centroid, as
/// far apart as the readings spread. A punch: centred on the centroid, turned to the
/// principal direction, kPunchStartHalfSize_mm across it and longer along it as the readings
/// spread more that way. A round punch: centred on the centroid, kPunchStartHalfSize_mm in
/// radius.
Hypothesis StartHypothesis(const ReconstructionOptions& options, const sensors::ContactPrimitive& guess,
                           const NormalMoments& moments, const SelectionStart& start);

}  // namespace sedbridge::contact
