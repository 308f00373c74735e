#include "scene/fingertip_scene.h"

#include <Eigen/Dense>
#include <set>

#include "fem/elastic_tet_force.h"
#include "fem/mesh_topology.h"
#include "fem/nodal_pressure_tet_force.h"
#include "fem/pseudo_friction_force.h"

namespace sedbridge::scene {

FingertipScene::FingertipScene(const SceneDescription& d)
    : FingertipScene(d, model::LoadFingertipModel(d.model)) {}

FingertipScene::FingertipScene(const SceneDescription& d, model::FingertipModel m)
    : description_(d), model_(std::make_unique<model::FingertipModel>(std::move(m))) {
  Build();
}

void FingertipScene::Build() {
  const model::FingertipModel& m = *model_;
  const SceneDescription& d = description_;
  std::vector<std::unique_ptr<fem::ForceTerm>> terms;

  auto elastic = std::make_unique<fem::ElasticTetForce>(m.soft, d.elasticity, d.rayleigh_beta_s, d.nodal_pressure);
  // Quasi-static Newton iterates to equilibrium: the consistent tangent takes it there in
  // fewer iterations (docs/performance.md). Same equilibria either way.
  if (d.integrator.kind == fem::IntegratorKind::kQuasiStatic)
    elastic->set_corotational_tangent(fem::CorotationalTangent::kConsistent);
  const fem::ElasticTetForce& elastic_ref = *elastic;
  terms.push_back(std::move(elastic));
  if (d.nodal_pressure) {
    // Right after the elastic term: it reads that term's rotations of the same assembly.
    auto nodal = std::make_unique<fem::NodalPressureTetForce>(elastic_ref, d.rayleigh_beta_s);
    nodal_pressure_ = nodal.get();
    terms.push_back(std::move(nodal));
  }
  if (d.bone) {
    std::vector<Eigen::Vector3d> normals;
    if (d.bone->spring.anisotropy != 1.0) {
      // Bone-surface normals: boundary faces of the soft mesh made only of attached nodes.
      const std::set<int> attached(m.attached_nodes.begin(), m.attached_nodes.end());
      std::vector<fem::Triangle> interface;
      for (const auto& f : fem::BoundaryFaces(m.soft.tets, m.soft.rest_positions_m))
        if (attached.count(f[0]) && attached.count(f[1]) && attached.count(f[2])) interface.push_back(f);
      normals = fem::VertexNormals(interface, m.soft.rest_positions_m, m.attached_nodes);
    }
    terms.push_back(std::make_unique<fem::BoneCouplingForce>(m.soft.rest_positions_m, m.attached_nodes, normals,
                                                             d.bone->spring, d.bone->motion));
  }
  if (d.contact) {
    std::vector<geometry::RigidObject> objects;
    for (const auto& o : d.contact->objects_pad_frame)
      objects.push_back({o.name, o.shape, o.trajectory.Transformed(m.pad_frame.model_from_pad)});
    auto contact = std::make_unique<fem::PenaltyContactForce>(m.skin_nodes, std::move(objects), d.contact->params);
    contact_ = contact.get();
    terms.push_back(std::move(contact));
    if (d.friction)
      terms.push_back(std::make_unique<fem::PseudoFrictionForce>(*contact_, d.friction->anisotropy, d.friction->coulomb_mu));
  }
  if (d.surface_traction) {
    auto traction = std::make_unique<fem::SurfaceTractionForce>(m.soft.rest_positions_m, m.skin_triangles);
    traction_ = traction.get();
    terms.push_back(std::move(traction));
  }
  const bool compliance = d.solver == SolverKind::kCompliance;
  // With the compliance solver the simulation is never stepped (it keeps the state and the
  // terms others read); its linear solver is never factorized.
  simulation_ = std::make_unique<fem::Simulation>(m.soft, std::move(terms), d.integrator,
                                                  fem::MakeLinearSolver(compliance ? "ldlt" : ToString(d.solver), d.pcg, &elastic_ref, contact_));
  if (d.outputs.merkel_sed)
    merkel_ = std::make_unique<MerkelLayer>(m, *simulation_->elastic(), nodal_pressure_, d.outputs.merkel_side);
  if (compliance) compliance_ = std::make_unique<FingertipCompliance>(m, ComplianceOptionsFromScene(d));
  skin_area_m2_ = fem::VertexAreas(m.skin_triangles, m.soft.rest_positions_m);
}

fem::StepReport FingertipScene::Step() {
  if (compliance_) {
    // The simulation never steps here: its team chooser measures this step instead (the
    // contact solve and the threaded SED).
    fem::ChosenTeamScope team = simulation_->StepTeam();
    compliance_t_s_ += description_.dt_s;
    static const std::vector<geometry::RigidObject> kNone;
    fem::StepReport r;
    StageTimer solve_timer(r.stage_ms, Stage::kSolve);
    const fem::ComplianceStepResult& c =
        compliance_->Step(description_.contact ? description_.contact->objects_pad_frame : kNone, compliance_t_s_);
    solve_timer.Stop();
    r.t_s = compliance_t_s_;
    r.threads = team.team();
    r.newton_iterations = c.iterations;
    r.converged = c.ok && c.converged;
    r.finite = c.ok;
    if (c.ok) simulation_->SetPositions(compliance_->contact().positions_m());
    compliance_->contact().EndStep();  // friction anchors, as the simulation's EndStep
    EvaluateMerkelSed(r.stage_ms);
    team.Record();
    return r;
  }
  StageTimes sed_ms;
  fem::StepReport r = simulation_->Step(description_.dt_s, [&] { EvaluateMerkelSed(sed_ms); });
  r.stage_ms.Add(sed_ms);
  return r;
}

void FingertipScene::EvaluateMerkelSed(StageTimes& times) {
  const StageTimer timer(times, Stage::kSed);
  if (merkel_) merkel_->Evaluate(simulation_->positions_m());
}

std::vector<std::string> FingertipScene::BuiltEffects() const {
  std::vector<std::string> names;
  for (const auto& t : simulation_->terms()) names.push_back(t->name());
  return names;
}

double FingertipScene::time_s() const { return compliance_ ? compliance_t_s_ : simulation_->time_s(); }

Eigen::Vector3d FingertipScene::ContactSpringForce_N() const {
  if (compliance_) return compliance_->contact().last().spring_force_N;
  return contact_ ? contact_->TotalSpringForce() : Eigen::Vector3d::Zero();
}

double FingertipScene::ContactArea_m2() const {
  if (!contact_ && !compliance_) return 0.0;
  std::set<int> nodes;
  for (const auto& c : compliance_ ? compliance_->contact().last().contacts : contact_->active_contacts())
    nodes.insert(c.node);
  double area = 0;
  for (int n : nodes) area += skin_area_m2_[n];
  return area;
}

}  // namespace sedbridge::scene
