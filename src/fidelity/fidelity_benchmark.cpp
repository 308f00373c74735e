#include "fidelity/fidelity_benchmark.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "bridge/bridge_config.h"
#include "bridge/contact_fe_step.h"
#include "bridge/reduced_linear_fe_step.h"
#include "bridge/scene_fe_step.h"
#include "bridge/taxel_values.h"
#include "display/display_profile.h"
#include "display/sed_to_command_mapping.h"
#include "model/fingertip_model.h"
#include "scene/fingertip_compliance.h"

namespace sedbridge::fidelity {
namespace {

display::SedField Field(const Eigen::Matrix3Xd& pad_mm, const Eigen::VectorXd& sed) {
  display::SedField f;
  for (Eigen::Index i = 0; i < pad_mm.cols(); ++i) {
    f.x_mm.push_back(pad_mm(0, i));
    f.y_mm.push_back(pad_mm(1, i));
    f.z_mm.push_back(pad_mm(2, i));
    f.sed_Pa.push_back(sed[i]);
  }
  return f;
}

// A field's peak region: its vertices within this fraction of its maximum [-].
constexpr double kPeakRegion = 0.95;

double RelL2(const Eigen::VectorXd& a, const Eigen::VectorXd& ref) {
  const double den = ref.norm();
  return den > 0 ? (a - ref).norm() / den : (a.norm() > 0 ? 1.0 : 0.0);
}

}  // namespace

MethodError CompareMerkelMaps(const Eigen::Matrix3Xd& pad_mm, const Eigen::VectorXd& s, const Eigen::VectorXd& truth) {
  MethodError e;
  Eigen::Index is = 0, it = 0;
  const double ms = s.maxCoeff(&is), mt = truth.maxCoeff(&it);
  e.peak_ratio = mt > 0 ? ms / mt : 0;
  e.rel_l2 = RelL2(s, truth);
  e.peak_offset_mm = (pad_mm.col(is).head<2>() - pad_mm.col(it).head<2>()).norm();
  // Distance from a point to the nearest vertex of a field's peak region.
  auto to_region = [&](const Eigen::VectorXd& field, double max, Eigen::Index from) {
    double d = std::numeric_limits<double>::infinity();
    for (Eigen::Index i = 0; i < field.size(); ++i)
      if (field[i] >= kPeakRegion * max) d = std::min(d, (pad_mm.col(i).head<2>() - pad_mm.col(from).head<2>()).norm());
    return d;
  };
  e.peak_region_offset_mm =
      ms > 0 && mt > 0 ? std::max(to_region(s, ms, it), to_region(truth, mt, is)) : e.peak_offset_mm;
  return e;
}

namespace {

MethodError Compare(const Eigen::Matrix3Xd& pad_mm, const Eigen::VectorXd& s, const Eigen::VectorXd& truth,
                    const display::SedToCommandMapping& mapping) {
  MethodError e = CompareMerkelMaps(pad_mm, s, truth);
  const auto cs = mapping.Map(Field(pad_mm, s)).requested, ct = mapping.Map(Field(pad_mm, truth)).requested;
  e.command_rel_l2 = RelL2(Eigen::Map<const Eigen::VectorXd>(cs.data(), Eigen::Index(cs.size())),
                           Eigen::Map<const Eigen::VectorXd>(ct.data(), Eigen::Index(ct.size())));
  return e;
}

}  // namespace

bool WithinTargets(const MethodError& e, const FidelityTargets& t, bool by_peak_region) {
  const double offset_mm = by_peak_region ? e.peak_region_offset_mm : e.peak_offset_mm;
  return e.peak_ratio >= t.min_peak_ratio && e.peak_ratio <= t.max_peak_ratio && e.rel_l2 <= t.max_rel_l2 &&
         offset_mm <= t.max_peak_offset_mm;
}

std::string ObjectKind(const FidelityRow& row) {
  if (!row.truth_is_primitive) return "other";
  const sensors::ContactPrimitive& t = row.truth_object;
  switch (t.shape) {
    case sensors::ContactShape::kFlat:
      return "flat";
    case sensors::ContactShape::kCylinder:
      return "rod";
    case sensors::ContactShape::kPunch:
    case sensors::ContactShape::kRoundPunch:
      return "punch";
    case sensors::ContactShape::kSphere:
      return std::hypot(t.shear_x_N, t.shear_y_N) > 0.05 * t.normal_force_N ? "stroke" : "sphere";
    case sensors::ContactShape::kCorner:  // a box's, among the other objects
      return "other";
  }
  return "other";
}

namespace {

// The default bridge config with the given cache and face contact.
bridge::BridgeConfig DefaultConfigWith(const std::string& cache_dir, bool face_contact) {
  bridge::BridgeConfig config = bridge::LoadBridgeConfig(bridge::DefaultBridgeConfigPath());
  config.compliance_cache_dir = cache_dir;
  config.face_contact = face_contact;
  return config;
}

}  // namespace

FidelityBenchmark::FidelityBenchmark(const std::string& model_name, const sensors::SensorProfile& profile,
                                     const display::DisplayProfile& display, const std::string& cache_dir,
                                     bool face_contact)
    : FidelityBenchmark(model_name, profile, display, DefaultConfigWith(cache_dir, face_contact)) {}

FidelityBenchmark::FidelityBenchmark(const std::string& model_name, const sensors::SensorProfile& profile,
                                     const display::DisplayProfile& display, const bridge::BridgeConfig& config)
    : profile_(profile),
      reconstruction_(bridge::ReconstructionOptionsOf(config)),
      press_(bridge::ReconstructedPressOptions(config)) {
  model_ = std::make_unique<model::FingertipModel>(model::LoadFingertipModel(model_name));
  leader_ = std::make_unique<scene::FingertipCompliance>(
      *model_, contact::LeaderComplianceOptions(config.compliance_cache_dir, config.face_contact));
  // The pressure-map bridge as the config runs it.
  const bridge::PadRegistration registration(profile.taxels, config.registration);
  map_step_ = std::make_unique<bridge::ReducedLinearFeStep>(bridge::BridgeSceneDescription(model_name, "fast"), profile,
                                                            registration, config.traction);
  conditioner_ = std::make_unique<bridge::ScanConditioner>(profile, registration, config.conditioning);
  mapping_ = std::make_unique<display::SedToCommandMapping>(display);
  // The surface pressure in the sensor's pad frame, pressed where the truth and the
  // reconstruction press (no registration: the benchmark's leader frame is the sensor's).
  surface_ = std::make_unique<sensors::SurfacePressureInversion>(profile, config.surface_pressure);
  Eigen::Matrix2Xd cells(2, surface_->cell_count());
  for (int c = 0; c < surface_->cell_count(); ++c) cells.col(c) = surface_->CellCentre_mm(c);
  // A leader of its own on the same operator: its steps leave the truth's and the
  // reconstruction's leader as it was (the SED's kept columns change the last digits).
  scene::FingertipComplianceOptions own = contact::LeaderComplianceOptions(config.compliance_cache_dir, config.face_contact);
  own.contact.shared_operator = leader_->contact().shared_operator();
  surface_leader_ = std::make_unique<scene::FingertipCompliance>(*model_, own);
  surface_on_leader_ = std::make_unique<contact::SurfacePressureOnLeader>(*surface_leader_, cells, surface_->cell_mm());
  fallback_ = config.fallback;
}

FidelityBenchmark::~FidelityBenchmark() = default;

FidelityRow FidelityBenchmark::Run(const FidelityCase& press, FidelityMaps* maps) {
  FidelityRow row;
  row.name = press.name;
  row.label = press.label;
  row.scans = static_cast<int>(press.scans.size());
  // The scan of peak measured normal force.
  size_t peak = 0;
  double best = -1;
  for (size_t i = 0; i < press.scans.size(); ++i) {
    const Eigen::VectorXd r = sensors::ScanReadings_N(press.scans[i], profile_);
    double z = 0;
    for (Eigen::Index k = 2; k < r.size(); k += 3) z += r[k];
    if (z > best) best = z, peak = i;
  }
  row.truth_is_primitive = press.has_primitive;
  row.truth_object = press.primitive;
  row.truth_object.normal_force_N = press.load_N[peak].z();
  row.truth_object.shear_x_N = press.load_N[peak].x();
  row.truth_object.shear_y_N = press.load_N[peak].y();
  if (press.has_primitive && press.primitive.shape != sensors::ContactShape::kFlat) {
    // Where the object is at the peak (the sliding case moves).
    const Eigen::Vector3d at = press.objects[0].trajectory.Pose(press.t_s[peak]).translation() * 1e3;
    row.truth_object.x_mm = at.x();
    row.truth_object.y_mm = at.y();
  }

  // Reconstruction through the press up to the peak, as the live bridge would run it.
  contact::ContactReconstructor recon(profile_, reconstruction_);
  std::vector<double> us;
  contact::ContactEstimate at_peak;
  for (size_t i = 0; i <= peak; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    const contact::ContactEstimate& e = recon.Reconstruct(press.scans[i]);
    us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
    if (i == peak) at_peak = e;
  }
  std::sort(us.begin(), us.end());
  row.recon_median_us = us[us.size() / 2];
  row.recon_max_us = us.back();
  row.fallbacks = static_cast<int>(recon.counters().fallbacks);
  row.recon_object = at_peak.primitive;
  row.recon_two_contacts = at_peak.two_contacts;
  row.recon_second = at_peak.second;
  row.recon_ok = at_peak.ok && at_peak.contact;
  row.recon_rms_sigma = at_peak.rms_sigma;
  row.recon_inadequate = at_peak.model_inadequate;
  row.recon_inadequate_scans = static_cast<int>(recon.counters().model_inadequate);

  maps->merkel_pad_mm = leader_->merkel_rest_pad_mm();
  // Truth.
  {
    const auto r = leader_->PressToForce(press.ObjectsAt(peak), row.truth_object.normal_force_N, {},
                                         Eigen::Vector2d(row.truth_object.shear_x_N, row.truth_object.shear_y_N));
    row.truth_valid = contact::PressAnswered(r, *leader_);
    row.truth_press = row.truth_valid ? "reached" : scene::ToString(r.status);
    if (!r.reached) row.truth_press += " (" + std::to_string(r.force_N) + " N at " + std::to_string(r.indentation_mm) + " mm)";
    maps->truth = leader_->sed_Pa();
  }
  // Pressure map.
  {
    bridge::TaxelValues values;
    const bridge::ConditioningReport rep = conditioner_->Condition(press.scans[peak], &values);
    const bridge::MerkelSedResult& r = map_step_->Step(values);
    maps->map = rep.usable && r.ok ? *r.sed_Pa : Eigen::VectorXd::Zero(maps->truth.size());
  }
  // The surface pressure (every case: beside the map and the reconstruction).
  {
    const auto t0 = std::chrono::steady_clock::now();
    const sensors::SurfacePressure& p = surface_->Solve(press.scans[peak]);
    row.surface_us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
    row.surface_ok = p.ok && surface_on_leader_->Press(p.cell_force_N, p.shear_N);
    row.surface_force_N = p.normal_force_N;
    row.surface_rms_sigma = p.rms_sigma;
    row.surface_cells = p.active_cells;
    maps->surface = row.surface_ok ? surface_leader_->sed_Pa() : Eigen::VectorXd::Zero(maps->truth.size());
  }
  // Reconstructed contact (a flagged fit answered by the surface pressure where the config asks).
  if (row.recon_ok && fallback_ == bridge::FallbackAnswer::kSurfacePressureAndFlagged && at_peak.model_inadequate) {
    row.recon_press = "flagged: surface pressure";
    row.recon_fallback_surface = true;
    maps->recon = maps->surface;
  } else if (row.recon_ok) {
    leader_->ResetWarmStart();
    const contact::LeaderPress pressed =
        contact::PressReconstructed(*leader_, at_peak, press_, contact::LeaderTangentialLoad_N(at_peak));
    const scene::PressToForceResult& r = pressed.result;
    row.recon_press = contact::PressAnswered(r, *leader_) ? "reached" : scene::ToString(r.status);
    if (pressed.thickened_radius_mm > 0) {
      char why[64];
      std::snprintf(why, sizeof why, " (as R%.2f: thinner slips)", pressed.thickened_radius_mm);
      row.recon_press += why;
    }
    maps->recon = leader_->sed_Pa();
  } else if (fallback_ != bridge::FallbackAnswer::kPressureMap) {
    row.recon_press = "fallback (surface pressure): " + at_peak.problem;
    row.recon_fallback_surface = true;
    maps->recon = maps->surface;
  } else {
    row.recon_press = "fallback: " + at_peak.problem;
    maps->recon = maps->map;
  }
  leader_->ResetWarmStart();
  row.truth_max_sed_Pa = maps->truth.maxCoeff();
  row.map_max_sed_Pa = maps->map.maxCoeff();
  row.recon_max_sed_Pa = maps->recon.maxCoeff();
  row.map_error = Compare(maps->merkel_pad_mm, maps->map, maps->truth, *mapping_);
  row.recon_error = Compare(maps->merkel_pad_mm, maps->recon, maps->truth, *mapping_);
  row.surface_max_sed_Pa = maps->surface.maxCoeff();
  row.surface_error = Compare(maps->merkel_pad_mm, maps->surface, maps->truth, *mapping_);
  return row;
}

std::vector<double> PeakRatioSteps(const std::vector<FidelityBenchmark::ScanScore>& scores) {
  auto ratio = [](const FidelityBenchmark::ScanScore& s) {
    const bool scored = s.truth_valid && s.recon_ok && s.truth_max_sed_Pa > 0 && s.recon_max_sed_Pa > 0;
    return scored ? s.recon_max_sed_Pa / s.truth_max_sed_Pa : std::numeric_limits<double>::quiet_NaN();
  };
  std::vector<double> steps;
  for (size_t k = 1; k < scores.size(); ++k) {
    const double before = ratio(scores[k - 1]), after = ratio(scores[k]);
    if (std::isfinite(before) && std::isfinite(after)) steps.push_back(std::abs(std::log(after / before)));
  }
  return steps;
}

std::vector<FidelityBenchmark::ScanScore> FidelityBenchmark::RunThroughPress(const FidelityCase& press, int stride,
                                                                              double min_force_share) {
  std::vector<ScanScore> scores;
  double peak_N = 0;
  for (const Eigen::Vector3d& load : press.load_N) peak_N = std::max(peak_N, load.z());
  if (!(peak_N > 0)) return scores;
  const Eigen::Matrix3Xd& pad_mm = leader_->merkel_rest_pad_mm();
  contact::ContactReconstructor recon(profile_, reconstruction_);
  int since = stride;
  for (size_t k = 0; k < press.scans.size(); ++k) {
    const contact::ContactEstimate& e = recon.Reconstruct(press.scans[k]);  // every scan, as the bridge runs
    const Eigen::Vector3d& load = press.load_N[k];
    if (load.z() < min_force_share * peak_N || ++since < stride) continue;
    since = 0;
    ScanScore s;
    s.scan = k;
    s.t_s = press.t_s[k];
    s.force_N = load.z();
    leader_->ResetWarmStart();
    const auto truth = leader_->PressToForce(press.ObjectsAt(k), load.z(), {}, Eigen::Vector2d(load.x(), load.y()));
    s.truth_valid = contact::PressAnswered(truth, *leader_);
    const Eigen::VectorXd truth_sed = leader_->sed_Pa();
    s.truth_max_sed_Pa = truth_sed.maxCoeff();
    s.recon_ok = e.ok && e.contact;
    if (s.truth_valid && s.recon_ok) {
      leader_->ResetWarmStart();
      contact::PressReconstructed(*leader_, e, press_, contact::LeaderTangentialLoad_N(e));
      s.recon_max_sed_Pa = leader_->sed_Pa().maxCoeff();
      s.recon_radius_mm = e.primitive.radius_mm;
      s.recon_error = Compare(pad_mm, leader_->sed_Pa(), truth_sed, *mapping_);
    }
    scores.push_back(s);
  }
  leader_->ResetWarmStart();
  return scores;
}

}  // namespace sedbridge::fidelity
