#include "render/suction_display_on_leader.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

#include "common/geometry/signed_distance_field.h"
#include "common/geometry/planar_barycentric.h"

namespace sedbridge::render {

namespace {

constexpr double kMm = 1e-3;
// The hole's disc quadrature: midpoint rings in the radius (exact for the disc's area) times
// equal angles. The shares sum to the disc's area to rounding where the pad covers the hole;
// a node's own share is off only in the cells a face's edge crosses.
constexpr int kRings = 8, kAngles = 32;
// Largest suction added between two warm-started contact solves of a press [kPa].
constexpr double kRampStep_kPa = 2.5;

// The display's plate at indentation depth_mm: PlateWithHolesSdf is the half-space z < 0 of
// its frame less the holes; turned over (pi about x) its solid is z > -depth in the pad
// frame, and a hole at pad (x, y) sits at (x, -y) of the plate's frame.
geometry::RigidObject HoledPlate(const display::DisplayDevice& device, double depth_mm) {
  std::vector<Eigen::Vector2d> centres_m;
  for (const display::ActuatorFootprint& f : device.footprints) centres_m.emplace_back(f.x_mm * kMm, -f.y_mm * kMm);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(0, 0, -depth_mm * kMm);
  return {"suction plate",
          std::make_shared<geometry::PlateWithHolesSdf>(std::move(centres_m), device.hole_radius_mm * kMm),
          geometry::Trajectory(pose)};
}

}  // namespace

SuctionDisplayOnLeader::SuctionDisplayOnLeader(scene::FingertipCompliance& leader, const display::DisplayDevice& device)
    : leader_(leader), device_(device) {
  if (device.kind != display::DisplayKind::kSuction || device.footprints.empty() || !(device.hole_radius_mm > 0))
    throw std::invalid_argument("suction display on the leader: needs a suction display's device model");
  preload_force_N_ = PreloadForce_N(device);
  leader_.ClearSampleLoads();
  leader_.ResetWarmStart();
  const scene::PressToForceResult r = leader_.PressToForce({HoledPlate(device_, 0.0)}, preload_force_N_);
  if (!r.reached)
    throw std::runtime_error(std::string("suction display on the leader: the preload press failed: ") +
                             scene::ToString(r.status) + " " + r.message);
  preload_depth_mm_ = r.indentation_mm;
  plate_at_preload_ = HoledPlate(device_, preload_depth_mm_);
  FindHoleShares();
}

void SuctionDisplayOnLeader::FindHoleShares() {
  // The candidate nodes where the preload press left them, pad frame [m]: the skin lies on
  // the plate there, and the holes are its openings.
  const fem::ComplianceContact& contact = leader_.contact();
  const model::FingertipModel& model = leader_.model();
  const std::vector<int>& candidates = contact.candidate_nodes();
  const int c = int(candidates.size());
  std::vector<int> candidate_of(size_t(model.num_soft_nodes()), -1);
  Eigen::Matrix3Xd x(3, c);
  for (int j = 0; j < c; ++j) {
    const int node = candidates[size_t(j)];
    candidate_of[size_t(node)] = j;
    x.col(j) = model.pad_frame.ToPad(model.soft.rest_positions_m.col(node) + contact.candidate_displacements_m().col(j));
  }
  // The skin faces of the candidate patch, as candidate triples.
  std::vector<std::array<int, 3>> faces;
  for (const fem::Triangle& t : model.skin_triangles) {
    const std::array<int, 3> f{candidate_of[size_t(t[0])], candidate_of[size_t(t[1])], candidate_of[size_t(t[2])]};
    if (std::min({f[0], f[1], f[2]}) >= 0) faces.push_back(f);
  }
  const double R = device_.hole_radius_mm * kMm;
  hole_shares_m2_.assign(device_.footprints.size(), {});
  Eigen::VectorXd share(c);
  for (size_t i = 0; i < device_.footprints.size(); ++i) {
    const Eigen::Vector2d centre(device_.footprints[i].x_mm * kMm, device_.footprints[i].y_mm * kMm);
    // Faces whose x-y bounding box meets the hole's.
    std::vector<size_t> near;
    for (size_t k = 0; k < faces.size(); ++k) {
      Eigen::Vector2d lo = x.col(faces[k][0]).head<2>(), hi = lo;
      for (int a = 1; a < 3; ++a)
        lo = lo.cwiseMin(x.col(faces[k][size_t(a)]).head<2>()), hi = hi.cwiseMax(x.col(faces[k][size_t(a)]).head<2>());
      if ((lo.array() <= (centre.array() + R)).all() && (hi.array() >= (centre.array() - R)).all()) near.push_back(k);
    }
    share.setZero();
    for (int ring = 0; ring < kRings; ++ring) {
      const double rho = (ring + 0.5) * R / kRings, weight = rho * (R / kRings) * (2 * M_PI / kAngles);
      for (int step = 0; step < kAngles; ++step) {
        const double theta = (step + 0.5) * 2 * M_PI / kAngles;
        const Eigen::Vector2d q = centre + rho * Eigen::Vector2d(std::cos(theta), std::sin(theta));
        // The face over q nearest the plate (highest z): the skin the hole opens onto.
        double best_z = -std::numeric_limits<double>::infinity();
        const std::array<int, 3>* best = nullptr;
        Eigen::Vector3d best_w = Eigen::Vector3d::Zero(), w;
        for (size_t k : near) {
          const std::array<int, 3>& f = faces[k];
          if (!geometry::PlanarBarycentric(q, x.col(f[0]).head<2>(), x.col(f[1]).head<2>(), x.col(f[2]).head<2>(), w)) continue;
          if (w.minCoeff() < -1e-12) continue;
          const double z = w[0] * x(2, f[0]) + w[1] * x(2, f[1]) + w[2] * x(2, f[2]);
          if (z > best_z) best_z = z, best = &f, best_w = w;
        }
        if (!best) continue;  // off the pad: no skin to pull
        for (int a = 0; a < 3; ++a) share[(*best)[size_t(a)]] += weight * best_w[a];
      }
    }
    for (int j = 0; j < c; ++j)
      if (share[j] != 0) hole_shares_m2_[i].emplace_back(j, share[j]);  // node sample j = candidate j
  }
}

double SuctionDisplayOnLeader::hole_skin_area_mm2(int actuator) const {
  double area_m2 = 0;
  for (const auto& [sample, a] : hole_shares_m2_.at(size_t(actuator))) area_m2 += a;
  return area_m2 * 1e6;
}

Eigen::Matrix3Xd SuctionDisplayOnLeader::Loads(const Eigen::VectorXd& suction_kPa) const {
  // Toward the display (+z_pad): the pressure below ambient pulls the skin into the hole.
  Eigen::Matrix3Xd loads = Eigen::Matrix3Xd::Zero(3, leader_.contact().num_samples());
  for (size_t i = 0; i < hole_shares_m2_.size(); ++i) {
    const double p_Pa = suction_kPa[Eigen::Index(i)] * 1e3;
    if (p_Pa == 0) continue;
    for (const auto& [sample, area_m2] : hole_shares_m2_[i]) loads(2, sample) += p_Pa * area_m2;
  }
  return loads;
}

bool SuctionDisplayOnLeader::Press(const Eigen::VectorXd& suction_kPa, Eigen::VectorXd& sed_Pa) {
  error_.clear();
  if (suction_kPa.size() != num_actuators() || !suction_kPa.allFinite() || (suction_kPa.array() < 0).any()) {
    error_ = "one finite suction >= 0 [kPa] per hole";
    return false;
  }
  leader_.ResetWarmStart();
  const int steps = std::max(1, int(std::ceil(suction_kPa.maxCoeff() / kRampStep_kPa)));
  for (int k = 1; k <= steps; ++k) {
    leader_.SetSampleLoads(Loads(suction_kPa * (double(k) / steps)));  // all zero: none held
    const fem::ComplianceStepResult& r = leader_.Step({plate_at_preload_});
    if (!r.ok || !r.converged) {
      leader_.ClearSampleLoads();
      error_ = "contact solve failed: " + (r.error.empty() ? std::string("not converged") : r.error);
      return false;
    }
  }
  leader_.ClearSampleLoads();  // the step's answer stays; the leader is left without loads
  sed_Pa = leader_.sed_Pa();
  return true;
}

ElementStrainInfluence SuctionDisplayOnLeader::Influence(double reference_kPa) {
  if (!(reference_kPa > 0)) throw std::invalid_argument("suction display influence: reference suction > 0");
  return InfluenceByPresses(*this, leader_, reference_kPa, "suction display", &failed_actuators_);
}

}  // namespace sedbridge::render
