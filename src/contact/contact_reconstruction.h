#pragma once
// Contact reconstruction: from one scan of the follower's three-axis sensor, the object that
// touches it — shape (sphere, cylinder, flat, or two spheres at once), pad-frame position,
// radius, yaw, normal force and tangential force — by inverting the calibrated forward model
// (sensors/tactile_forward_model.h) with weighted nonlinear least squares.
//
// Per scan:
//  - hold averaging: while the contact holds still (the scan agrees with the running mean
//    within noise) the fit reads the mean of the scans since it last moved, with that
//    mean's noise: a hold determines what one scan cannot (a thin rod's radius);
//  - no contact: the normal readings sum below min_force_N x the model's gain -> force 0;
//  - warm start: the last scan's shape and parameters, refined (contacts move
//    continuously, so this is the common path); off a hold, a step in the force and shear
//    alone comes first and answers the scan when it explains it as well as the last fit
//    explained its own (a ramp changes the force, not the shape: force_step_first);
//  - model selection among starts of every shape (moments of the normal readings; spheres,
//    rods across the pad, rods that end on it, flats, two spheres at once), the
//    least penalized residual (chi^2 + 2 x #unknowns) winning: amortized (default) refines
//    the current model and at most one candidate start per scan, each within a budget of
//    forward-model evaluations, continuing from where the last scan stopped (a fit of the
//    scan before is a good start for this one), until every start was tried in the contact
//    episode and the fit is within noise; full fits every start to convergence at once;
//  - a lone misfit: a fit whose RMS residual exceeds max_rms_sigma and whose misfit one
//    taxel carries at least lone_taxel_share of is refitted (warm, from it) without that
//    taxel; the refit answers when it explains the others within max_rms_sigma (a taxel
//    that lies and that taxel health has not masked yet; TaxelUse::kLoneMisfit), and stays
//    out of the contact episode's later scans until the fit predicts its readings again.
//    Failing that, the taxel that reads the most below the fit is tried the same way, and
//    answers when its misfit under the refit is at least all the others' (a fit that bent
//    around a dead taxel puts most of its misfit on the live ones beside it); a finite rod
//    that the refit stretches across the pad is refitted as the rod across it. A fit within
//    max_rms_sigma that is still inadequate (model_inadequate's test) tries only the taxel
//    that reads the most below it, and only when that taxel reads less than
//    dead_reading_share of its prediction (a dead one: a wrong shape's misfit leaves it most
//    of its reading); it answers when the refit is adequate and its misfit stands alone;
//  - a fit whose RMS residual exceeds max_rms_sigma, or that leaves the plausible domain
//    (position off the pad, radius outside [min, max]), is a fallback: the caller uses the
//    pressure-map boundary condition instead, and it is counted.
// A weak prior on log R keeps light scans (ramp, release) from sending the radius to the
// ends of the plausible range; a radius that still leaves it stops at the bound.
//
// Its parts, one concept a file: the parameterisation of each model (contact_parameters.h),
// the Levenberg-Marquardt fitter (contact_fitter.h), the model selection's starts and budgets
// (model_selection.h), hold averaging (hold_filter.h) and radius tracking (radius_tracking.h).

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "contact/contact_estimate.h"
#include "contact/contact_fitter.h"
#include "contact/contact_parameters.h"
#include "contact/hold_filter.h"
#include "contact/model_selection.h"
#include "contact/radius_tracking.h"
#include "contact/reconstruction_options.h"
#include "sensors/scan.h"
#include "sensors/sensor_profile.h"
#include "sensors/tactile_forward_model.h"

namespace sedbridge::contact {

/// Counters since construction.
struct ReconstructionCounters {
  int64_t scans = 0;
  int64_t no_contact = 0;
  int64_t fits = 0;
  int64_t warm_fits = 0;       ///< answered from the warm start alone
  int64_t fallbacks = 0;       ///< poor or diverged fits
  int64_t two_contacts = 0;    ///< scans answered with two spheres
  int64_t force_steps = 0;     ///< warm fits answered by the force step alone (force_step_first)
  int64_t saturated_taxels = 0;
  int64_t lone_taxels_left_out = 0;  ///< fits redone without the one taxel that carried their misfit
  int64_t lone_taxel_scans = 0;      ///< scans fitted without a lone misfit left out on an earlier scan
  int64_t evaluations = 0;     ///< forward-model evaluations, all scans (the cost, deterministic)
  int64_t model_inadequate = 0;  ///< contact scans no model explained within noise (ContactEstimate::model_inadequate)
};

class ContactReconstructor {
 public:
  /// @param profile  three-axis profile with a `forward_model` (throws std::invalid_argument
  ///                 otherwise)
  ContactReconstructor(const sensors::SensorProfile& profile, ReconstructionOptions options = {});

  /// Reconstructs the contact of one scan (conditioned values as the assembler gives them).
  const ContactEstimate& Reconstruct(const sensors::Scan& scan);
  /// Same from readings [N] (3 per taxel: x, y, z) with per-taxel validity and saturation.
  const ContactEstimate& Reconstruct(const Eigen::VectorXd& readings_N, const std::vector<uint8_t>& valid,
                                     const std::vector<uint8_t>& saturated = {});
  /// Forgets the warm start.
  void Reset() {
    have_last_ = false;
    have_last_chi2_ = false;
    have_candidate_ = false;
    lone_taxel_ = -1;
    explored_ = 0;
    pair_checked_ = false;
    punch_round_ = false;
    round_punch_ = corner_ = SideCandidate{};
    hold_.Reset();
  }

  const ReconstructionCounters& counters() const { return counters_; }
  const sensors::TactileForwardModel& model() const { return model_; }
  const ReconstructionOptions& options() const { return options_; }

 private:
  /// One scan's model selection: its noise, first guess and starts, and the best fit so far.
  struct Selection {
    double dof = 1;                    // readings x averaged scans: chi^2 in single-scan noise units
    NormalMoments moments;
    sensors::ContactPrimitive guess;   // centroid and force of the normal readings
    SelectionStarts starts;
    bool track_candidates = false;     // candidates of the last answer's shape get the tracked prior
    Fit best;
    bool warm_won = false;             // best is the warm fit (its chi2 has the tracked prior already)
  };

  // The stages of Reconstruct, in order.
  /// Readings, weights and saturation of the scan into obs_, weight_, saturated_, and the hold
  /// mean; false (estimate_ says why, counted) when the scan cannot be fitted.
  bool LoadScan(const Eigen::VectorXd& readings_N, const std::vector<uint8_t>& valid,
                const std::vector<uint8_t>& saturated);
  /// Sum and (unnormalized) first moments of the normal readings.
  NormalMoments NormalSum() const;
  /// The no-contact answer (ok, force 0): the episode ends.
  const ContactEstimate& NoContact();
  /// Centroid and spread of the normal readings (from NormalSum's moments), the first guess
  /// and the starts.
  Selection StartSelection(NormalMoments moments);
  /// The last answer refined: a force step first when it explains the scan, else a warm fit.
  void WarmFit(Selection& s);
  /// kFull: every start to convergence.
  void SelectFull(Selection& s);
  /// kAmortized: the pair's quick check, then candidates within the scan's budget, and the
  /// flat when nothing explains the scan.
  void SelectAmortized(Selection& s);
  void CheckPair(Selection& s);
  /// kAmortized: the round punch's check on a hold's mean, once an episode (model_selection.cpp).
  void CheckRoundPunch(Selection& s);
  /// kAmortized: the box corner's check on a hold's mean read as a small sphere, once an
  /// episode (model_selection.cpp).
  void CheckCorner(Selection& s);
  void AdvanceCandidates(Selection& s, int budget, bool explained);
  void FlatWhenNothing(Selection& s);
  /// A fit that one taxel's misfit would send to the fallback, redone without that taxel.
  void LeaveOutLoneMisfit(Selection& s);
  /// s.best refitted without taxel k; true (s.best replaced, k the lone misfit) when the
  /// refit explains the others within max_rms_sigma and, must_stand_alone, k's misfit under
  /// the refit is at least the others' together.
  bool RefitWithout(int k, Selection& s, bool must_stand_alone, bool adequate = false);
  /// The largest RMS residual^2 (single-scan noise units) that FlagInadequate calls adequate,
  /// for `dof` weighted channels x the scans averaged.
  double AdequateRms2(double dof) const;
  /// The lone misfit left out since an earlier scan comes back when the accepted fit
  /// predicts its readings within max_rms_sigma.
  void MaybeTakeBackLoneTaxel(const Fit& fit);
  /// A fit's predicted readings [N] (its prediction's parts and tangential force).
  Eigen::VectorXd Predicted(const Fit& fit) const;
  /// The best fit into estimate_ and the warm start (or a fallback).
  void Accept(const Fit& fit, bool warm, double dof);
  /// estimate_.model_inadequate (and its counter) from the accepted answer; dof: its
  /// weighted channels times the scans averaged.
  void FlagInadequate(double dof);

  FitProblem Problem() const;
  Fit FitStart(const SelectionStart& start, const Selection& s);
  /// Penalized residual for model selection; a candidate of the last answer's shape judged
  /// with the tracked radius prior instead of the weak one.
  double Penalized(const Fit& f, bool warm, const Selection& s) const;
  bool Better(const Fit& a, const Fit& b, const Selection& s) const;  // a better than b
  /// A fit's cost into this scan's estimate (evaluations, and weighted as the budgets count).
  void Tally(const Fit& fit);
  bool Plausible(const sensors::ContactPrimitive& p) const;
  bool Plausible(const Hypothesis& h) const;

  sensors::SensorProfile profile_;
  ReconstructionOptions options_;
  sensors::TactileForwardModel model_;
  Eigen::VectorXd inv_sigma_;       // per channel [1/N]
  Eigen::VectorXd full_scale_N_;    // per channel, saturation reading [N]
  // The scan being fitted.
  Eigen::VectorXd obs_, weight_;
  std::vector<uint8_t> saturated_;
  double log_r_lo_ = 0, log_r_hi_ = 0;  // plausible log radius [log mm]
  HoldFilter hold_;
  ContactEstimate estimate_;
  bool have_last_ = false;
  Hypothesis last_;
  Prediction last_prediction_;  // at last_ (when valid)
  double last_log_radius_var_ = 0;  // posterior variance of log R at last_ (single spheres, rods)
  TrackedRadius track_;             // this scan's tracked radius prior
  bool have_last_chi2_ = false;
  double last_chi2_per_dof_ = 0;  // the last accepted fit's chi^2 per reading (its own scan's dof)
  int next_start_ = 0;   // amortized selection: next start to try
  int explored_ = 0;     // starts tried in this contact episode
  bool pair_checked_ = false;  // the pair's quick check ran in this contact episode
  bool punch_round_ = false;   // a punch replaced another shape in this contact episode (AdvanceCandidates)
  // A shape checked outside the rotation, once an episode (CheckRoundPunch, CheckCorner): its
  // iterate over the scans of this episode and what it has spent.
  struct SideCandidate {
    bool started = false, done = false;
    Hypothesis model;
    Prediction prediction;
    int spent = 0;
    void Start(const Hypothesis& start) { model = start, prediction = Prediction{}, spent = 0, started = true; }
  };
  /// One scan's refinement of `side` within the candidate budget, its iterate kept; empty
  /// when nothing was evaluated (it waits as it was).
  std::optional<Fit> RefineSideCandidate(SideCandidate& side);
  SideCandidate round_punch_, corner_;
  // Amortized selection: the candidate being fitted over several scans (its iterate) and
  // the evaluations it has spent.
  bool have_candidate_ = false;
  // The lone misfit (LeaveOutLoneMisfit), left out of the later scans of the contact episode
  // until the fit predicts it again: otherwise the next scan's warm fit carries its misfit
  // again and a candidate that bends around it (two spheres either side of a dead taxel)
  // replaces the contact. -1: none.
  int lone_taxel_ = -1;
  Hypothesis candidate_;
  Prediction candidate_prediction_;  // at candidate_ (when valid)
  int candidate_spent_ = 0;
  double candidate_cost_ = 0;  // budget units per evaluation of the candidate's last fit (0: none yet)
  ReconstructionCounters counters_;
};

}  // namespace sedbridge::contact
