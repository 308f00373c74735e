#include "render/display_on_leader.h"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <vector>

#include "render/pin_display_on_leader.h"
#include "render/suction_display_on_leader.h"

namespace sedbridge::render {

namespace {

// Preload area [mm^2]: the footprints' bounding box grown by half the nearest spacing.
double ActuatedArea_mm2(const display::DisplayDevice& device) {
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const display::ActuatorFootprint& f : device.footprints)
    x0 = std::min(x0, f.x_mm), x1 = std::max(x1, f.x_mm), y0 = std::min(y0, f.y_mm), y1 = std::max(y1, f.y_mm);
  std::vector<double> x, y;
  for (const display::ActuatorFootprint& f : device.footprints) x.push_back(f.x_mm), y.push_back(f.y_mm);
  const double spacing =
      device.footprints.size() > 1 ? display::NearestActuatorDistance_mm(x, y) : 2 * device.footprint_radius_mm();
  return (x1 - x0 + spacing) * (y1 - y0 + spacing);
}

using Maker = std::unique_ptr<DisplayOnLeader> (*)(scene::FingertipCompliance& leader,
                                                   const display::DisplayDevice& device);

template <typename Display>
std::unique_ptr<DisplayOnLeader> Make(scene::FingertipCompliance& leader, const display::DisplayDevice& device) {
  return std::make_unique<Display>(leader, device);
}

// The one list of display kinds with a mechanical load: the factory builds from it and
// HasMechanicalLoad answers from it, so a kind added here is rendered by the bridge at once.
Maker MakerOf(display::DisplayKind kind) {
  switch (kind) {
    case display::DisplayKind::kPin:
      return &Make<PinDisplayOnLeader>;
    case display::DisplayKind::kSuction:
      return &Make<SuctionDisplayOnLeader>;
    default:
      return nullptr;
  }
}

}  // namespace

scene::FingertipComplianceOptions DisplayLeaderOptions(scene::FingertipComplianceOptions base) {
  base.face_samples = true;
  base.contact.max_iterations = std::max(base.contact.max_iterations, 200);
  // Pins at a pitch near the skin's sample spacing, deep in the pad: the accelerated
  // iterations can cycle there (docs/display-rendering.md); the unaccelerated ones cannot.
  base.contact.monotone_fallback = true;
  return base;
}

bool HasMechanicalLoad(display::DisplayKind kind) { return MakerOf(kind) != nullptr; }

void AddLayerOf(const scene::FingertipCompliance& leader, ElementStrainInfluence& in) {
  const fem::ComplianceSedMap& map = leader.contact().sed_map();
  in.mu_Pa = Eigen::Map<const Eigen::VectorXd>(map.element_mu_Pa().data(), Eigen::Index(map.element_mu_Pa().size()));
  in.lambda_Pa = Eigen::Map<const Eigen::VectorXd>(map.element_lambda_Pa().data(), Eigen::Index(map.element_lambda_Pa().size()));
  map.VertexAverage(in.vertex_start, in.vertex_element, in.vertex_weight);
}

Eigen::VectorXd StrainsOfLastStep(const scene::FingertipCompliance& leader) {
  Eigen::VectorXd strain;
  const fem::ComplianceSedMap& map = leader.contact().sed_map();
  map.ElementStrains(map.displacements_m(), strain);
  return strain;
}

double PreloadForce_N(const display::DisplayDevice& device) {
  return device.preload_kPa * 1e3 * ActuatedArea_mm2(device) * 1e-6;
}

ElementStrainInfluence InfluenceByPresses(DisplayOnLeader& display, const scene::FingertipCompliance& leader,
                                          double reference, const std::string& what, int* failed_actuators) {
  const int n = display.num_actuators();
  Eigen::VectorXd sed;
  if (!display.Press(Eigen::VectorXd::Zero(n), sed)) throw std::runtime_error(what + " influence: " + display.error());
  ElementStrainInfluence in;
  in.preload_strain = StrainsOfLastStep(leader);
  in.strain_per_command.resize(in.preload_strain.size(), n);
  if (failed_actuators) *failed_actuators = 0;
  for (int i = 0; i < n; ++i) {
    // A press that does not converge is tried again at a quarter of the reference (the load
    // is linear in the command while the contact set holds); if that fails too, the actuator
    // is modelled as doing nothing (the renderer then leaves it off) and counted.
    bool pressed = false;
    for (double command : {reference, 0.25 * reference}) {
      Eigen::VectorXd commands = Eigen::VectorXd::Zero(n);
      commands[i] = command;
      if (!display.Press(commands, sed)) continue;
      in.strain_per_command.col(i) = (StrainsOfLastStep(leader) - in.preload_strain) / command;
      pressed = true;
      break;
    }
    if (pressed) continue;
    if (!failed_actuators)
      throw std::runtime_error(what + " influence: actuator " + std::to_string(i) + ": " + display.error());
    in.strain_per_command.col(i).setZero();
    ++*failed_actuators;
  }
  AddLayerOf(leader, in);
  return in;
}

std::unique_ptr<DisplayOnLeader> MakeDisplayOnLeader(scene::FingertipCompliance& leader,
                                                     const display::DisplayDevice& device) {
  if (device.footprints.empty()) throw std::invalid_argument("display on the leader: the profile has no device model");
  if (const Maker make = MakerOf(device.kind)) return make(leader, device);
  throw std::invalid_argument(std::string("display on the leader: no mechanical load for a ") +
                              display::ToString(device.kind) + " display");
}

}  // namespace sedbridge::render
