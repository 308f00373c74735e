#include "bridge/scene_fe_step.h"

#include <omp.h>

#include "fem/thread_team.h"

#include <cstdio>
#include <stdexcept>

namespace sedbridge::bridge {

scene::SceneDescription BridgeSceneDescription(const std::string& model, const std::string& preset) {
  scene::SceneDescription d;
  d.file = "<bridge>";
  d.model = model;
  d.preset = preset;
  scene::ApplyPreset(preset, d);
  d.integrator.kind = fem::IntegratorKind::kQuasiStatic;
  d.steps = 1;
  d.dt_s = 1.0;
  d.bone = scene::BoneSection{};
  d.surface_traction = true;
  d.outputs.merkel_sed = true;
  d.outputs.full_sed = false;
  d.outputs.vtu_every = 0;
  return d;
}

model::FingertipModel LoadBridgeModel(const std::string& name, const model::MerkelVertexFilter& merkel_filter) {
  model::FingertipModel m = model::LoadFingertipModel(name);
  if (merkel_filter) model::KeepMerkelVertices(&m, merkel_filter);
  return m;
}

SceneFeStep::SceneFeStep(const scene::SceneDescription& description, const sensors::SensorProfile& profile,
                         const PadRegistration& registration, const TractionFieldOptions& options,
                         const model::MerkelVertexFilter& merkel_filter)
    : scene_(std::make_unique<scene::FingertipScene>(description, LoadBridgeModel(description.model, merkel_filter))) {
  if (!scene_->traction()) throw std::invalid_argument("bridge scene needs surface_traction: true");
  if (!scene_->merkel()) throw std::invalid_argument("bridge scene needs outputs.merkel_sed: true");
  bc_ = std::make_unique<PressureBoundaryCondition>(*scene_, profile, registration, options);
  model_id_ = scene_->model().name;
  TaxelValues zero;
  zero.pressure_Pa.assign(size_t(profile.taxel_count), 0.0);
  Step(zero);
}

void SetFeThreads(int threads) {
  fem::SetAutoThreadTeam(false);  // the bridge's team is what it asked for
  omp_set_num_threads(threads < 1 ? 1 : threads);
}

const MerkelSedResult& SceneFeStep::Step(const TaxelValues& values) {
  result_ = MerkelSedResult{};
  StageTimes bc_time;
  StageTimer bc_timer(bc_time, Stage::kBoundaryCondition);
  const Eigen::Matrix3Xd& traction = bc_->Apply(values);
  if (!traction.allFinite()) {  // cannot happen with conditioned values; never hand NaN to the FE
    result_.error = "non-finite traction";
    return result_;
  }
  try {
    scene_->traction()->SetNodalTraction(traction);
  } catch (const std::invalid_argument& e) {
    result_.error = e.what();
    return result_;
  }
  bc_timer.Stop();
  result_.report = scene_->Step();
  result_.report.stage_ms.Add(bc_time);
  const Eigen::Vector3d f_model = scene_->traction()->TotalForce();
  result_.applied_force_N = -(scene_->model().pad_frame.model_from_pad.linear().transpose() * f_model).z();
  if (!result_.report.finite) {
    result_.error = "FE step produced NaN/Inf (rolled back)";
    return result_;
  }
  // Not `report.converged`: with one Newton iteration (the linear "fast" preset, exact for
  // a linear problem) it reads false whenever the load changed. A bad linear solve is what
  // matters here.
  if (!(result_.report.linear_residual <= kMaxLinearResidual)) {
    result_.error = "FE linear solve residual " + std::to_string(result_.report.linear_residual);
    return result_;
  }
  result_.sed_Pa = &scene_->merkel()->sed_Pa();
  result_.ok = true;
  return result_;
}

Eigen::VectorXd SceneFeStep::LoadVector(const TaxelValues& values, double* applied_force_N) {
  scene_->traction()->SetNodalTraction(bc_->Apply(values));
  *applied_force_N = -(scene_->model().pad_frame.model_from_pad.linear().transpose() * scene_->traction()->TotalForce()).z();
  return scene_->simulation().TotalForce();
}

const Eigen::Matrix3Xd& SceneFeStep::merkel_rest_pad_mm() const { return scene_->merkel()->rest_pad_mm(); }

bool SceneFeStep::Frame(FeFrame* frame) const {
  const scene::FingertipScene& sc = *scene_;
  const fem::TetMesh& mesh = sc.model().soft;
  const int n = mesh.num_nodes();
  frame->mesh = &mesh;
  frame->positions_m = sc.simulation().positions_m();
  scene::VtuField traction{"traction_pad_Pa", 3, std::vector<double>(size_t(3 * n), 0.0)};
  const Eigen::Matrix3Xd& t = bc_->traction_pad_Pa();
  const std::vector<int>& ids = sc.traction()->nodes();
  for (size_t k = 0; k < ids.size(); ++k)
    for (int d = 0; d < 3; ++d) traction.values[size_t(3 * ids[k] + d)] = t(d, Eigen::Index(k));
  frame->point_fields = {std::move(traction), MerkelSedPointField(n, sc.merkel()->nodes(), sc.merkel()->sed_Pa())};
  return true;
}

std::string SceneFeStep::Describe() const {
  const auto& m = scene_->model();
  char buf[256];
  std::snprintf(buf, sizeof buf, "model %s (%s): %d soft nodes, %zu Merkel vertices, solver %s; %zu loaded skin nodes",
                m.name.c_str(), scene_->description().preset.c_str(), m.num_soft_nodes(), m.merkel_nodes.size(),
                scene_->simulation().solver().name().c_str(), bc_->field().loaded_nodes.size());
  return buf;
}

}  // namespace sedbridge::bridge
