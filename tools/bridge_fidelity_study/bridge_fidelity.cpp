#include "bridge_fidelity.h"

#include <cmath>
#include <map>

#include "bridge/pressure_boundary_condition.h"
#include "bridge/scene_fe_step.h"
#include "scene/fingertip_scene.h"

namespace sedbridge::bridge::fidelity {

std::vector<Case> DefaultCases() {
  return {
      {"plane", "{shape: plane, rpy_deg: [180, 0, 0], position_mm: [0, 0, 0]}", 1.0},
      {"sphere", "{shape: sphere, radius_mm: 10, position_mm: [0, 0, 10]}", 1.0},
      {"edge", "{shape: edge, radius_mm: 1.0, length_mm: 30, position_mm: [0, 0, 1.0]}", 0.5},
  };
}

namespace {

sensors::SensorProfile IdealGrid(double pitch_mm, double half_width_mm) {
  sensors::SensorProfile p;
  p.name = "ideal_grid";
  p.axes = 1;
  const int n = 2 * static_cast<int>(std::ceil(half_width_mm / pitch_mm));  // even: cells tile around 0
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) p.taxels.push_back({(c - n / 2 + 0.5) * pitch_mm, (r - n / 2 + 0.5) * pitch_mm});
  p.taxel_count = static_cast<int>(p.taxels.size());
  p.taxel_width_mm = p.taxel_height_mm = pitch_mm;
  return p;
}

}  // namespace

std::vector<Result> RunCase(const std::string& model, const Case& c, const std::vector<double>& pitches_mm,
                            NodalLoad nodal_load, int press_steps) {
  // Direct press: the object moves depth_mm along -z_pad over the quasi-static steps.
  char yaml[1024];
  std::snprintf(yaml, sizeof yaml,
                "model: %s\nelasticity: linear\n"
                "dynamics: {integrator: quasi_static, steps: %d, newton_iterations: 30, newton_tolerance_mm: 1.0e-6}\n"
                "solver: {type: ldlt}\nbone: {mode: fixed}\n"
                "contact:\n  objects:\n    - %.*s, motion: {keyframes: [{t_s: 0, offset_mm: [0, 0, 0]}, "
                "{t_s: 1, offset_mm: [0, 0, %g]}]}}\n",
                model.c_str(), press_steps, static_cast<int>(c.object_yaml.size() - 1), c.object_yaml.c_str(),
                -c.depth_mm);
  scene::FingertipScene direct(scene::ParseSceneDescription(yaml, "fidelity_" + c.name));
  for (int s = 0; s < press_steps; ++s) direct.Step();
  const Eigen::VectorXd s_ref = direct.merkel()->sed_Pa();
  const std::vector<int>& facing = direct.merkel()->facing_pad();
  const auto& pad = direct.model().pad_frame;
  const Eigen::Matrix3d R_pad = pad.model_from_pad.linear().transpose();

  // Contact force per skin node, in the pad frame (pressing = along -z_pad).
  std::map<int, double> node_force_N;
  double contact_force = 0;
  for (const auto& a : direct.contact()->active_contacts()) {
    const double fz = -(R_pad * (a.normal * a.spring_force_N)).z();
    node_force_N[a.node] += fz;
    contact_force += fz;
  }

  // Diagnostic: the contact's nodal forces exactly, through the traction term.
  double exact_error = 0;
  {
    sensors::SensorProfile one = IdealGrid(4.0, 4.0);
    SceneFeStep exact(BridgeSceneDescription(model, "fast"), one, PadRegistration(one.taxels));
    fem::SurfaceTractionForce& tr = *exact.scene().traction();
    const std::vector<int>& ids = tr.nodes();
    std::map<int, int> index;
    for (size_t k = 0; k < ids.size(); ++k) index[ids[k]] = static_cast<int>(k);
    Eigen::Matrix3Xd F = Eigen::Matrix3Xd::Zero(3, Eigen::Index(ids.size()));
    for (const auto& a : direct.contact()->active_contacts())
      if (index.count(a.node)) F.col(index[a.node]) += a.normal * a.spring_force_N;
    const Eigen::VectorXd& area = exact.scene().skin_node_area_m2();
    // Richardson on M t = F with the lumped areas as preconditioner (M/a has spectrum in (0, 1]).
    Eigen::Matrix3Xd t = Eigen::Matrix3Xd::Zero(3, F.cols());
    for (int it = 0; it < 400; ++it) {
      tr.SetNodalTraction(t);
      const Eigen::Matrix3Xd r = F - tr.NodalForces();
      for (Eigen::Index k = 0; k < t.cols(); ++k) t.col(k) += r.col(k) / area[ids[size_t(k)]];
    }
    tr.SetNodalTraction(t);
    exact.scene().Step();
    const Eigen::VectorXd& s = exact.scene().merkel()->sed_Pa();
    double num = 0, den = 0;
    for (Eigen::Index k = 0; k < s_ref.size(); ++k)
      if (facing[size_t(k)]) num += (s[k] - s_ref[k]) * (s[k] - s_ref[k]), den += s_ref[k] * s_ref[k];
    exact_error = den > 0 ? std::sqrt(num / den) : 0;
  }

  std::vector<Result> results;
  for (double h : pitches_mm) {
    const sensors::SensorProfile grid = IdealGrid(h, 12.0);
    TaxelValues v;
    v.pressure_Pa.assign(size_t(grid.taxel_count), 0.0);
    const int n_side = static_cast<int>(std::lround(std::sqrt(grid.taxel_count)));
    for (const auto& [node, f] : node_force_N) {
      const Eigen::Vector3d p = pad.ToPad(direct.model().soft.rest_positions_m.col(node)) * 1e3;
      const int col = static_cast<int>(std::floor(p.x() / h)) + n_side / 2;
      const int row = static_cast<int>(std::floor(p.y() / h)) + n_side / 2;
      if (col < 0 || row < 0 || col >= n_side || row >= n_side) continue;
      v.pressure_Pa[size_t(row * n_side + col)] += f / (h * h * 1e-6);
    }
    TractionFieldOptions options;
    options.nodal_load = nodal_load;
    SceneFeStep bc(BridgeSceneDescription(model, "fast"), grid, PadRegistration(grid.taxels), options);
    const MerkelSedResult& r = bc.Step(v);
    Result out;
    out.name = c.name;
    out.pitch_mm = h;
    out.taxels = grid.taxel_count;
    out.contact_force_N = contact_force;
    out.bc_force_N = r.applied_force_N;
    double num = 0, den = 0;
    for (Eigen::Index k = 0; k < s_ref.size(); ++k) {
      if (!facing[size_t(k)]) continue;
      const double d = (*r.sed_Pa)[k] - s_ref[k];
      num += d * d;
      den += s_ref[k] * s_ref[k];
      out.ref_max_sed_Pa = std::max(out.ref_max_sed_Pa, s_ref[k]);
      out.bc_max_sed_Pa = std::max(out.bc_max_sed_Pa, (*r.sed_Pa)[k]);
    }
    out.rel_l2_error = den > 0 ? std::sqrt(num / den) : 0;
    out.peak_ratio = out.ref_max_sed_Pa > 0 ? out.bc_max_sed_Pa / out.ref_max_sed_Pa : 0;
    out.exact_nodal_rel_l2_error = exact_error;
    results.push_back(out);
  }
  return results;
}

}  // namespace sedbridge::bridge::fidelity
