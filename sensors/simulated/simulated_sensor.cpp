#include "sensors/simulated/simulated_sensor.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include "common/config_error.h"
#include "common/yaml_read_archive.h"

namespace sedbridge::sensors {

double PadModel::EffectiveModulus_Pa() const {
  const double nu = poisson_ratio;
  return youngs_modulus_Pa * (1 - nu) / ((1 + nu) * (1 - 2 * nu));
}

namespace {

Eigen::Vector3d Vec3(config::MapReader& r, const std::string& key) {
  if (!r.Has(key)) return Eigen::Vector3d::Zero();
  auto v = r.Required<std::vector<double>>(key);
  if (v.size() != 3) r.Fail(r.Node(key), "'" + key + "' needs 3 numbers");
  return {v[0], v[1], v[2]};
}

// Most blocks the half-space pad solves for at once (one dense Cholesky of this size per
// active-set round; blocks of k x k cells keep a contact under it).
constexpr double kElasticPadMaxUnknowns = 400;

}  // namespace

double PenetrationAlong(const geometry::RigidObject& object, const Eigen::Vector3d& q_m,
                        const Eigen::Vector3d& inward, double t_s) {
  // Sphere tracing inside the solid: a step of |sdf| never crosses the boundary, so the
  // distance marched until the SDF turns non-negative is the depth of the object's surface
  // below q along `inward` (overshoot at most kMinStep for grazing walls).
  constexpr double kMinStep = 1e-5;
  constexpr int kMaxSteps = 200;
  double sdf = object.Evaluate(q_m, t_s).distance_m;
  if (!(sdf < 0)) return 0.0;
  double travelled = 0;
  for (int i = 0; i < kMaxSteps && sdf < 0; ++i) {
    travelled += std::max(-sdf, kMinStep);
    sdf = object.Evaluate(q_m + travelled * inward, t_s).distance_m;
  }
  return travelled;
}

const config::EnumNames<PadMechanics>& NamesOf(PadMechanics) {
  static const config::EnumNames<PadMechanics> names{{PadMechanics::kWinkler, "winkler"},
                                                     {PadMechanics::kKernel, "kernel"},
                                                     {PadMechanics::kHalfSpace, "halfspace"},
                                                     {PadMechanics::kLayer, "layer"}};
  return names;
}

SimulatedSensorConfig LoadSimulatedSensorScene(const std::string& path,
                                               const std::string& profile_override) {
  auto doc = config::LoadYamlFile(path);
  config::MapReader root(doc.root, doc.file);
  SimulatedSensorConfig c;
  config::MapReader s = root.Child("sensor");
  std::string profile = profile_override;
  if (s.Has("profile")) {
    const std::string in_file = s.Required<std::string>("profile");
    if (profile.empty()) {
      // A relative path is tried next to the scene first, then as a shipped name/path.
      const auto beside = std::filesystem::path(path).parent_path() / in_file;
      profile = std::filesystem::exists(beside) && in_file.find('/') != std::string::npos
                    ? beside.string()
                    : ResolveProfilePath(in_file);
    }
  }
  if (profile.empty()) s.Fail("missing 'profile' (or pass --profile)");
  c.profile = LoadNamedSensorProfile(profile);
  c.interface = s.Optional<std::string>("interface", "can0");
  if (c.interface.empty() || c.interface.size() >= kInterfaceNameMax)
    s.Fail(s.Node("interface"), "'interface' must have 1..15 characters");
  c.start_utime = s.Optional<int64_t>("start_utime", c.start_utime);
  config::YamlReadArchive sensor_archive(&s);
  // At most one day: a longer scene is refused, not run until killed.
  sensor_archive.Visit(config::Field("duration_s", &c.duration_s).Unit("s").Within({0, kMaxSimulatedDuration_s, true, false}));
  sensor_archive.Visit(config::Field("pad", &c.pad));
  if (s.Has("pad")) {
    config::MapReader p(s.node()["pad"], s.file());  // keys checked by the archive
    if (c.pad.mechanics != PadMechanics::kWinkler && !c.profile.has_forward_model)
      p.Fail(p.Node("model"), "'model: " + config::NameOf(c.pad.mechanics) +
                                  "' needs a sensor profile with a forward_model (profile '" + c.profile.name +
                                  "' has none)");
    c.pad.scene_from_pad.translation() = Vec3(p, "position_mm") * 1e-3;
    c.pad.scene_from_pad.linear() = geometry::RotationFromRpyDeg(Vec3(p, "rpy_deg"));
  }
  sensor_archive.Visit(config::Field("noise", &c.noise));
  c.frame_spacing_us = s.Optional<int64_t>("frame_spacing_us", 130);
  if (c.frame_spacing_us < 0) s.Fail(s.Node("frame_spacing_us"), "'frame_spacing_us' must be >= 0");
  s.Finish();
  c.objects = geometry::ParseRigidObjects(root, "objects");
  root.Finish();
  return c;
}

SimulatedSensor::SimulatedSensor(SimulatedSensorConfig config)
    : config_(std::move(config)), codec_(config_.profile), rng_(config_.noise.seed) {
  const SensorProfile& p = config_.profile;
  const int n = config_.pad.subsamples;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      sub_offsets_m_.push_back({((i + 0.5) / n - 0.5) * p.taxel_width_mm * 1e-3,
                                ((j + 0.5) / n - 0.5) * p.taxel_height_mm * 1e-3});
  if (config_.pad.mechanics != PadMechanics::kWinkler) {
    if (!p.has_forward_model)
      throw std::invalid_argument("simulated sensor: pad model '" + config::NameOf(config_.pad.mechanics) +
                                  "' needs a profile with a forward_model ('" + p.name + "' has none)");
    kernel_model_ = std::make_shared<const TactileForwardModel>(p, p.forward_model);
  }

  if (config_.pad.smoothing_m > 0) {
    const int t = p.taxel_count;
    smoothing_.assign(static_cast<size_t>(t) * t, 0.0);
    const double s2 = config_.pad.smoothing_m * config_.pad.smoothing_m * 1e6;  // mm^2
    for (int a = 0; a < t; ++a) {
      double sum = 0;
      for (int b = 0; b < t; ++b) {
        const double dx = p.taxels[a].x_mm - p.taxels[b].x_mm, dy = p.taxels[a].y_mm - p.taxels[b].y_mm;
        const double w = std::exp(-0.5 * (dx * dx + dy * dy) / s2);
        smoothing_[a * t + b] = w;
        sum += w;
      }
      for (int b = 0; b < t; ++b) smoothing_[a * t + b] /= sum;
    }
  }
}

double SimulatedSensor::Penetration_m(const Eigen::Vector3d& q_pad_m, double t_s,
                                      const geometry::RigidObject** deepest) const {
  const PadModel& pad = config_.pad;
  const Eigen::Vector3d q = pad.scene_from_pad * q_pad_m;
  const Eigen::Vector3d inward = -pad.scene_from_pad.linear().col(2);  // into the pad
  double depth = 0;
  *deepest = nullptr;
  for (const auto& obj : config_.objects) {
    const double d = PenetrationAlong(obj, q, inward, t_s);
    if (d > depth) depth = d, *deepest = &obj;
  }
  return depth;
}

Eigen::Vector2d SimulatedSensor::FrictionTraction_Pa(const geometry::RigidObject& object, const Eigen::Vector3d& q_pad_m,
                                                     double t_s, double pressure_Pa) const {
  const PadModel& pad = config_.pad;
  if (!(pad.friction_coefficient > 0)) return Eigen::Vector2d::Zero();
  const Eigen::Vector3d q = pad.scene_from_pad * q_pad_m;
  const Eigen::Vector3d v = pad.scene_from_pad.linear().transpose() * object.trajectory.PointVelocity(q, t_s);
  const double speed = std::hypot(v.x(), v.y());
  if (!(speed > 1e-6)) return Eigen::Vector2d::Zero();
  return pad.friction_coefficient * pressure_Pa / speed * Eigen::Vector2d(v.x(), v.y());
}

Eigen::Vector3d SimulatedSensor::WinklerTraction_Pa(const Eigen::Vector3d& q_pad_m, double t_s) const {
  const PadModel& pad = config_.pad;
  const geometry::RigidObject* deepest = nullptr;
  const double depth = Penetration_m(q_pad_m, t_s, &deepest);
  if (!deepest) return Eigen::Vector3d::Zero();
  const double pressure = pad.EffectiveModulus_Pa() / pad.thickness_m * depth;
  const Eigen::Vector2d shear = FrictionTraction_Pa(*deepest, q_pad_m, t_s, pressure);
  return Eigen::Vector3d(shear.x(), shear.y(), pressure);
}

void SimulatedSensor::ElasticPadLoads(double t_s, std::vector<SurfaceLoad>* loads) const {
  const SensorProfile& p = config_.profile;
  const TactileForwardModel& model = *kernel_model_;
  const int nf = model.grid_n();
  const double h_mm = model.cell_size_mm();
  const double half_mm = 0.5 * p.forward_model.pad_size_mm;
  const double cell_m2 = h_mm * h_mm * 1e-6;
  auto on_pad = [&](const Eigen::Vector2d& xy) { return std::abs(xy.x()) <= half_mm && std::abs(xy.y()) <= half_mm; };
  auto depth_at = [&](const Eigen::Vector2d& xy_mm, const geometry::RigidObject** deepest) {
    return Penetration_m(Eigen::Vector3d(xy_mm.x() * 1e-3, xy_mm.y() * 1e-3, 0), t_s, deepest);
  };
  // The cells the objects overlap, then blocks of k x k cells, k as small as keeps the solve
  // within kElasticPadMaxUnknowns (a thin rod on single cells, a flat on 5 x 5 blocks).
  int overlapped = 0;
  std::vector<double> cell_depth_m(static_cast<size_t>(model.cell_count()), 0.0);
  std::vector<const geometry::RigidObject*> cell_deepest(cell_depth_m.size(), nullptr);
  for (int cell = 0; cell < model.cell_count(); ++cell) {
    const Eigen::Vector2d xy = model.CellCentre_mm(cell);
    if (!on_pad(xy)) continue;
    cell_depth_m[static_cast<size_t>(cell)] = depth_at(xy, &cell_deepest[static_cast<size_t>(cell)]);
    if (cell_depth_m[static_cast<size_t>(cell)] > 0) ++overlapped;
  }
  loads->clear();
  if (overlapped == 0) return;
  const int k = std::max(1, static_cast<int>(std::ceil(std::sqrt(double(overlapped) / kElasticPadMaxUnknowns))));
  const int nc = (nf + k - 1) / k;
  auto& solver = pad_contact_[k];
  if (!solver) {
    // kHalfSpace: the forward model's E*, infinitely thick; kLayer: the pad's own elastomer.
    ElasticLayer layer;
    double e_star_Pa = p.forward_model.contact_modulus_kPa * 1e3;
    if (config_.pad.mechanics == PadMechanics::kLayer) {
      const PadModel& pad = config_.pad;
      layer = {pad.thickness_m, pad.poisson_ratio};
      e_star_Pa = pad.youngs_modulus_Pa / (1 - pad.poisson_ratio * pad.poisson_ratio);
    }
    solver = std::make_shared<ElasticPadContact>(k * h_mm * 1e-3, e_star_Pa, layer);
  }
  // Each block's penetration at its centre, and the object there (for the friction); single
  // cells have theirs already.
  std::vector<double> depth_m = k == 1 ? cell_depth_m : std::vector<double>(static_cast<size_t>(nc) * nc, 0.0);
  std::vector<const geometry::RigidObject*> deepest =
      k == 1 ? cell_deepest : std::vector<const geometry::RigidObject*>(depth_m.size(), nullptr);
  std::vector<Eigen::Vector2d> centre_mm(depth_m.size());
  for (int I = 0; I < nc; ++I)
    for (int J = 0; J < nc; ++J) {
      const size_t b = static_cast<size_t>(I) * nc + J;
      centre_mm[b] = model.CellCentre_mm(I * k * nf + J * k) + Eigen::Vector2d::Constant(0.5 * (k - 1) * h_mm);
      if (k > 1 && on_pad(centre_mm[b])) depth_m[b] = depth_at(centre_mm[b], &deepest[b]);
    }
  std::vector<double> pressure_Pa;
  solver->Solve(nc, depth_m, &pressure_Pa);
  for (int cell = 0; cell < model.cell_count(); ++cell) {
    const Eigen::Vector2d xy = model.CellCentre_mm(cell);
    if (!on_pad(xy)) continue;
    const size_t b = static_cast<size_t>((cell / nf) / k) * nc + (cell % nf) / k;
    const double pressure = pressure_Pa[b];
    if (!(pressure > 0) || !deepest[b]) continue;
    const Eigen::Vector2d shear = FrictionTraction_Pa(
        *deepest[b], Eigen::Vector3d(centre_mm[b].x() * 1e-3, centre_mm[b].y() * 1e-3, 0), t_s, pressure);
    SurfaceLoad l;
    l.cell = cell;
    l.normal_N = pressure * cell_m2;
    l.shear_x_N = shear.x() * cell_m2;
    l.shear_y_N = shear.y() * cell_m2;
    loads->push_back(l);
  }
}

void SimulatedSensor::KernelLoads(double t_s, std::vector<SurfaceLoad>* loads) const {
  if (config_.pad.mechanics == PadMechanics::kHalfSpace || config_.pad.mechanics == PadMechanics::kLayer)
    return ElasticPadLoads(t_s, loads);
  const SensorProfile& p = config_.profile;
  const TactileForwardModel& model = *kernel_model_;
  const double cell_m2 = model.cell_size_mm() * model.cell_size_mm() * 1e-6;
  const double half_mm = 0.5 * p.forward_model.pad_size_mm;
  loads->clear();
  for (int cell = 0; cell < model.cell_count(); ++cell) {
    const Eigen::Vector2d xy = model.CellCentre_mm(cell);
    if (std::abs(xy.x()) > half_mm || std::abs(xy.y()) > half_mm) continue;  // no pad there
    const Eigen::Vector3d t_Pa = WinklerTraction_Pa(Eigen::Vector3d(xy.x() * 1e-3, xy.y() * 1e-3, 0), t_s);
    if (!(t_Pa.z() > 0)) continue;
    SurfaceLoad l;
    l.cell = cell;
    l.normal_N = t_Pa.z() * cell_m2;
    l.shear_x_N = t_Pa.x() * cell_m2;
    l.shear_y_N = t_Pa.y() * cell_m2;
    loads->push_back(l);
  }
}

Eigen::Vector3d SimulatedSensor::TotalLoad_N(double t_s) const {
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  if (!kernel_model_) return total;
  std::vector<SurfaceLoad> loads;
  KernelLoads(t_s, &loads);
  for (const auto& l : loads) total += Eigen::Vector3d(l.shear_x_N, l.shear_y_N, l.normal_N);
  return total;
}

TaxelTractions SimulatedSensor::EvaluateKernel(double t_s) const {
  const SensorProfile& p = config_.profile;
  const TactileForwardModel& model = *kernel_model_;
  std::vector<SurfaceLoad> loads;
  KernelLoads(t_s, &loads);
  Eigen::VectorXd r;
  model.Respond(loads, &r);
  const double area_m2 = p.taxel_area_mm2() * 1e-6;
  TaxelTractions out;
  for (int k = 0; k < p.taxel_count; ++k) {
    out.shear_x_Pa.push_back(r[3 * k] / area_m2);
    out.shear_y_Pa.push_back(r[3 * k + 1] / area_m2);
    out.pressure_Pa.push_back(r[3 * k + 2] / area_m2);
  }
  return out;
}

TaxelTractions SimulatedSensor::Evaluate(double t_s) const {
  if (kernel_model_) return EvaluateKernel(t_s);
  const SensorProfile& p = config_.profile;
  const int taxels = p.taxel_count;
  TaxelTractions out;
  out.pressure_Pa.assign(taxels, 0.0);
  out.shear_x_Pa.assign(taxels, 0.0);
  out.shear_y_Pa.assign(taxels, 0.0);
  for (int i = 0; i < taxels; ++i) {
    double p_sum = 0, tx_sum = 0, ty_sum = 0;
    for (const Eigen::Vector2d& o : sub_offsets_m_) {
      const Eigen::Vector3d q_pad(p.taxels[i].x_mm * 1e-3 + o.x(), p.taxels[i].y_mm * 1e-3 + o.y(), 0);
      const Eigen::Vector3d t_Pa = WinklerTraction_Pa(q_pad, t_s);
      p_sum += t_Pa.z();
      tx_sum += t_Pa.x();
      ty_sum += t_Pa.y();
    }
    const double n = static_cast<double>(sub_offsets_m_.size());
    out.pressure_Pa[i] = p_sum / n;
    out.shear_x_Pa[i] = tx_sum / n;
    out.shear_y_Pa[i] = ty_sum / n;
  }
  if (!smoothing_.empty()) {
    auto blur = [&](std::vector<double>& v) {
      std::vector<double> r(taxels, 0.0);
      for (int a = 0; a < taxels; ++a)
        for (int b = 0; b < taxels; ++b) r[a] += smoothing_[a * taxels + b] * v[b];
      v.swap(r);
    };
    blur(out.pressure_Pa);
    blur(out.shear_x_Pa);
    blur(out.shear_y_Pa);
  }
  return out;
}

std::vector<int32_t> SimulatedSensor::ToRawCounts(const TaxelTractions& tr) const {
  const SensorProfile& p = config_.profile;
  const Calibration& cal = p.calibration;
  const double area_m2 = p.taxel_area_mm2() * 1e-6;
  double from_Pa = 1.0;  // profile unit per Pa
  if (cal.unit == CalibrationUnit::kKiloPascal) from_Pa = 1e-3;
  if (cal.unit == CalibrationUnit::kNewton) from_Pa = area_m2;
  std::vector<int32_t> raw(p.channel_count());
  for (int i = 0; i < p.taxel_count; ++i) {
    for (int a = 0; a < p.axes; ++a) {
      double value_Pa = tr.pressure_Pa[i];
      if (p.axes == 3 && a == 0) value_Pa = tr.shear_x_Pa[i];
      if (p.axes == 3 && a == 1) value_Pa = tr.shear_y_Pa[i];
      const double counts =
          cal.offset_counts[a] + value_Pa * from_Pa / (cal.scale_per_count[a] * cal.taxel_gain[i]);
      const double limited = std::clamp(counts, -2e9, 2e9);  // NaN-safe below
      raw[i * p.axes + a] = std::isfinite(limited) ? static_cast<int32_t>(std::lround(limited)) : 0;
    }
  }
  return raw;
}

int64_t SimulatedSensor::scan_count() const {
  return static_cast<int64_t>(std::floor(config_.duration_s * config_.profile.scan_rate_Hz + 1e-9));
}

void SimulatedSensor::ScanFrames(int64_t k, std::vector<Frame>* out) {
  const double t = ScanTime_s(k);
  std::vector<int32_t> raw = ToRawCounts(Evaluate(t));
  const SimulationNoise& noise = config_.noise;
  if (noise.stddev_counts > 0) {
    std::normal_distribution<double> gauss(0.0, noise.stddev_counts);
    for (auto& r : raw) r = static_cast<int32_t>(std::lround(r + gauss(rng_)));
  }
  const int64_t period_us = static_cast<int64_t>(1e6 / config_.profile.scan_rate_Hz);
  const int64_t spacing =
      std::min<int64_t>(config_.frame_spacing_us, period_us / (codec_.frame_count() + 1));
  const int64_t t0 = config_.start_utime + static_cast<int64_t>(std::llround(t * 1e6));
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int slot = 0; slot < codec_.frame_count(); ++slot) {
    Frame f = codec_.EncodeSlot(slot, raw, k, t0 + slot * spacing);
    f.SetInterface(config_.interface);
    if (noise.dropout_probability > 0 && uniform(rng_) < noise.dropout_probability) {
      ++frames_dropped_;
      continue;
    }
    if (noise.bit_error_probability > 0) {
      for (int bit = 0; bit < f.len * 8; ++bit)
        if (uniform(rng_) < noise.bit_error_probability) {
          f.data[bit / 8] ^= static_cast<uint8_t>(1u << (bit % 8));
          ++bits_flipped_;
        }
    }
    out->push_back(f);
  }
}

SimulatedSensorSource::SimulatedSensorSource(SimulatedSensorConfig config)
    : sensor_(std::move(config)) {}

std::optional<Frame> SimulatedSensorSource::Next(int64_t /*timeout_us*/) {
  while (!done_ && next_ >= pending_.size()) {
    if (scan_ >= sensor_.scan_count()) {
      done_ = true;
      break;
    }
    pending_.clear();
    next_ = 0;
    sensor_.ScanFrames(scan_++, &pending_);
  }
  if (done_) return std::nullopt;
  ++stats_.frames;
  return pending_[next_++];
}

std::string SimulatedSensorSource::Describe() const {
  return "simulated " + sensor_.config().profile.name;
}

}  // namespace sedbridge::sensors
