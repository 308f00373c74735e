// Hard cases stay numerically stable. Each case runs a fingertip scene and
// asserts: every value finite; every inverted element is reported; energy bounded (and,
// once the load holds still, never growing); no growing oscillation after the load
// settles; every step converged or reported a counted solver fallback.

#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "fem/bone_coupling_force.h"
#include "fem/box_mesh.h"
#include "fem/tet_element.h"
#include "scene/fingertip_scene.h"

namespace sedbridge::scene {
namespace {

struct StabilityCase {
  std::string yaml;          // scene
  int steps = 0;
  int settle_step = -1;      // from here on the load holds still (-1: periodic forcing)
  double poisson = -1;       // override all soft materials' nu when > 0
};

struct StabilityStats {
  int unconverged_without_fallback = 0;
  int fallbacks = 0;
  int max_inverted = 0;
  int unreported_inversions = 0;
  bool finite = true;
  double energy_at_settle = 0, max_energy_after_settle = 0, final_energy = 0;
  double max_energy_first_half = 0, max_energy_second_half = 0;
  double amplitude_early = 0, amplitude_late = 0;  // peak-to-peak of a probe node after settling
};

int CountInverted(const fem::TetMesh& mesh, const Eigen::VectorXd& x) {
  int n = 0;
  for (const auto& t : mesh.tets)
    if (fem::SignedVolume(x.segment<3>(3 * t[0]), x.segment<3>(3 * t[1]), x.segment<3>(3 * t[2]),
                          x.segment<3>(3 * t[3])) <= 0)
      ++n;
  return n;
}

StabilityStats RunCase(const StabilityCase& c) {
  model::FingertipModel m = model::LoadFingertipModel("B_coarse");
  if (c.poisson > 0)
    for (auto& mat : m.soft.materials) mat.poisson_ratio = c.poisson;
  FingertipScene s(ParseSceneDescription(c.yaml, "stability"), std::move(m));
  StabilityStats st;
  // Probe: the Merkel vertex nearest the pad-frame origin (under the load).
  int probe = s.model().merkel_nodes.front();
  double best = 1e9;
  for (int n : s.model().merkel_nodes) {
    const double d = s.model().pad_frame.ToPad(s.model().soft.rest_positions_m.col(n)).norm();
    if (d < best) best = d, probe = n;
  }
  const int settle = c.settle_step;
  const int window = std::max(1, (c.steps - std::max(settle, 0)) / 4);
  double early_lo = 1e9, early_hi = -1e9, late_lo = 1e9, late_hi = -1e9;
  for (int k = 0; k < c.steps; ++k) {
    const fem::StepReport r = s.Step();
    const auto& x = s.simulation().positions_m();
    st.finite = st.finite && r.finite && x.allFinite() && s.simulation().velocities_m_s().allFinite();
    if (s.merkel()) st.finite = st.finite && s.merkel()->sed_Pa().allFinite();
    if (!r.converged && r.solver_fallbacks == 0) ++st.unconverged_without_fallback;
    st.fallbacks += r.solver_fallbacks;
    const int inverted = CountInverted(s.model().soft, x);
    st.max_inverted = std::max(st.max_inverted, inverted);
    // Corotational elements report inversion at the last force evaluation; the step's
    // final state is checked again here, so compare with a fresh evaluation.
    s.simulation().TotalForce();
    if (s.simulation().elastic()->formulation() == fem::ElasticFormulation::kCorotational &&
        s.simulation().elastic()->inverted_elements() != inverted)
      ++st.unreported_inversions;
    const double energy = s.simulation().KineticEnergy() + s.simulation().PotentialEnergy();
    st.finite = st.finite && std::isfinite(energy);
    st.final_energy = energy;
    if (k < c.steps / 2) st.max_energy_first_half = std::max(st.max_energy_first_half, energy);
    else st.max_energy_second_half = std::max(st.max_energy_second_half, energy);
    const double z = x[3 * probe + 2];
    if (settle >= 0 && k == settle) st.energy_at_settle = energy;
    if (settle >= 0 && k > settle) {
      st.max_energy_after_settle = std::max(st.max_energy_after_settle, energy);
      if (k <= settle + window) early_lo = std::min(early_lo, z), early_hi = std::max(early_hi, z);
      if (k > c.steps - window) late_lo = std::min(late_lo, z), late_hi = std::max(late_hi, z);
    }
  }
  st.amplitude_early = early_hi - early_lo;
  st.amplitude_late = late_hi - late_lo;
  return st;
}

void ExpectStable(const StabilityStats& st, bool periodic) {
  EXPECT_TRUE(st.finite);
  EXPECT_EQ(st.unconverged_without_fallback, 0);
  EXPECT_EQ(st.unreported_inversions, 0);
  if (periodic) {
    EXPECT_LE(st.max_energy_second_half, 1.5 * st.max_energy_first_half + 1e-12);
  } else {
    // Once the load holds still, backward Euler with damping only dissipates.
    EXPECT_LE(st.max_energy_after_settle, st.energy_at_settle * 1.001 + 1e-12);
    EXPECT_LE(st.final_energy, st.energy_at_settle + 1e-12);
    EXPECT_LE(st.amplitude_late, st.amplitude_early + 1e-9);
  }
}

std::string Scene(const std::string& elasticity, const std::string& solver, const std::string& contact_yaml,
                  double k_contact = 1e4) {
  return "model: B_coarse\nelasticity: " + elasticity + "\nsolver: {type: " + solver +
         ", tolerance: 1.0e-8, max_iterations: 300}\n"
         "dynamics: {integrator: backward_euler, dt_s: 0.001, newton_iterations: 1}\nbone: {mode: fixed}\n"
         "contact:\n  stiffness_N_m: " + std::to_string(k_contact) + "\n  objects:\n" + contact_yaml;
}

// A plane from first touch to `depth_mm` in `ramp_s`, then held.
std::string PlanePress(double depth_mm, double ramp_s) {
  return "    - {shape: plane, rpy_deg: [180, 0, 0], motion: {keyframes: [{t_s: 0, offset_mm: [0, 0, 0]}, "
         "{t_s: " + std::to_string(ramp_s) + ", offset_mm: [0, 0, " + std::to_string(-depth_mm) + "]}]}}\n";
}

TEST(Stability, NearlyIncompressibleNu0499) {
  StabilityCase c{Scene("corotational", "pcg_warp", PlanePress(1.0, 0.05)), 150, 60, 0.499};
  ExpectStable(RunCase(c), false);
}

TEST(Stability, StiffContactK1e6) {
  StabilityCase c{Scene("corotational", "pcg_warp", PlanePress(1.0, 0.05), 1e6), 150, 60};
  ExpectStable(RunCase(c), false);
}

TEST(Stability, PressIntoBone4mm) {
  StabilityCase c{Scene("corotational", "pcg_warp", PlanePress(4.0, 0.1)), 200, 110};
  const StabilityStats st = RunCase(c);
  ExpectStable(st, false);
  RecordProperty("max_inverted_elements", st.max_inverted);
}

TEST(Stability, SharpEdgeIndenter) {
  const std::string edge =
      "    - {shape: edge, radius_mm: 0.1, rpy_deg: [0, 0, 0], position_mm: [0, 0, 0.1], motion: {keyframes: "
      "[{t_s: 0, offset_mm: [0, 0, 0]}, {t_s: 0.05, offset_mm: [0, 0, -1.0]}]}}\n";
  StabilityCase c{Scene("corotational", "pcg_warp", edge), 150, 60};
  ExpectStable(RunCase(c), false);
}

TEST(Stability, InstantaneousStep2mm) {
  const std::string step =
      "    - {shape: plane, rpy_deg: [180, 0, 0], motion: {keyframes: [{t_s: 0, offset_mm: [0, 0, 0]}, "
      "{t_s: 0.0005, offset_mm: [0, 0, -2.0]}]}}\n";
  StabilityCase c{Scene("corotational", "pcg_warp", step), 200, 5};
  ExpectStable(RunCase(c), false);
}

TEST(Stability, VibratingIndenter300Hz) {
  const std::string vib =
      "    - {shape: sphere, radius_mm: 4, position_mm: [0, 0, 3.5], motion: {vibration: "
      "{amplitude_mm: 0.2, frequency_Hz: 300, direction: [0, 0, 1]}}}\n";
  StabilityCase c{Scene("corotational", "pcg_warp", vib), 200, -1};
  ExpectStable(RunCase(c), true);
}

// The plane pushed 2 mm in 1 s and held 2 s on B_coarse, backward Euler at dt = 10 ms, one
// Newton iteration a step: final force, largest force, largest energy in the first and the
// second half of the hold.
std::array<double, 4> HeldPlanePress(const std::string& solver) {
  const std::string yaml =
      "model: B_coarse\nelasticity: corotational\nsolver: " + solver +
      "\ndynamics: {integrator: backward_euler, dt_s: 0.01, newton_iterations: 1}\nbone: {mode: fixed}\n"
      "contact:\n  objects:\n" + PlanePress(2.0, 1.0);
  FingertipScene s(ParseSceneDescription(yaml, "capped"), model::LoadFingertipModel("B_coarse"));
  // Inexact steps are not backward Euler steps: after the plane stops, the lag is worked
  // off with a transient; it must die out, not grow.
  double max_force_N = 0, max_energy_mid_hold = 0, max_energy_late_hold = 0;
  for (int k = 0; k < 300; ++k) {
    const fem::StepReport r = s.Step();
    EXPECT_TRUE(r.finite) << "step " << k;
    max_force_N = std::max(max_force_N, s.contact()->TotalSpringForceMagnitude());
    const double e = s.simulation().KineticEnergy() + s.simulation().PotentialEnergy();
    if (k >= 200 && k < 250) max_energy_mid_hold = std::max(max_energy_mid_hold, e);
    if (k >= 250) max_energy_late_hold = std::max(max_energy_late_hold, e);
  }
  return {s.contact()->TotalSpringForceMagnitude(), max_force_N, max_energy_mid_hold, max_energy_late_hold};
}

void ExpectSettlesLikeTheExactSolve(const std::array<double, 4>& capped, const std::array<double, 4>& exact) {
  EXPECT_NEAR(capped[0], exact[0], 0.02 * exact[0]);  // settles at the exact equilibrium
  EXPECT_LT(capped[1], 1.5 * exact[1]);               // bounded transient when the plane stops
  EXPECT_LE(capped[3], capped[2] * 1.001 + 1e-12);    // no energy growth while held
}

TEST(Stability, CappedPcgAcceptedWithoutFallback) {
  // A real-time budget: 3 PCG iterations a step, the capped iterate used as is (no direct
  // fallback). Before the solver stopped warm-starting from a guess worse than zero, the
  // last step's dv fed back and the contact force reached 1e12 N by 2 mm.
  const auto exact = HeldPlanePress("{type: pcg_warp, tolerance: 1.0e-8, max_iterations: 300}");
  ASSERT_GT(exact[0], 1.0);  // the press does reach > 1 N
  ExpectSettlesLikeTheExactSolve(
      HeldPlanePress("{type: pcg_warp, tolerance: 1.0e-8, max_iterations: 3, fallback_to_direct: false}"), exact);
}

TEST(Stability, OnePcgIterationHoldsThePressWithContactInThePreconditioner) {
  // One PCG iteration a step. With the rest factor alone the held press was not stable (the
  // force wandered between 1.3 and 5.4 N over the hold, 1.835 N exact: docs/accuracy-cost.md);
  // with the contact springs in the preconditioner (solver.contact_update) it settles.
  const auto exact = HeldPlanePress("{type: pcg_warp, tolerance: 1.0e-8, max_iterations: 300}");
  ASSERT_GT(exact[0], 1.0);
  ExpectSettlesLikeTheExactSolve(
      HeldPlanePress("{type: pcg_warp, tolerance: 1.0e-8, max_iterations: 1, fallback_to_direct: false}"), exact);
}

TEST(Stability, SoakAtRest100kSteps) {
  // 10^5 backward Euler steps with nothing touching: rounding in F = Ds Dm^-1 and in the
  // rotation extraction must not drift or grow. Corotational on a block on rollers (a
  // fingertip would take minutes at this step count; the fingertip soak follows).
  const fem::TetMesh mesh = fem::MakeBoxMesh({0.008, 0.008, 0.006}, {4, 4, 3}, {"skin", 1e5, 0.48, 1000});
  std::vector<std::unique_ptr<fem::ForceTerm>> terms;
  auto elastic = std::make_unique<fem::ElasticTetForce>(mesh, fem::ElasticFormulation::kCorotational);
  const fem::ElasticTetForce* rotations = elastic.get();
  terms.push_back(std::move(elastic));
  std::vector<int> bottom;
  for (int i = 0; i < mesh.num_nodes(); ++i)
    if (mesh.rest_positions_m(2, i) == 0.0) bottom.push_back(i);
  terms.push_back(std::make_unique<fem::BoneCouplingForce>(mesh.rest_positions_m, bottom, std::vector<Eigen::Vector3d>{},
                                                           fem::SpringDamperParams{200, 0.1, 1.0}));
  fem::Simulation sim(mesh, std::move(terms), fem::IntegratorSettings{}, fem::MakeLinearSolver("pcg_warp", {}, rotations));
  const Eigen::VectorXd x0 = sim.positions_m();
  double max_drift = 0;
  for (int k = 0; k < 100000; ++k) {
    const auto r = sim.Step(1e-3);
    ASSERT_TRUE(r.finite && r.converged) << "step " << k;
    if (k % 1000 == 999) max_drift = std::max(max_drift, (sim.positions_m() - x0).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(max_drift, 1e-12);
  EXPECT_LT(sim.KineticEnergy(), 1e-24);
}

TEST(Stability, SoakAtRestFingertip) {
  const std::string yaml =
      "model: B_coarse\nelasticity: corotational\nsolver: {type: pcg_warp}\n"
      "dynamics: {integrator: backward_euler, dt_s: 0.001}\nbone: {mode: fixed}\nsurface_traction: true\n";
  FingertipScene s(ParseSceneDescription(yaml, "soak"), model::LoadFingertipModel("B_coarse"));
  const Eigen::VectorXd x0 = s.simulation().positions_m();
  for (int k = 0; k < 2000; ++k) ASSERT_TRUE(s.Step().finite) << "step " << k;
  EXPECT_LT((s.simulation().positions_m() - x0).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT(s.merkel()->sed_Pa().maxCoeff(), 1e-12);
}

}  // namespace
}  // namespace sedbridge::scene
