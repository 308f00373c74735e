#include "contact/surface_pressure_on_leader.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "common/geometry/planar_barycentric.h"

namespace sedbridge::contact {
namespace {

// A cell's force reaches the skin at kSub x kSub equal points over the cell.
constexpr int kSub = 3;
// Barycentric coordinates below this are outside the face [-] (round-off on shared edges).
constexpr double kInsideFace = -1e-9;

}  // namespace

SurfacePressureOnLeader::SurfacePressureOnLeader(scene::FingertipCompliance& leader, const Eigen::Matrix2Xd& cells_pad_mm,
                                                 double cell_mm)
    : leader_(leader) {
  if (!(cell_mm > 0) || !cells_pad_mm.allFinite())
    throw std::invalid_argument("surface pressure on the leader: finite cell centres and a cell size > 0");
  const fem::ComplianceContact& contact = leader.contact();
  const model::FingertipModel& model = leader.model();
  const std::vector<int>& candidates = contact.candidate_nodes();
  const int c = int(candidates.size());
  std::vector<int> candidate_of(size_t(model.num_soft_nodes()), -1);
  Eigen::Matrix3Xd x(3, c);  // candidates at rest, pad frame [mm]
  for (int j = 0; j < c; ++j) {
    candidate_of[size_t(candidates[size_t(j)])] = j;
    x.col(j) = model.pad_frame.ToPad(model.soft.rest_positions_m.col(candidates[size_t(j)])) * 1e3;
  }
  struct Face {
    std::array<int, 3> v;
    Eigen::Vector2d lo, hi;
  };
  std::vector<Face> faces;
  for (const fem::Triangle& t : model.skin_triangles) {
    Face f{{candidate_of[size_t(t[0])], candidate_of[size_t(t[1])], candidate_of[size_t(t[2])]}, {}, {}};
    if (std::min({f.v[0], f.v[1], f.v[2]}) < 0) continue;
    f.lo = f.hi = x.col(f.v[0]).head<2>();
    for (int a = 1; a < 3; ++a) f.lo = f.lo.cwiseMin(x.col(f.v[size_t(a)]).head<2>()), f.hi = f.hi.cwiseMax(x.col(f.v[size_t(a)]).head<2>());
    faces.push_back(f);
  }
  shares_.resize(size_t(cells_pad_mm.cols()));
  std::vector<double> share(static_cast<size_t>(c), 0.0);
  std::vector<int> touched;
  for (Eigen::Index k = 0; k < cells_pad_mm.cols(); ++k) {
    const Eigen::Vector2d centre = cells_pad_mm.col(k);
    const Eigen::Vector2d lo = centre.array() - 0.5 * cell_mm, hi = centre.array() + 0.5 * cell_mm;
    std::vector<const Face*> near;
    for (const Face& f : faces)
      if ((f.lo.array() <= hi.array()).all() && (f.hi.array() >= lo.array()).all()) near.push_back(&f);
    touched.clear();
    for (int sy = 0; sy < kSub; ++sy)
      for (int sx = 0; sx < kSub; ++sx) {
        const Eigen::Vector2d q = centre + cell_mm * Eigen::Vector2d((sx + 0.5) / kSub - 0.5, (sy + 0.5) / kSub - 0.5);
        // The face over q nearest the pad (highest z): the skin a pressure there loads.
        double best_z = -std::numeric_limits<double>::infinity();
        const Face* best = nullptr;
        Eigen::Vector3d best_w = Eigen::Vector3d::Zero(), w;
        for (const Face* f : near) {
          if (!geometry::PlanarBarycentric(q, x.col(f->v[0]).head<2>(), x.col(f->v[1]).head<2>(), x.col(f->v[2]).head<2>(), w)) continue;
          if (w.minCoeff() < kInsideFace) continue;
          const double z = w[0] * x(2, f->v[0]) + w[1] * x(2, f->v[1]) + w[2] * x(2, f->v[2]);
          if (z > best_z) best_z = z, best = f, best_w = w;
        }
        if (!best) continue;
        for (int a = 0; a < 3; ++a) {
          const int s = best->v[size_t(a)];
          if (share[size_t(s)] == 0) touched.push_back(s);
          share[size_t(s)] += best_w[a] / (kSub * kSub);
        }
      }
    for (const int s : touched) {
      if (share[size_t(s)] != 0) shares_[size_t(k)].emplace_back(s, share[size_t(s)]);  // node sample s = candidate s
      share[size_t(s)] = 0;
    }
  }
  loads_ = Eigen::Matrix3Xd::Zero(3, contact.num_samples());
}

double SurfacePressureOnLeader::coverage(int cell) const {
  double sum = 0;
  for (const auto& [sample, share] : shares_.at(size_t(cell))) sum += share;
  return sum;
}

bool SurfacePressureOnLeader::Press(const Eigen::VectorXd& cell_force_N, const Eigen::Vector2d& shear_pad_N) {
  error_.clear();
  applied_N_ = 0;
  if (cell_force_N.size() != Eigen::Index(shares_.size()) || !cell_force_N.allFinite() ||
      (cell_force_N.array() < 0).any() || !shear_pad_N.allFinite()) {
    error_ = "surface pressure on the leader: one finite force >= 0 per cell and a finite tangential force";
    return false;
  }
  const double total = cell_force_N.sum();
  loads_.setZero();
  for (size_t k = 0; k < shares_.size(); ++k) {
    const double f = cell_force_N[Eigen::Index(k)];
    if (f == 0) continue;
    const Eigen::Vector2d t = shear_pad_N * (f / total);
    for (const auto& [sample, share] : shares_[k]) {
      loads_(0, sample) += share * t.x();
      loads_(1, sample) += share * t.y();
      loads_(2, sample) -= share * f;  // pressing: along -z_pad
      applied_N_ += share * f;
    }
  }
  leader_.ResetWarmStart();
  leader_.SetSampleLoads(loads_);  // all zero: none held
  const fem::ComplianceStepResult& r = leader_.Step({});
  leader_.ClearSampleLoads();
  leader_.ResetWarmStart();
  if (!r.ok) {
    error_ = "surface pressure on the leader: the step failed: " + r.error;
    return false;
  }
  return true;
}

}  // namespace sedbridge::contact
