#include "render/pin_display_on_leader.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>

#include "common/geometry/signed_distance_field.h"

namespace sedbridge::render {

namespace {

constexpr double kMm = 1e-3;
// The pin's body above its tip [m]: longer than any travel plus the preload, so the skin
// only ever meets its tip and sides.
constexpr double kPinHalfLength_m = 10e-3;
// Longest rise of a pin between two contact solves [mm]: the contact's SDF is evaluated at
// the displaced nodes, so a long jump lets nodes tunnel past a pin, and each solve starts
// from the last one's contact set (longer jumps left solves unconverged on model B).
constexpr double kLongestRise_mm = 0.1;

// A rounded pin: its tip's spherical cap (radius R, centre at the origin) on a shaft of
// radius <= R running from the centre along +z (toward the display's body). Without the
// shaft a pin raised past its tip radius would leave the skin behind it untouched.
class RoundedPinSdf final : public geometry::SignedDistanceField {
 public:
  RoundedPinSdf(double tip_radius_m, double shaft_radius_m, double length_m)
      : tip_(tip_radius_m), shaft_radius_m_(shaft_radius_m), length_m_(length_m) {}
  geometry::SdfSample Evaluate(const Eigen::Vector3d& p_m) const override {
    const geometry::SdfSample cap = tip_.Evaluate(p_m);
    if (p_m.z() <= 0) return cap;
    // The shaft: a cylinder of the shaft radius over z in [0, length].
    const Eigen::Vector2d radial(p_m.x(), p_m.y());
    const double dr = radial.norm() - shaft_radius_m_, dz = p_m.z() - length_m_;
    geometry::SdfSample shaft;
    if (dr > 0 && dz > 0) {
      shaft.distance_m = std::hypot(dr, dz);
      const Eigen::Vector2d n = radial.norm() > 0 ? Eigen::Vector2d(radial.normalized()) : Eigen::Vector2d::UnitX();
      shaft.normal = Eigen::Vector3d(dr * n.x(), dr * n.y(), dz).normalized();
    } else if (dr > dz) {
      shaft.distance_m = dr;
      const Eigen::Vector2d n = radial.norm() > 0 ? Eigen::Vector2d(radial.normalized()) : Eigen::Vector2d::UnitX();
      shaft.normal = Eigen::Vector3d(n.x(), n.y(), 0);
    } else {
      shaft.distance_m = dz;
      shaft.normal = Eigen::Vector3d::UnitZ();
    }
    return shaft.distance_m < cap.distance_m ? shaft : cap;
  }
  std::string Describe() const override { return "rounded pin"; }
  bool lipschitz() const override { return true; }

 private:
  geometry::SphereSdf tip_;
  double shaft_radius_m_, length_m_;
};

// Median distance from each contact sample under the display to its nearest neighbour
// [mm]: what the leader's FE resolves there.
double SampleSpacing_mm(const scene::FingertipCompliance& leader, const display::DisplayDevice& device) {
  const Eigen::Matrix3Xd& rest = leader.contact().sample_rest_positions_m();
  std::vector<Eigen::Vector3d> under;
  for (Eigen::Index j = 0; j < rest.cols(); ++j) {
    const Eigen::Vector3d p = leader.model().pad_frame.ToPad(rest.col(j)) * 1e3;
    if (std::abs(p.x() - device.surface_center_mm[0]) <= device.surface_half_size_mm[0] &&
        std::abs(p.y() - device.surface_center_mm[1]) <= device.surface_half_size_mm[1] && p.z() > -3.0)
      under.push_back(p);
  }
  std::vector<double> nearest;
  for (size_t a = 0; a < under.size(); ++a) {
    double d = std::numeric_limits<double>::infinity();
    for (size_t b = 0; b < under.size(); ++b)
      if (a != b) d = std::min(d, (under[a] - under[b]).norm());
    nearest.push_back(d);
  }
  if (nearest.empty()) return 0;
  std::nth_element(nearest.begin(), nearest.begin() + long(nearest.size() / 2), nearest.end());
  return nearest[nearest.size() / 2];
}

geometry::RigidObject Plate(double depth_mm) {
  // PlaneSdf is the half-space z < 0 of its frame: turned over, its solid is z > -depth.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(0, 0, -depth_mm * kMm);
  return {"display plate", std::make_shared<geometry::PlaneSdf>(), geometry::Trajectory(pose)};
}

}  // namespace

PinDisplayOnLeader::PinDisplayOnLeader(scene::FingertipCompliance& leader, const display::DisplayDevice& device)
    : leader_(leader), device_(device) {
  if (device.kind != display::DisplayKind::kPin || device.footprints.empty())
    throw std::invalid_argument("pin display on the leader: needs a pin display's device model");
  preload_force_N_ = PreloadForce_N(device);
  // A pin narrower than the skin's contact samples passes between them (a 1 mm pin on
  // model B pressed the same 267 Pa at every height): pressed as a pin that wide.
  sample_spacing_mm_ = SampleSpacing_mm(leader_, device);
  pressed_radius_mm_ = std::max(device.pin_radius_mm, sample_spacing_mm_);
  pressed_tip_radius_mm_ = std::max(device.tip_radius_mm, pressed_radius_mm_);
  leader_.ResetWarmStart();
  const scene::PressToForceResult r = leader_.PressToForce({Plate(0.0)}, preload_force_N_);
  if (!r.reached)
    throw std::runtime_error(std::string("pin display on the leader: the preload press failed: ") +
                             scene::ToString(r.status) + " " + r.message);
  preload_depth_mm_ = r.indentation_mm;
}

std::vector<geometry::RigidObject> PinDisplayOnLeader::Objects(const Eigen::VectorXd& heights_mm) const {
  std::vector<geometry::RigidObject> objects{Plate(preload_depth_mm_)};
  const double radius_m = pressed_radius_mm_ * kMm;
  for (size_t i = 0; i < device_.footprints.size(); ++i) {
    const double h = heights_mm[Eigen::Index(i)];
    if (!(h > 0)) continue;  // a pin at rest is under the plate's surface
    const display::ActuatorFootprint& f = device_.footprints[i];
    const double tip_z_m = -(preload_depth_mm_ + h) * kMm;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    std::shared_ptr<geometry::SignedDistanceField> shape;
    if (device_.tip == display::PinTip::kRounded) {
      // The tip's spherical cap, its centre R above the tip, on the shaft.
      const double R = pressed_tip_radius_mm_ * kMm;
      pose.translation() = Eigen::Vector3d(f.x_mm * kMm, f.y_mm * kMm, tip_z_m + R);
      shape = std::make_shared<RoundedPinSdf>(R, std::min(radius_m, R), 2 * kPinHalfLength_m);
    } else {
      // A flat-ended cylinder along pad z (CylinderSdf runs along its frame's x).
      pose.linear() = Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
      pose.translation() = Eigen::Vector3d(f.x_mm * kMm, f.y_mm * kMm, tip_z_m + kPinHalfLength_m);
      shape = std::make_shared<geometry::CylinderSdf>(radius_m, kPinHalfLength_m);
    }
    objects.push_back({"pin " + std::to_string(i), shape, geometry::Trajectory(pose)});
  }
  return objects;
}

bool PinDisplayOnLeader::Press(const Eigen::VectorXd& heights_mm, Eigen::VectorXd& sed_Pa) {
  error_.clear();
  if (heights_mm.size() != num_actuators() || !heights_mm.allFinite() || (heights_mm.array() < 0).any()) {
    error_ = "one finite height >= 0 per pin";
    return false;
  }
  leader_.ResetWarmStart();
  if (!MoveTo(Eigen::VectorXd::Zero(num_actuators()), heights_mm)) return false;
  sed_Pa = leader_.sed_Pa();
  return true;
}

double PinDisplayOnLeader::default_reference_command() const {
  return std::min(0.2, 0.2 * device_.travel_mm);
}

bool PinDisplayOnLeader::MoveTo(const Eigen::VectorXd& from_mm, const Eigen::VectorXd& to_mm) {
  const double distance = (to_mm - from_mm).cwiseAbs().maxCoeff();
  const double full_step = 1.0 / std::max(1, int(std::ceil(distance / kLongestRise_mm))), least_step = full_step / 32;
  // Fractions of the way; a step whose solve fails is retried from the last converged
  // state at half the length (a contact set that cycles at one configuration often
  // settles from a nearer start).
  double done = 0, step = full_step;
  int last_iterations = 0;
  while (done < 1) {
    const double next = std::min(1.0, done + step);
    const fem::ComplianceContact::WarmStart warm = leader_.contact().SaveWarmStart();
    const fem::ComplianceStepResult& r = leader_.Step(Objects(from_mm + (to_mm - from_mm) * next));
    if (r.ok && r.converged) {
      done = next;
      step = std::min(full_step, 2 * step);
      continue;
    }
    last_iterations = r.iterations;
    if (!r.ok || step <= least_step) {
      error_ = "contact solve failed " + std::to_string(int(std::round(100 * next))) + " % of the way: " +
               (r.error.empty() ? "not converged in " + std::to_string(last_iterations) + " iterations" : r.error);
      return false;
    }
    leader_.contact().RestoreWarmStart(warm);
    step /= 2;
  }
  return true;
}

double PinDisplayOnLeader::RaiseAlone(int pin, double from_mm, double height_mm) {
  Eigen::VectorXd from = Eigen::VectorXd::Zero(num_actuators()), to = from;
  from[pin] = from_mm, to[pin] = height_mm;
  if (!MoveTo(from, to)) return -1;
  double force_N = 0;
  for (const fem::ActiveContact& c : leader_.contact().last().contacts)
    if (c.object == 1) force_N += c.normal_force_N;  // object 0 is the plate, 1 the raised pin
  return height_mm > 0 ? force_N : 0.0;
}

double PinDisplayOnLeader::Gap(int pin, double max_mm) {
  // Searched in steps of a fifth of the pin radius: the contact of a rising pin's tip is
  // near linear once it touches, so two touching heights locate the first touch.
  const double step = std::min(0.1, 0.2 * device_.pin_radius_mm);
  double below = 0, h = 0, first = -1, first_force = 0;
  while (h < max_mm) {
    const double next = std::min(max_mm, h + step);
    const double force = RaiseAlone(pin, h, next);
    if (force < 0) return -1;
    h = next;
    if (force <= 0) {
      below = h;
      continue;
    }
    if (first < 0) {
      first = h, first_force = force;
      continue;
    }
    const double touch = first - first_force * (h - first) / std::max(force - first_force, 1e-300);
    return std::clamp(touch, below, first);
  }
  return first < 0 ? max_mm : below;
}

ElementStrainInfluence PinDisplayOnLeader::Influence(double reference_height_mm) {
  if (!(reference_height_mm > 0)) throw std::invalid_argument("pin display influence: reference height > 0");
  const int n = num_actuators();
  Eigen::VectorXd sed;
  if (!Press(Eigen::VectorXd::Zero(n), sed)) throw std::runtime_error("pin display influence: " + error_);
  ElementStrainInfluence in;
  in.preload_strain = StrainsOfLastStep(leader_);
  const Eigen::Index rows = in.preload_strain.size();
  for (double f : {0.25, 0.5, 1.0, 2.0, 4.0}) in.knot_command.push_back(f * reference_height_mm);
  in.strain_at_knot.assign(in.knot_command.size(), Eigen::MatrixXd::Zero(rows, n));
  in.command_offset.assign(size_t(n), 0.0);
  gaps_mm_.setZero(n);
  failed_knots_ = 0;
  for (int i = 0; i < n; ++i) {
    const std::string which = "pin display influence: pin " + std::to_string(i) + ": ";
    leader_.ResetWarmStart();
    if (!leader_.Step(Objects(Eigen::VectorXd::Zero(n))).converged) throw std::runtime_error(which + "the preload solve failed");
    const double gap = Gap(i, device_.travel_mm);
    if (gap < 0) throw std::runtime_error(which + "a contact solve failed while looking for the gap");
    gaps_mm_[i] = in.command_offset[size_t(i)] = gap;
    double h = gap + 0.5 * std::min(0.1, 0.2 * device_.pin_radius_mm);  // where Gap left the pin, near enough
    for (size_t k = 0; k < in.knot_command.size() && gap < device_.travel_mm; ++k) {
      const double next = gap + in.knot_command[k];
      if (RaiseAlone(i, h, next) < 0) {
        // Past what the contact solve holds (a wide pin deep at the pad's rim): the response
        // stays at the last knot it held, so the renderer gains nothing by going higher.
        ++failed_knots_;
        for (size_t rest = k; rest < in.knot_command.size(); ++rest)
          in.strain_at_knot[rest].col(i) = k ? Eigen::VectorXd(in.strain_at_knot[k - 1].col(i)) : Eigen::VectorXd::Zero(rows);
        break;
      }
      h = next;
      in.strain_at_knot[k].col(i) = StrainsOfLastStep(leader_) - in.preload_strain;
    }
  }
  in.strain_per_command = in.strain_at_knot.front() / in.knot_command.front();
  AddLayerOf(leader_, in);
  return in;
}

}  // namespace sedbridge::render
