#include "contact/model_selection.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "contact/contact_reconstruction.h"

namespace sedbridge::contact {
namespace {

using sensors::ContactPrimitive;
using sensors::ContactShape;

constexpr double kPi = 3.14159265358979323846;

// One LM iteration of a 1-unit patch (a Jacobian of three pose/radius columns and a trial):
// the overrun a soft budget allows, and the margin of the hard one (FitBudget).
constexpr int kCheapIterationUnits = 4;

}  // namespace

SelectionStarts MakeStarts(const ReconstructionOptions& options, const NormalMoments& moments) {
  const double yaw = moments.principal_yaw_deg;
  SelectionStarts s{{{ContactShape::kSphere, 3.0, 0},
                     {ContactShape::kCylinder, 1.0, yaw},
                     {ContactShape::kFlat, 0, 0},
                     {ContactShape::kSphere, 10.0, 0},
                     {ContactShape::kCylinder, 3.0, yaw},
                     {ContactShape::kCylinder, 1.5, yaw + 90}},
                    6};
  if (options.fit_finite_rods) s.start[s.count++] = {ContactShape::kCylinder, 1.0, yaw, false, true};
  s.pair = s.count;
  if (options.fit_pairs) s.start[s.count++] = {ContactShape::kSphere, 3.0, yaw, true};
  if (options.fit_punches) s.start[s.count++] = {ContactShape::kPunch, 0, yaw};
  return s;
}

Hypothesis StartHypothesis(const ReconstructionOptions& options, const ContactPrimitive& guess,
                           const NormalMoments& moments, const SelectionStart& s) {
  Hypothesis h;
  h.first = guess;
  h.first.shape = s.shape;
  h.first.radius_mm = s.radius_mm;
  h.first.yaw_deg = s.yaw_deg;
  if (s.finite) {
    // Centred on the centroid; a uniform line of length l has variance l^2 / 12 along it
    // (the minor variance stands for the readings' own spread).
    h.first.length_mm = std::clamp(std::sqrt(12 * std::max(moments.principal_var_mm2 - moments.minor_var_mm2, 0.0)),
                                   options.min_rod_length_mm + 1, 2 * kMaxHalfLength_mm);
  }
  if (s.shape == ContactShape::kPunch) {
    // The readings' spread is the face's blurred by the pad: their aspect, not their size,
    // says how much longer than wide.
    const double aspect = std::sqrt(moments.principal_var_mm2 / std::max(moments.minor_var_mm2, 1e-6));
    h.first.radius_mm = 0;
    h.first.half_size_mm[0] = kPunchStartHalfSize_mm * std::clamp(aspect, 1.0, 3.0);
    h.first.half_size_mm[1] = kPunchStartHalfSize_mm;
  }
  if (s.pair) {
    const double yaw = s.yaw_deg * kPi / 180;
    const double d = std::max(std::sqrt(moments.principal_var_mm2), 0.5 * options.min_pair_separation_mm);
    h.pair = true;
    h.first.yaw_deg = 0;
    h.first.normal_force_N = 0.5 * guess.normal_force_N;
    h.second = h.first;
    h.first.x_mm = moments.mx - d * std::cos(yaw);
    h.first.y_mm = moments.my - d * std::sin(yaw);
    h.second.x_mm = moments.mx + d * std::cos(yaw);
    h.second.y_mm = moments.my + d * std::sin(yaw);
    h.second.shear_x_N = h.second.shear_y_N = 0;
  }
  return h;
}

void ContactReconstructor::Tally(const Fit& fit) {
  estimate_.evaluations += fit.evaluations;
  estimate_.evaluation_cost += fit.budget_used;
}

Fit ContactReconstructor::FitStart(const SelectionStart& start, const Selection& s) {
  const Fit fit = FitModel(Problem(), StartHypothesis(options_, s.guess, s.moments, start), options_.explore_evaluations);
  Tally(fit);
  return fit;
}

double ContactReconstructor::Penalized(const Fit& f, bool warm, const Selection& s) const {
  double p = f.Penalized();
  if (s.track_candidates && !warm && !f.model.pair && f.model.first.shape == last_.first.shape &&
      sensors::HasFittedRadius(f.model.first.shape)) {
    const double log_r = std::log(f.model.first.radius_mm);
    const double tracked = (log_r - track_.log_radius) / track_.log_sigma;
    const double weak = options_.radius_prior_log_sigma > 0
                            ? (log_r - std::log(options_.radius_prior_mm)) / options_.radius_prior_log_sigma
                            : 0.0;
    p += tracked * tracked - weak * weak;
  }
  return p;
}

bool ContactReconstructor::Better(const Fit& a, const Fit& b, const Selection& s) const {
  if (!Plausible(a.model) || !std::isfinite(a.chi2)) return false;
  if (!std::isfinite(b.chi2)) return true;
  double pa = Penalized(a, false, s), pb = Penalized(b, s.warm_won, s);
  const auto own_error = [](const Fit& f) {
    return !f.model.pair && (sensors::IsPunch(f.model.first.shape) || f.model.first.shape == ContactShape::kCorner);
  };
  if (own_error(a) != own_error(b)) {
    // A punch (either) against another shape: the chi^2 with the forward model's own error in the
    // noise (variance sigma^2 (1 / N + model_error_sigma^2) per channel of an N-scan hold
    // mean), so that the punch's two more unknowns win by what the data say beyond the
    // model's error, not by absorbing that error. Without it, on the synthetic sets (pressed
    // on the simulated pad, not through the kernels) a punch read spheres of 2-9 mm by
    // 0.01-0.02 sigma of RMS (sphere_r2_3_-2: 0.268 -> 0.257) and their SED 1.3-1.8 too high.
    // A corner against a small sphere alike: its one unknown fewer wins unless the data say
    // more than the model's error (the synthetic box_corner's hold: the sphere lower by 8-10
    // in chi^2, 0.5 after the model's error).
    const double n = std::max(1, estimate_.averaged_scans);
    const double kept = 1 - (1 / n) / (1 / n + options_.model_error_sigma * options_.model_error_sigma);
    pa -= kept * a.chi2;
    pb -= kept * b.chi2;
  }
  return pa < pb;
}

void ContactReconstructor::WarmFit(Selection& s) {
  const bool amortized = options_.selection == ModelSelection::kAmortized;
  // A scan of a moving load (no hold mean, or a short one) whose contact keeps its shape,
  // only its force: the force step explains it as well as the last fit explained its scan,
  // and the shape's refinement waits for a scan that needs it (or the hold's mean).
  bool quick = false;
  const bool saturated = std::find(saturated_.begin(), saturated_.end(), 1) != saturated_.end();
  if (amortized && options_.force_step_first && have_last_chi2_ &&
      estimate_.averaged_scans <= options_.force_step_max_averaged_scans && !last_.pair &&
      sensors::HasFittedRadius(last_.first.shape) && options_.fit_shear &&
      !saturated) {
    const Fit step = FitModel(Problem(), last_, 0, 0, FitMode::kForceStep, &last_prediction_);
    Tally(step);
    const double tolerance = 3 * std::sqrt(2 / s.dof);
    if (Plausible(step.model) && step.chi2 / s.dof <= last_chi2_per_dof_ + tolerance) {
      s.best = step;
      quick = true;
      ++counters_.force_steps;
    }
  }
  if (!quick) {
    const double tracked = amortized ? track_.log_radius : std::numeric_limits<double>::quiet_NaN();
    s.best = FitModel(Problem(), last_, 0, amortized ? options_.warm_scan_evaluations : 0, FitMode::kLevenbergMarquardt,
                      &last_prediction_, tracked, track_.log_sigma);
    Tally(s.best);
  }
  s.warm_won = Plausible(s.best.model);
  if (!s.warm_won) s.best = Fit{};
}

void ContactReconstructor::SelectFull(Selection& s) {
  // Every start, now.
  for (int i = 0; i < s.starts.count; ++i) {
    const Fit fit = FitStart(s.starts.start[i], s);
    if (Better(fit, s.best, s)) s.best = fit, s.warm_won = false;
  }
  if (options_.fit_round_punches) {
    const Fit fit = FitStart(kRoundPunchStart, s);
    if (Better(fit, s.best, s)) s.best = fit, s.warm_won = false;
  }
  if (options_.fit_corners && ReadAsSmallSphere(s.best)) {
    const Fit fit = FitModel(Problem(), CornerStart(s.best.model.first), options_.explore_evaluations);
    Tally(fit);
    if (Better(fit, s.best, s)) s.best = fit, s.warm_won = false;
  }
}

bool ReadAsSmallSphere(const Fit& fit) {
  return std::isfinite(fit.chi2) && !fit.model.pair && fit.model.first.shape == ContactShape::kSphere &&
         fit.model.first.radius_mm < kCornerSphereRadius_mm;
}

Hypothesis CornerStart(const ContactPrimitive& sphere) {
  Hypothesis h;
  h.first = sphere;
  h.first.shape = ContactShape::kCorner;
  h.first.radius_mm = 0;
  h.first.yaw_deg = 0;
  return h;
}

void ContactReconstructor::CheckCorner(Selection& s) {
  // The box corner outside the rotation, as the round punch (CheckRoundPunch): once a
  // contact episode, on a hold's mean of at least kCornerHoldScans scans read as a sphere
  // smaller than kCornerSphereRadius_mm, refined within the candidate budget per scan over
  // the scans that follow until it converges or spends candidate_evaluations; it replaces
  // the sphere when Better (AIC with the model's error: the corner has one unknown fewer,
  // its angle being the box's). A sharp corner's patch is a sub-taxel point load that a small
  // sphere mimics within noise (the synthetic box_corner: a 0.77 mm sphere at 0.25 sigma),
  // but on the leader that sphere concentrates the SED 1.8 times the corner's. A real sphere
  // that small is read as a corner too: the pad cannot tell them apart. Only on such answers,
  // so that every other hold (the rig's and synthetic spheres: 1.99 mm and larger) is read
  // as before and pays nothing.
  if (!options_.fit_corners || options_.selection != ModelSelection::kAmortized || corner_.done) return;
  if (!corner_.started) {
    if (estimate_.averaged_scans < kCornerHoldScans || !ReadAsSmallSphere(s.best)) return;
    corner_.Start(CornerStart(s.best.model.first));
  }
  const std::optional<Fit> refined = RefineSideCandidate(corner_);
  if (!refined) return;
  const Fit& fit = *refined;
  const bool won = ReadAsSmallSphere(s.best) && Better(fit, s.best, s);
  if (won) s.best = fit, s.warm_won = false;
  if (won || fit.converged || corner_.spent >= options_.candidate_evaluations || !Plausible(fit.model) ||
      !std::isfinite(fit.chi2))
    corner_.done = true;
}

std::optional<Fit> ContactReconstructor::RefineSideCandidate(SideCandidate& side) {
  Fit fit = FitModel(Problem(), side.model, options_.explore_evaluations, FitBudget(options_.candidate_scan_evaluations),
                     FitMode::kLevenbergMarquardt, &side.prediction);
  Tally(fit);
  side.spent += fit.budget_used;
  if (fit.stopped && !std::isfinite(fit.chi2)) return std::nullopt;
  side.model = fit.model;
  side.prediction = fit.prediction;
  return fit;
}

void ContactReconstructor::CheckRoundPunch(Selection& s) {
  // The round punch outside the rotation: once a contact episode, on a hold's mean of at
  // least kRoundPunchHoldScans scans whose answer is inadequate (FlagInadequate's test: no
  // model of the rotation explains it within noise), refined within the candidate budget per
  // scan over the scans that follow (its iterate kept) until it converges, spends
  // candidate_evaluations or leaves the plausible domain; it replaces the answer, while that
  // is still inadequate, when it is Better by kRoundPunchMarginChi2. A hold's mean is what
  // tells a round face from a dome (on single scans a 2.5 mm round punch is a 15 mm sphere
  // within noise; on its hold's mean that sphere is flagged). Outside the rotation, so that
  // the rotation's order and every adequate answer stay as they were: with the round punch as
  // a start of the rotation, or checked on adequate answers too, the rig's press_21 (a 3 x 3
  // mm punch, a 10 mm sphere within noise, its SED within the targets) was read as a 1.9 mm
  // round punch, peak ratio 0.97 -> 0.67.
  if (!options_.fit_round_punches || options_.selection != ModelSelection::kAmortized || round_punch_.done) return;
  const bool adequate = std::isfinite(s.best.chi2) && s.best.chi2 <= AdequateRms2(s.dof) * s.dof;
  if (!round_punch_.started) {
    if (estimate_.averaged_scans < kRoundPunchHoldScans || adequate) return;
    if (std::isfinite(s.best.chi2) && !s.best.model.pair && sensors::IsPunch(s.best.model.first.shape)) return;
    round_punch_.Start(StartHypothesis(options_, s.guess, s.moments, kRoundPunchStart));
  }
  const std::optional<Fit> refined = RefineSideCandidate(round_punch_);
  if (!refined) return;
  const Fit& fit = *refined;
  // Against the answer the rotation settled on, by strong evidence: its data chi^2 lower by
  // kRoundPunchMarginChi2 too (a small sphere and a small round face are alike through the
  // pad: a 2.5 mm sphere's hold was read as a 1.3 mm round punch at 2.9 less).
  const bool won = !adequate && Better(fit, s.best, s) && !(fit.chi2 > s.best.chi2 - kRoundPunchMarginChi2);
  if (won) s.best = fit, s.warm_won = false;
  if (won || fit.converged || round_punch_.spent >= options_.candidate_evaluations || !Plausible(fit.model) ||
      !std::isfinite(fit.chi2))
    round_punch_.done = true;
}

void ContactReconstructor::SelectAmortized(Selection& s) {
  // One candidate at a time, rotating through the starts, refined within a budget per
  // scan and continued by the next scan; it replaces the current model as soon as it
  // explains the scan better, and is given up when it converged or spent its share.
  // Without a current model (first touch, or the warm fit left the plausible domain)
  // the candidates get the warm budget too, and the next start is tried while budget
  // is left and nothing explains the scan.
  int budget = options_.candidate_scan_evaluations + (s.warm_won ? 0 : options_.warm_scan_evaluations);
  const bool explained = s.warm_won && options_.explained_candidate_evaluations > 0 &&
                         std::sqrt(s.best.chi2 / s.dof) <= options_.settle_rms_sigma;
  if (explained) budget = std::min(budget, options_.explained_candidate_evaluations);
  CheckPair(s);
  AdvanceCandidates(s, budget, explained);
  FlatWhenNothing(s);
}

void ContactReconstructor::CheckPair(Selection& s) {
  // Two contacts are what no single shape explains: when the current model stops
  // explaining the scan, the pair gets a quick check (once an episode, its own candidate
  // budget, outside the rotation), so a two-point touch is found as its load grows
  // instead of after every single shape's turn (12 fallback scans on the synthetic
  // two_spheres). Taking the rotation's slot instead cost press_02 and press_08 a fallback
  // scan each on the first touch, where the next single shape explained the scan.
  if (options_.fit_pairs && !pair_checked_ && s.warm_won &&
      !(s.best.chi2 <= options_.max_rms_sigma * options_.max_rms_sigma * s.dof)) {
    pair_checked_ = true;
    const Fit fit = FitModel(Problem(), StartHypothesis(options_, s.guess, s.moments, s.starts.start[s.starts.pair]),
                             options_.explore_evaluations, options_.candidate_scan_evaluations);
    Tally(fit);
    if (Better(fit, s.best, s)) s.best = fit, s.warm_won = false;
  }
}

void ContactReconstructor::AdvanceCandidates(Selection& s, int budget, bool explained) {
  for (int tried = 0; budget > 0 && tried < s.starts.count; ++tried) {
    if (!have_candidate_) {
      const int pick = next_start_ % s.starts.count;
      next_start_ = (pick + 1) % s.starts.count;
      if (sensors::IsPunch(s.starts.start[pick].shape) && lone_taxel_ >= 0 && explained) {
        // No punch while a lone misfit is left out and the model explains the rest: with a
        // taxel under the contact gone, a small face explains a dome as well (rig press_04,
        // a 5 mm sphere with taxel 5 dead: read as a 2.3 x 2.5 mm punch at 0.18 sigma).
        ++explored_;
        continue;
      }
      candidate_ = StartHypothesis(options_, s.guess, s.moments, s.starts.start[pick]);
      const bool after_punch = punch_round_ && have_last_ && !last_.pair && last_.first.shape == ContactShape::kPunch;
      if (after_punch && s.starts.start[pick].finite) {
        // A rod that ends on the pad, against the punch: along the punch's longer side, as
        // long (the moments' start goes off the plausible domain on a short thick rod, whose
        // readings spread as much across it as along).
        const ContactPrimitive& punch = last_.first;
        const bool along_first = punch.half_size_mm[0] >= punch.half_size_mm[1];
        candidate_.first.x_mm = punch.x_mm;
        candidate_.first.y_mm = punch.y_mm;
        candidate_.first.yaw_deg = punch.yaw_deg + (along_first ? 0 : 90);
        candidate_.first.length_mm = 2 * std::max(punch.half_size_mm[0], punch.half_size_mm[1]);
      }
      candidate_prediction_ = Prediction{};
      candidate_spent_ = 0;
      candidate_cost_ = 0;
      have_candidate_ = true;
    }
    // While the current model explains the scans, a candidate whose one LM iteration
    // (a Jacobian and a trial: about 4 evaluations of its patch) costs more than the
    // scan's check waits for a scan the model does not explain: such a candidate (a rod
    // grown over the pad to explain a sphere's patch) took 20-26 budget units a scan
    // against a budget of 6, 0.5-1 ms of reconstruction (rig press_10).
    const bool defer = options_.defer_costly_candidates && explained;
    if (defer && 4 * candidate_cost_ > budget) {
      if (!punch_round_) break;
      // The round against a new punch gives such a candidate up instead (it would wait
      // for a scan the punch does not explain, and the round with it).
      have_candidate_ = false;
      ++explored_;
      continue;
    }
    // Nor does its fit start evaluations past the budget and one cheap iteration: a
    // candidate whose patch grows since its last cost was measured (a rod over the pad:
    // 23-31 units in one iteration on rig press_09) stops where it is.
    FitBudget fit_budget(budget);
    if (defer) fit_budget.hard_units = budget + kCheapIterationUnits;
    const Fit fit = FitModel(Problem(), candidate_, options_.explore_evaluations, fit_budget,
                             FitMode::kLevenbergMarquardt, &candidate_prediction_);
    Tally(fit);
    budget -= fit.budget_used;
    candidate_spent_ += fit.budget_used;
    if (fit.stopped) candidate_cost_ = fit.refused_units;  // what its next iteration asks for
    else candidate_cost_ = fit.evaluations > 0 ? double(fit.budget_used) / fit.evaluations : 0.0;
    if (fit.stopped && !std::isfinite(fit.chi2)) break;  // nothing evaluated: it waits as it was
    candidate_ = fit.model;
    candidate_prediction_ = fit.prediction;
    // A candidate whose radius runs out of the plausible range is the wrong shape (a rod
    // or sphere growing without bound to explain a flat), and its huge patches are the
    // most expensive evaluations: given up.
    bool done = fit.converged || candidate_spent_ >= options_.candidate_evaluations || !Plausible(fit.model) ||
                !std::isfinite(fit.chi2) || fit.at_radius_bound;
    bool new_punch = false;
    if (Better(fit, s.best, s)) {
      new_punch = !fit.model.pair && sensors::IsPunch(fit.model.first.shape) &&
                  !(have_last_ && !last_.pair && sensors::IsPunch(last_.first.shape));
      s.best = fit, s.warm_won = false, done = true;
    }
    if (done) {
      have_candidate_ = false;
      ++explored_;
    }
    // A punch that replaces another shape: every start gets another round against it before
    // the selection settles. The punch has the most unknowns of the single shapes and,
    // early on a ramp, mimics a short rod or a blunt sphere well enough to win against
    // their candidates tried before the evidence was in (rig press_28, a 6 mm rod that ends
    // on the pad: read as a 6 x 2 mm punch at 0.52 sigma where the rod explains its hold
    // at 0.13).
    if (new_punch) explored_ = 0, punch_round_ = true;
    // The scan is explained: the rest waits for the next.
    if (std::isfinite(s.best.chi2) && s.best.chi2 <= options_.max_rms_sigma * options_.max_rms_sigma * s.dof) break;
  }
}

void ContactReconstructor::FlatWhenNothing(Selection& s) {
  // Still nothing: the flat, whose evaluations are precomputed unit responses (about a
  // microsecond each), so that a scan between two models is answered, not dropped.
  if (std::isfinite(s.best.chi2)) return;
  Hypothesis flat_start;
  flat_start.first = s.guess;
  flat_start.first.shape = ContactShape::kFlat;
  const Fit flat = FitModel(Problem(), flat_start);
  Tally(flat);
  if (Better(flat, s.best, s)) s.best = flat;
}

}  // namespace sedbridge::contact
