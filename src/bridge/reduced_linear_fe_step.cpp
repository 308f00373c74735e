#include "bridge/reduced_linear_fe_step.h"

#include <cstdio>
#include <stdexcept>
#include <vector>

#include "fem/stiffness_inverse.h"

namespace sedbridge::bridge {

ReducedLinearFeStep::ReducedLinearFeStep(const scene::SceneDescription& d, const sensors::SensorProfile& profile,
                                         const PadRegistration& registration, const TractionFieldOptions& options,
                                         const model::MerkelVertexFilter& merkel_filter) {
  if (d.elasticity != fem::ElasticFormulation::kLinear || d.integrator.kind != fem::IntegratorKind::kQuasiStatic ||
      d.contact || d.friction || (d.bone && d.bone->motion) || !d.surface_traction)
    throw std::invalid_argument(
        "the reduced FE step needs a linear quasi-static traction-only scene with the bone fixed (preset 'fast')");
  auto pre = std::make_shared<ReducedLinearPrecompute>();
  pre->scene_step = std::make_unique<SceneFeStep>(d, profile, registration, options, merkel_filter);
  const int num_taxels_ = pre->num_taxels = profile.taxel_count;
  const bool shear_ = pre->shear = profile.axes == 3;
  Eigen::MatrixXd& U_ = pre->U;
  Eigen::VectorXd& rest_m_ = pre->rest_m;
  Eigen::VectorXd& force_per_Pa_N_ = pre->force_per_Pa_N;
  SceneFeStep& scene_step = *pre->scene_step;
  scene::FingertipScene& sc = scene_step.scene();
  const Eigen::Matrix3Xd& rest = sc.model().soft.rest_positions_m;
  rest_m_ = Eigen::Map<const Eigen::VectorXd>(rest.data(), rest.size());
  const int axes = shear_ ? 3 : 1;
  if (sc.simulation().matrix_free())
    throw std::invalid_argument("the reduced FE step needs an assembled stiffness (a direct solver, not matrix-free PCG)");
  U_.resize(rest_m_.size(), num_taxels_ * axes);
  force_per_Pa_N_.setZero(num_taxels_);
  // The load of each unit taxel value (1 kPa for round-off, scaled back to per Pa) at rest.
  constexpr double kUnit_Pa = 1e3;
  TaxelValues unit;
  unit.pressure_Pa.assign(size_t(num_taxels_), 0.0);
  if (shear_) unit.shear_x_Pa = unit.shear_y_Pa = unit.pressure_Pa;
  sc.simulation().SetPositions(rest_m_);
  std::vector<Eigen::VectorXd> loads(size_t(num_taxels_ * axes));
  for (int a = 0; a < axes; ++a)
    for (int j = 0; j < num_taxels_; ++j) {
      std::vector<double>& target = a == 0 ? unit.pressure_Pa : (a == 1 ? unit.shear_x_Pa : unit.shear_y_Pa);
      target[size_t(j)] = kUnit_Pa;
      double applied_N = 0;
      loads[size_t(a * num_taxels_ + j)] = scene_step.LoadVector(unit, &applied_N);
      if (a == 0) force_per_Pa_N_[j] = applied_N / kUnit_Pa;
      target[size_t(j)] = 0.0;
    }
  double unloaded_N = 0;  // back to no traction (unit is all zero again)
  scene_step.LoadVector(unit, &unloaded_N);
  // One back-substitution per column on the scene's K at rest (assembled by its unloaded
  // step: the linear quasi-static matrix is constant).
  const bool ok = fem::SolveForLoads(
      sc.simulation().system_matrix(), int(loads.size()),
      [&](int i, Eigen::VectorXd& b, std::vector<int>& touched) {
        const Eigen::VectorXd& f = loads[size_t(i)];
        for (Eigen::Index k = 0; k < f.size(); ++k)
          if (f[k] != 0) b[k] = f[k], touched.push_back(int(k));
      },
      [&](int i, const Eigen::VectorXd& u) { U_.col(i) = u / kUnit_Pa; }, 0);
  if (!ok) throw std::runtime_error("reduced FE step: a unit load's solve failed");
  sc.simulation().SetPositions(rest_m_);
  pre->sed_nodes = sc.merkel()->element_nodes();
  pre->U_sed.resize(3 * Eigen::Index(pre->sed_nodes.size()), U_.cols());
  for (size_t k = 0; k < pre->sed_nodes.size(); ++k)
    pre->U_sed.middleRows<3>(3 * Eigen::Index(k)) = U_.middleRows<3>(3 * pre->sed_nodes[k]);
  pre_ = std::move(pre);
  StartState();
}

ReducedLinearFeStep::ReducedLinearFeStep(std::shared_ptr<const ReducedLinearPrecompute> precompute)
    : pre_(std::move(precompute)) {
  if (!pre_ || !pre_->scene_step) throw std::invalid_argument("reduced FE step: no precompute");
  StartState();
}

void ReducedLinearFeStep::StartState() {
  // A copy of the shared scene's layer as it was built (never evaluated since): the same
  // start as a layer of one's own.
  merkel_ = std::make_unique<scene::MerkelLayer>(*pre_->scene_step->scene().merkel());
  x_m_ = pre_->rest_m;
  v_.setZero(pre_->U.cols());
}



Eigen::VectorXd ReducedLinearFeStep::positions_m() const {
  Eigen::VectorXd x = pre_->rest_m;
  x.noalias() += pre_->U * v_;
  return x;
}

const MerkelSedResult& ReducedLinearFeStep::Step(const TaxelValues& values) {
  const ReducedLinearPrecompute& p = *pre_;
  const int num_taxels_ = p.num_taxels;
  const bool shear_ = p.shear;
  result_ = MerkelSedResult{};
  StageTimes& times = result_.report.stage_ms;
  StageTimer bc_timer(times, Stage::kBoundaryCondition);
  if (static_cast<int>(values.pressure_Pa.size()) != num_taxels_) {
    result_.error = "taxel count does not match the reduced FE step";
    return result_;
  }
  const bool shear = shear_ && static_cast<int>(values.shear_x_Pa.size()) == num_taxels_ &&
                     static_cast<int>(values.shear_y_Pa.size()) == num_taxels_;
  for (int j = 0; j < num_taxels_; ++j) {
    v_[j] = values.pressure_Pa[size_t(j)];
    if (shear_) {
      v_[num_taxels_ + j] = shear ? values.shear_x_Pa[size_t(j)] : 0.0;
      v_[2 * num_taxels_ + j] = shear ? values.shear_y_Pa[size_t(j)] : 0.0;
    }
  }
  if (!v_.allFinite()) {  // never evaluate NaN
    result_.error = "non-finite taxel values";
    return result_;
  }
  bc_timer.Stop();
  StageTimer solve_timer(times, Stage::kSolve);
  u_sed_.noalias() = p.U_sed * v_;
  for (size_t k = 0; k < p.sed_nodes.size(); ++k)
    x_m_.segment<3>(3 * p.sed_nodes[k]) = p.rest_m.segment<3>(3 * p.sed_nodes[k]) + u_sed_.segment<3>(3 * Eigen::Index(k));
  solve_timer.Stop();
  result_.applied_force_N = p.force_per_Pa_N.dot(v_.head(num_taxels_));
  result_.report.finite = u_sed_.allFinite();
  result_.report.converged = true;
  if (!result_.report.finite) {
    result_.error = "reduced step produced NaN/Inf";
    return result_;
  }
  const StageTimer sed_timer(times, Stage::kSed);
  result_.sed_Pa = &merkel_->Evaluate(x_m_);
  result_.ok = true;
  return result_;
}

bool ReducedLinearFeStep::Frame(FeFrame* frame) const {
  const scene::FingertipScene& sc = pre_->scene_step->scene();
  frame->mesh = &sc.model().soft;
  frame->positions_m = positions_m();
  frame->point_fields = {MerkelSedPointField(sc.model().soft.num_nodes(), merkel_->nodes(), merkel_->sed_Pa())};
  return true;
}

std::string ReducedLinearFeStep::Describe() const {
  char buf[96];
  std::snprintf(buf, sizeof buf, " -- reduced linear step: %ld x %ld displacement map", static_cast<long>(pre_->U.rows()),
                static_cast<long>(pre_->U.cols()));
  return pre_->scene_step->Describe() + buf;
}

}  // namespace sedbridge::bridge
