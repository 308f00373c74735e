#include "sensors/simulated/pad_rig_check.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sensors/simulated/primitive_object.h"

namespace sedbridge::sensors {
namespace {

// The object is lowered linearly over one second of scene time, depth = t * travel: 3 mm,
// or its radius (deeper, a small sphere would pass below the pad's surface).
constexpr double kMaxTravel_m = 3e-3;
// A rod that crosses the pad at any yaw and offset.
constexpr double kRodHalfLength_m = 30e-3;
constexpr int kBisections = 40;
constexpr double kForceTolerance = 1e-4;  // relative
// The light-load window: on the ramp at 0.29 of the hold force (fit-sensor's first ramp
// window; its centre in the rig's protocol, PressProtocol::FromRigTime_s for another), where
// a small object's patch is smallest against the layer.
constexpr double kRampWindow_s = 0.5, kRampHalf_s = 0.02;

double Travel_m(const ContactPrimitive& object) {
  return object.shape == ContactShape::kFlat ? kMaxTravel_m : std::min(kMaxTravel_m, object.radius_mm * 1e-3);
}

geometry::RigidObject Lowered(const ContactPrimitive& object) {
  geometry::RigidObject o = RigidObjectOf(object, kRodHalfLength_m);
  const Eigen::Isometry3d first_touch = o.trajectory.Pose(0);
  geometry::PoseKeyframe top, bottom;
  top.position_m = first_touch.translation();
  top.orientation = Eigen::Quaterniond(first_touch.linear());
  bottom = top;
  bottom.t_s = 1;
  bottom.position_m.z() -= Travel_m(object);
  o.trajectory = geometry::Trajectory({top, bottom});
  return o;
}

}  // namespace

PadModel RigFittedLayerPad() {
  PadModel pad;
  pad.mechanics = PadMechanics::kLayer;
  pad.thickness_m = 2.5e-3;
  pad.youngs_modulus_Pa = 230e3;
  pad.poisson_ratio = 0.2;
  return pad;
}

std::vector<PadPressReport> EvaluatePadOnPresses(const std::vector<CalibrationPress>& presses,
                                                 const SensorProfile& profile, const PadModel& pad,
                                                 double noise_counts) {
  if (pad.mechanics == PadMechanics::kWinkler)
    throw std::invalid_argument("the rig check needs a pad model that uses the kernels (kernel, halfspace, layer)");
  if (!profile.has_forward_model || profile.axes != 3)
    throw std::invalid_argument("the rig check needs a three-axis profile with a forward_model");
  const int n = profile.taxel_count;
  Eigen::VectorXd inv_sigma(3 * n);
  for (int k = 0; k < n; ++k)
    for (int a = 0; a < 3; ++a) inv_sigma[3 * k + a] = 1.0 / (noise_counts * NewtonsPerCount(profile, k, a));
  std::vector<PadPressReport> out;
  for (const CalibrationPress& press : presses) {
    if (!press.is_primitive())
      throw std::invalid_argument(press.name + ": the rig check presses primitives, not a " + config::NameOf(press.shape));
    const PressProtocol& protocol = press.protocol;
    const double hold = protocol.HoldMid_s(), half = 0.4 * protocol.hold_s;
    const double ramp_window_s = protocol.FromRigTime_s(kRampWindow_s);
    PadPressReport rep;
    rep.name = press.name;
    SimulatedSensorConfig config;
    config.profile = profile;
    config.pad = pad;
    config.pad.friction_coefficient = 0;  // the rig's tangential force is applied below
    config.pad.scene_from_pad = Eigen::Isometry3d::Identity();
    config.objects = {Lowered(press.object)};
    const SimulatedSensor sensor(config);
    auto force_at = [&](double t) { return sensor.TotalLoad_N(t).z(); };
    // RMS per axis [sigma] of the pad's readings against the window's mean, the object at
    // `object`'s force; false if the pad cannot carry it.
    auto window = [&](const ContactPrimitive& object, double t0_s, double t1_s, double rms[3], double* depth_mm) {
      const double target_N = object.normal_force_N;
      double lo = 0, hi = 1;
      if (!(target_N > 0) || force_at(hi) < target_N) return false;
      for (int i = 0; i < kBisections && hi - lo > 1e-9; ++i) {
        const double mid = 0.5 * (lo + hi);
        const double f = force_at(mid);
        if (std::abs(f - target_N) <= kForceTolerance * target_N) {
          lo = hi = mid;
          break;
        }
        (f < target_N ? lo : hi) = mid;
      }
      const double t = 0.5 * (lo + hi);
      if (depth_mm) *depth_mm = t * Travel_m(object) * 1e3;
      std::vector<SurfaceLoad> loads;
      sensor.PadLoads(t, &loads);
      double total_N = 0;
      for (const SurfaceLoad& l : loads) total_N += l.normal_N;
      for (SurfaceLoad& l : loads) {  // the tangential force over the pressure, scaled to the force
        const double share = l.normal_N / total_N;
        l.normal_N = share * target_N;
        l.shear_x_N = share * object.shear_x_N;
        l.shear_y_N = share * object.shear_y_N;
      }
      Eigen::VectorXd predicted;
      sensor.forward_model()->Respond(loads, &predicted);
      const Eigen::VectorXd r = (predicted - press.MeanReadings(t0_s, t1_s)).cwiseProduct(inv_sigma);
      for (int a = 0; a < 3; ++a) {
        double sum = 0;
        for (int k = a; k < 3 * n; k += 3) sum += r[k] * r[k];
        rms[a] = std::sqrt(sum / n);
      }
      return true;
    };
    rep.reached = window(press.object, hold - half, hold + half, rep.rms_sigma, &rep.depth_mm) &&
                  window(press.ObjectAt(ramp_window_s), ramp_window_s - kRampHalf_s, ramp_window_s + kRampHalf_s,
                         rep.ramp_rms_sigma, nullptr);
    out.push_back(rep);
  }
  return out;
}

}  // namespace sedbridge::sensors
