#pragma once
// The contact reconstruction's options: model selection, noise, plausible domain, the
// evaluation budgets of the amortized selection, the fitter's stopping rules, hold
// averaging and radius tracking (contact_reconstruction.h describes the scan's path).

namespace sedbridge::contact {

/// How the shape is chosen among sphere, cylinder and flat.
enum class ModelSelection {
  kFull,       ///< every start whenever the warm start does not explain the scan (cold
               ///< single scans: tests, offline)
  kAmortized,  ///< per scan: the current model refined within warm_scan_evaluations and
               ///< one candidate start (rotating) within candidate_scan_evaluations, each
               ///< continued by the next scan; until all starts were tried in a contact
               ///< episode, or while the residual is above settle_rms_sigma: bounded cost
               ///< per scan (about warm + candidate budgets x one model evaluation)
};

struct ReconstructionOptions {
  ModelSelection selection = ModelSelection::kAmortized;
  double settle_rms_sigma = 1.6;  ///< amortized: keep exploring while the fit is worse
  double noise_counts = 2;        ///< single-scan noise (1 sigma) per raw reading [counts]
  double min_force_N = 0.02;      ///< below this normal force: no contact
  double max_rms_sigma = 4.0;     ///< worse fits fall back to the pressure map
  /// The model-adequacy flag (ContactEstimate::model_inadequate): a contact is flagged when
  /// no plausible model explains it, or the best fit's RMS residual (single-scan noise
  /// units, over the hold window of N scans and m weighted channels) exceeds what noise and
  /// the forward model's own error leave:
  ///   rms^2 > (1 + adequacy_z sqrt(2 / m)) / N + model_error_sigma^2,
  /// a chi^2 test at adequacy_z sigma of the hold mean's noise, plus the model's calibration
  /// error (in single-scan sigma), which averaging does not remove. 1.0: the worst right
  /// answer of the rig's presses at hold (press_09, a 15 mm sphere: 0.97). On the rig
  /// 00-29: of 2555 contact scans answered with the right shape 2 are flagged (z = 3; with
  /// a fixed rms gate of 1.2, 59); of the 82 answered with a wrong shape outside the
  /// ambiguous ones (first touches, a centred 3 x 3 punch read as a 10 mm sphere within
  /// noise, press_21), 57 are flagged, and every fallback.
  double adequacy_z = 3.0;
  double model_error_sigma = 1.0;
  /// A fit worse than max_rms_sigma whose misfit one taxel carries at least this share of
  /// (a lying taxel that taxel health has not masked yet: its neighbours contradict it) is
  /// redone without that taxel, and the refit answers when it explains the others within
  /// max_rms_sigma (contact_reconstruction.h). 0 = off. A leave-one-out refit, not a robust
  /// loss inside every fit: scans that fit keep their answers bit for bit, and only a scan
  /// that would fall back pays a few more warm fits (at most two candidates, the second the
  /// taxel that reads the most below the fit, and a finite rod's refit across the pad:
  /// contact_reconstruction.h).
  double lone_taxel_share = 0.5;
  /// A fit within max_rms_sigma that is still inadequate (model_inadequate's test) is redone
  /// without the taxel that reads the most below it when that taxel reads less than this
  /// share of what the fit predicts for it (a dead taxel reads nothing where the fit says it
  /// is loaded; a wrong shape's misfit leaves it most of its reading), the refit is adequate
  /// and the taxel's misfit under it is at least the others' together. 0 = off.
  double dead_reading_share = 0.25;
  double min_radius_mm = 0.3;     ///< plausible radii for spheres and rods
  double max_radius_mm = 60;
  double max_offset_mm = 14;      ///< contact centre within this of the pad centre
  /// Two simultaneous contacts (two fingertips, two bumps) are one more model: two spheres,
  /// each with its own position, radius and force, sharing the tangential force. A pair is
  /// plausible only when its spheres touch at least this far apart (closer, two spots are
  /// one broad contact to taxels of about this pitch) ...
  double min_pair_separation_mm = 5.0;
  /// ... and the lighter carries at least this share of the total force (a lighter one is
  /// fitting noise or the other's model error, not a second object).
  double min_pair_force_share = 0.15;
  bool fit_pairs = true;          ///< false: single primitives only (a pair is a fallback)
  /// Amortized: a scan that is not a hold (a press, a release) first tries one Gauss-Newton
  /// step in the force and shear alone, the shape held (2 evaluations: the last answer's
  /// prediction is kept, see Prediction); when that explains
  /// the scan as well as the last fit explained its own (chi^2 per reading within 3 standard
  /// deviations of pure noise's), the full warm fit is skipped.
  bool force_step_first = true;
  /// ... also on the mean of this many scans or fewer: a slow ramp holds still for 2-4 scans
  /// at a time, and so short a mean tells the shape hardly more than one scan (rig rod
  /// press_14: 5.1 -> 4.0 evaluations a scan with 4 instead of 1, its peak ratio 0.94 ->
  /// 0.97; docs/lab-notes/2026-11-27-time-per-scan-rounds.md#contact-tolerance,
  /// "The force step also answers short hold means"). A longer hold refines the shape.
  int force_step_max_averaged_scans = 4;
  /// A rod of finite length (a box's or a ruler's edge, a key: two more unknowns, its centre
  /// along the axis and its length) is one more model beside the rod that crosses the pad;
  /// shorter than this, or than its diameter, it is not plausible (a spot, not an edge, to
  /// taxels of about this pitch: a 2 mm sphere read as a 2.3 mm rod otherwise) [mm].
  bool fit_finite_rods = true;
  double min_rod_length_mm = 4.0;
  /// Also a rectangular flat-faced punch (sensors/flat_punch_pressure.h: a face of two half
  /// sizes, turned by its yaw, loaded most at its edges) among the starts.
  bool fit_punches = true;
  /// Also a round flat-faced punch (the same file: a face of one radius, p ~ 1 / sqrt(1 -
  /// (r/a)^2), its rim capped alike): kFull tries it after the starts; kAmortized checks it on
  /// a hold's mean whose answer is inadequate (ContactReconstructor::CheckRoundPunch,
  /// model_selection.cpp), outside the rotation.
  bool fit_round_punches = true;
  /// Also a box corner pointing into the pad (sensors/cone_pressure.h: x, y, F; its angle the
  /// box's), checked on a hold read as a small sphere (ContactReconstructor::CheckCorner;
  /// kFull: after the starts, when they read one).
  bool fit_corners = true;
  bool fit_shear = true;          ///< estimate the tangential force (three-axis sensors)
  int max_evaluations = 400;      ///< full: LM function evaluations per warm fit
  int explore_evaluations = 150;  ///< full: LM function evaluations per cold start
  /// Amortized: forward-model evaluations per scan (weighted by patch size, see
  /// cells_per_evaluation) for refining the current model and for the candidate (a
  /// sphere/rod LM iteration costs about 4 since the force column is free, a flat's 1). A
  /// fit that runs out continues on the next scan from where it stopped.
  /// 24 / 12 (about 6 and 3 LM iterations, as 30 / 15 were at 5 evaluations an iteration):
  /// with hold averaging (which settles a rod's radius over the hold), the smallest budgets
  /// tried that keep every fidelity case, rig and synthetic, and add no fallback over the
  /// 21 rig replays (20 / 10 added a fit fallback); 60 / 30 before hold averaging, where
  /// 24/12 to 40/20 (at 5 an iteration) each lost a rod (docs/lab-notes/2026-11-27-time-per-scan-rounds.md#s5;
  /// docs/lab-notes/2026-11-28-bridge-fidelity-rounds.md#s7, #s8).
  int warm_scan_evaluations = 24;
  int candidate_scan_evaluations = 12;
  /// Amortized: while the current model explains the scan within settle_rms_sigma, the
  /// candidate gets at most this many per scan (0 = candidate_scan_evaluations): exploring
  /// is then a check, spread thinner over more scans.
  int explained_candidate_evaluations = 6;
  /// Amortized: while the current model explains the scan, a candidate whose one LM
  /// iteration (about 4 of its evaluations at its last cost) exceeds the scan's budget
  /// waits for a scan the model does not explain (false: it takes its iteration anyway).
  /// And no candidate then starts evaluations past the scan's budget plus one cheap
  /// iteration (4 units): one whose patch grew stops where it is, its cost remembered.
  bool defer_costly_candidates = true;
  /// Amortized budgets count an evaluation as max(1, patch cells / this): an evaluation
  /// costs in proportion to its patch, and a rod or sphere grown over the whole pad (a
  /// candidate explaining a flat) costs 5-10 of a 5 mm sphere's (about 400 cells at 0.8 N).
  int cells_per_evaluation = 400;
  /// Amortized: forward-model evaluations over all scans before a candidate that neither
  /// converged nor beat the current model is given up.
  int candidate_evaluations = 150;
  /// Amortized: a fit stops when one Levenberg-Marquardt iteration lowers chi^2 (in the
  /// noise units of what it fits: a scan, or a hold's mean) by less than this; a rejected
  /// step counts as no gain. At a hold the mean changes by one scan in N and the answer is
  /// already there: one iteration (4 evaluations) instead of 30-45 to Eigen's ftol.
  /// 0.3: a third of what moves a parameter by one standard deviation (delta chi^2 = 1), so
  /// the iterations it skips move the answer by less than its noise, and the next scan goes
  /// on from there. Against 0.01: a third fewer evaluations over the rig replays, the same
  /// fidelity at the peak scans, the same force per scan to 0.08 % of peak (p95)
  /// (docs/lab-notes/2026-11-28-bridge-fidelity-rounds.md#s7).
  double min_chi2_gain = 0.3;
  /// A fit's Jacobian by finite differences (one forward-model evaluation per pose and
  /// radius unknown) at its first LM iteration and every jacobian_refresh-th after; the
  /// iterations between update it by Broyden's rank-one secant formula from the step just
  /// taken (no evaluation), the shear columns exact. 1 = finite differences every iteration.
  /// Only the pose columns are updated: the radius (which a light scan barely determines)
  /// keeps its difference column, and with it the free force column, so a sphere's or
  /// rod's iteration costs 2 evaluations instead of 4 (with the radius updated too: 1, but
  /// a light scan of the rig's rod press_12 walked to the 60 mm bound). The Jacobian is of
  /// the prediction, so it carries over to the next scan's fits (Prediction): their first
  /// iteration is an update too. 4: forward-model evaluations over the replays of the
  /// example and rig press_03 / press_14 965 / 1260 / 1487 -> 699 / 792 / 1043 (775 / 836 /
  /// 1114 without carrying it), the same fidelity counts, no fit fallback over the 21 rig
  /// replays (docs/lab-notes/2026-11-27-time-per-scan-rounds.md#s5, "the leader press by force
  /// control, and cheaper fits": Broyden updates of the pose columns).
  int jacobian_refresh = 4;
  /// Hold averaging: while the scans agree with their running mean within noise (a
  /// stationary contact: a hold, a slow press), the fit reads the mean of the last
  /// max_hold_scans scans with the noise of that mean. One scan barely determines a thin
  /// rod's radius (its chi^2 moves by < 1 between R = 1 and 3 mm on the rig); the ~40 scans
  /// of a hold do (by tens). Any change beyond noise starts the mean anew from that scan,
  /// so a moving contact is fitted scan by scan as before. 1 = off.
  int max_hold_scans = 50;
  /// A scan is stationary when the chi^2 per reading of (scan - mean) in single-scan noise
  /// units is below 1 + hold_change_sigma x sqrt(2 / #readings) (hold_change_sigma standard
  /// deviations of that statistic for pure noise).
  double hold_change_sigma = 3.0;
  /// ... and the sum of its normal readings differs from the mean's by less than this many
  /// standard deviations: a press or release moves every taxel's normal reading the same
  /// way, by under one sigma per scan on a slow ramp but several in the sum. Higher than
  /// hold_change_sigma: one noisy scan must not throw a hold's mean away (the benchmark's
  /// peak scan, the scan of largest measured force, is such a scan).
  double hold_force_change_sigma = 4.5;
  /// A weak prior on the radius of spheres and rods, log R ~ N(log radius_prior_mm,
  /// radius_prior_log_sigma^2): one more residual, (log R - log radius_prior_mm) / sigma.
  /// A scan of a light or thin contact hardly tells R, and the fit would wander to the ends
  /// of the plausible range (a 2.5 mm rod read as 0.3 or 60 mm on the ramp, whose leader
  /// presses then fail); a hold's mean outweighs it (chi^2 differences of tens to thousands
  /// against at most a few units here). 0 = no prior.
  double radius_prior_mm = 3.0;
  double radius_prior_log_sigma = 1.0;
  /// Amortized: the warm fit's radius prior is centred on the last answer's radius with this
  /// sigma in log R instead of the weak prior above: an object keeps its size while it
  /// touches, and a scan of a light or thin contact (or the mean of the few scans a slow ramp
  /// holds still) barely tells the radius (a rod's jumped 0.7-4.5 mm between neighbouring
  /// scans on the rig's loading ramps). A long hold's mean, whose chi^2 moves by tens between
  /// radii, still decides: each scan's fit steps from the last answer towards its minimum.
  /// Candidates (model selection) keep the weak prior. 0 = off.
  double radius_track_log_sigma = 0.15;
  /// Amortized, bridge key fe.radius_tracking (posterior: true, the default; steady: false):
  /// while the contact moves (no hold mean), the tracked prior also carries what the scans so
  /// far left open about the radius, sigma^2 = P + radius_track_log_sigma^2, P the last
  /// accepted fit's posterior variance of log R (the inverse of its Gauss-Newton information,
  /// its prior included). A light first touch, which hardly tells R, then does not fix the
  /// radius for the ramp that follows (the rig's 1 mm rod press_13 read 2.1 mm at 0.54 N with
  /// the steady prior). The radius itself then moves with the noise while the scans cannot
  /// tell it (a rod's |d log R| between scans up to 0.9, where steady keeps the warm fit's
  /// steps below 0.3), the delivered SED and the display's commands hardly more.
  /// docs/lab-notes/2026-11-28-bridge-fidelity-rounds.md#s20.
  bool radius_track_posterior = true;
};

}  // namespace sedbridge::contact
