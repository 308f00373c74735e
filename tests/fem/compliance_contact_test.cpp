// The compliance method must give the full FE answer: a block on rollers, a sphere or a
// plane pressed onto its top, solved (a) by the quasi-static Newton solve with
// PenaltyContactForce and (b) by ComplianceContact on the top nodes. Also: tangential
// load, warm start, and the disk cache (round trip, corrupt file).

#include "fem/compliance_contact.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include "fem/box_mesh.h"
#include "fem/elastic_tet_force.h"
#include "fem/pseudo_friction_force.h"
#include "fem/simulation.h"
#include "fem_test_util.h"

namespace sedbridge::fem {
namespace {

constexpr double kSide = 0.008, kHeight = 0.006, kContactK = 1e4;

TetMesh Block() { return MakeBoxMesh({kSide, kSide, kHeight}, {6, 6, 4}, testing::Skin(1e5, 0.4)); }

std::vector<std::unique_ptr<ForceTerm>> BlockTerms(const TetMesh& mesh) {
  std::vector<std::unique_ptr<ForceTerm>> terms;
  terms.push_back(std::make_unique<ElasticTetForce>(mesh, ElasticFormulation::kLinear));
  testing::AddRollerSupport(mesh, terms, 1e6);
  return terms;
}

// Mid-height nodes: an SED layer inside the block (like the Merkel layer under the skin).
std::vector<int> SedVertices(const TetMesh& mesh) { return testing::NodesWhere(mesh, 2, 0.5 * kHeight); }

geometry::RigidObject SphereAbove(double radius, double depth, double x = 0.5 * kSide) {
  const Eigen::Isometry3d pose(Eigen::Translation3d(x, 0.5 * kSide, kHeight + radius - depth));
  return {"sphere", std::make_shared<geometry::SphereSdf>(radius), geometry::Trajectory(pose)};
}

geometry::RigidObject PlaneAbove(double depth) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()).toRotationMatrix() *
                  Eigen::Vector3d(1, -1, -1).asDiagonal();  // tilted, normal ~ -z, solid above
  pose.translation() = Eigen::Vector3d(0.5 * kSide, 0.5 * kSide, kHeight - depth);
  return {"plane", std::make_shared<geometry::PlaneSdf>(), geometry::Trajectory(pose)};
}

struct FullAnswer {
  Eigen::VectorXd x;
  Eigen::Vector3d spring_force;
  Eigen::VectorXd sed;
  size_t contacts = 0;
};

FullAnswer FullFe(const TetMesh& mesh, const std::vector<geometry::RigidObject>& objects) {
  auto terms = BlockTerms(mesh);
  const auto top = testing::NodesWhere(mesh, 2, kHeight);
  terms.push_back(std::make_unique<PenaltyContactForce>(top, objects, ContactParams{kContactK, 0.0}));
  auto* contact = static_cast<PenaltyContactForce*>(terms.back().get());
  IntegratorSettings s;
  s.kind = IntegratorKind::kQuasiStatic;
  s.newton_iterations = 100;
  s.newton_tolerance_m = 1e-15;
  Simulation sim(mesh, std::move(terms), s, MakeLinearSolver("ldlt", {}));
  const StepReport r = sim.Step(1.0);
  EXPECT_TRUE(r.converged);
  sim.TotalForce();  // contact state at the converged positions
  FullAnswer a;
  a.x = sim.positions_m();
  a.spring_force = contact->TotalSpringForce();
  a.contacts = contact->active_contacts().size();
  ElasticTetForce elastic(mesh, ElasticFormulation::kLinear);
  VertexSedEvaluator sed(elastic, SedVertices(mesh));
  sed.Evaluate(a.x, a.sed);
  return a;
}

ComplianceContact MakeCompliance(const TetMesh& mesh, ComplianceContactOptions o = {}) {
  o.stiffness_N_m = kContactK;
  return ComplianceContact(mesh, BlockTerms(mesh), testing::NodesWhere(mesh, 2, kHeight), SedVertices(mesh), o);
}

double RelativeError(const Eigen::VectorXd& a, const Eigen::VectorXd& b) { return (a - b).norm() / b.norm(); }

void ExpectSameAsFullFe(const std::vector<geometry::RigidObject>& objects) {
  const TetMesh mesh = Block();
  const FullAnswer full = FullFe(mesh, objects);
  ASSERT_GT(full.contacts, 3u);
  ComplianceContact cc = MakeCompliance(mesh);
  const ComplianceStepResult& r = cc.Step(objects);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.contacts.size(), full.contacts);
  // Displacement of the candidate (top) nodes.
  Eigen::VectorXd u_full(3 * cc.candidate_nodes().size()), u_cc(u_full.size());
  for (size_t j = 0; j < cc.candidate_nodes().size(); ++j) {
    const int n = cc.candidate_nodes()[j];
    u_full.segment<3>(3 * Eigen::Index(j)) = full.x.segment<3>(3 * n) - mesh.rest_positions_m.col(n);
    u_cc.segment<3>(3 * Eigen::Index(j)) = cc.candidate_displacements_m().col(Eigen::Index(j));
  }
  EXPECT_LT(RelativeError(u_cc, u_full), 1e-6);
  EXPECT_LT((r.spring_force_N - full.spring_force).norm() / full.spring_force.norm(), 1e-6);
  EXPECT_LT(RelativeError(r.sed_Pa, full.sed), 1e-6);
  EXPECT_GT(full.sed.maxCoeff(), 0.0);
}

TEST(ComplianceContact, SphereEqualsFullFePenaltySolve) {
  ExpectSameAsFullFe({SphereAbove(0.004, 0.0004)});
}

TEST(ComplianceContact, TiltedPlaneEqualsFullFePenaltySolve) { ExpectSameAsFullFe({PlaneAbove(0.0002)}); }

TEST(ComplianceContact, TwoObjectsEqualFullFePenaltySolve) {
  ExpectSameAsFullFe({SphereAbove(0.002, 0.0003, 0.25 * kSide), SphereAbove(0.002, 0.0002, 0.75 * kSide)});
}

// Face samples: contact points between candidate nodes, their compliance the interpolation
// of the nodes' (B W B^T), their force spread to the nodes by the same weights.
TEST(ComplianceContact, FaceSamplesAreInterpolatedContactPoints) {
  const TetMesh mesh = Block();
  const ComplianceContact nodes = MakeCompliance(mesh);
  const int c = int(nodes.candidate_nodes().size());
  ComplianceContactOptions o;
  o.face_samples = {{{0, 1, 2}, {0.5, 0.25, 0.25}}, {{3, 4, 5}, {0.2, 0.3, 0.5}}, {{1, 7, 9}, {1.0 / 3, 1.0 / 3, 1.0 / 3}}};
  ComplianceContact faces = MakeCompliance(mesh, o);
  ASSERT_EQ(faces.num_samples(), c + 3);
  const Eigen::MatrixXd& Wn = nodes.compliance_m_N();
  const Eigen::MatrixXd& Wf = faces.compliance_m_N();
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(3 * (c + 3), 3 * c);
  B.topRows(3 * c).setIdentity();
  for (int k = 0; k < 3; ++k)
    for (int a = 0; a < 3; ++a)
      B.block<3, 3>(3 * (c + k), 3 * o.face_samples[size_t(k)].candidate[size_t(a)]) +=
          o.face_samples[size_t(k)].weight[size_t(a)] * Eigen::Matrix3d::Identity();
  EXPECT_LT((Wf - B * Wn * B.transpose()).norm(), 1e-12 * Wn.norm());
  EXPECT_LT((Wf - Wf.transpose()).norm(), 1e-14 * Wf.norm());
  EXPECT_EQ(faces.sed_node_map_m_N(), nodes.sed_node_map_m_N());  // G stays over the nodes
  // A press answers, with its contacts named by sample, and its displacements are those
  // of its forces through the node-space products: u = B W_nodes B^T f (the same as the
  // sample-space W f).
  const ComplianceStepResult& r = faces.Step({SphereAbove(0.004, 0.0004)});
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_TRUE(r.converged);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * faces.num_samples());
  for (const auto& contact : r.contacts) {
    EXPECT_GE(contact.sample, 0);
    EXPECT_LT(contact.sample, faces.num_samples());
    f.segment<3>(3 * contact.sample) += contact.spring_force_N * contact.normal;
  }
  const Eigen::VectorXd u_nodes = (Wf * f).head(3 * c);
  Eigen::VectorXd u_cc(3 * c);
  for (int j = 0; j < c; ++j) u_cc.segment<3>(3 * j) = faces.candidate_displacements_m().col(j);
  EXPECT_LT((u_cc - u_nodes).norm(), 1e-6 * u_nodes.norm());
  // Bad samples are refused.
  for (const ContactSample& bad : {ContactSample{{0, 1, c}, {0.2, 0.3, 0.5}}, ContactSample{{0, 1, 2}, {0.5, 0.5, 0.5}},
                                   ContactSample{{0, 1, 2}, {1.5, -0.25, -0.25}}}) {
    ComplianceContactOptions b;
    b.face_samples = {bad};
    EXPECT_THROW(MakeCompliance(mesh, b), std::invalid_argument);
  }
}

// Far points are not evaluated again within a step when the object's SDF is 1-Lipschitz;
// the answer is the one of evaluating every point every iteration (the same sphere behind
// an SDF that does not promise it).
TEST(ComplianceContact, SkippingFarPointsGivesTheSameAnswer) {
  struct Unpromised final : geometry::SignedDistanceField {
    geometry::SphereSdf sphere{0.004};
    geometry::SdfSample Evaluate(const Eigen::Vector3d& p) const override { return sphere.Evaluate(p); }
    std::string Describe() const override { return "sphere, not promised Lipschitz"; }
  };
  const TetMesh mesh = Block();
  ComplianceContactOptions o;
  o.face_samples = {{{0, 1, 2}, {0.5, 0.25, 0.25}}, {{3, 4, 5}, {0.2, 0.3, 0.5}}};
  ComplianceContact skipping = MakeCompliance(mesh, o), evaluating = MakeCompliance(mesh, o);
  geometry::RigidObject promised = SphereAbove(0.004, 0.0004), unpromised = promised;
  unpromised.shape = std::make_shared<Unpromised>();
  ASSERT_TRUE(promised.shape->lipschitz());
  ASSERT_FALSE(unpromised.shape->lipschitz());
  for (double depth_mm : {0.1, 0.4, 0.6}) {
    promised.trajectory = unpromised.trajectory = SphereAbove(0.004, depth_mm * 1e-3).trajectory;
    const ComplianceStepResult a = skipping.Step({promised});
    const ComplianceStepResult b = evaluating.Step({unpromised});
    ASSERT_TRUE(a.ok && b.ok);
    EXPECT_TRUE(a.converged && b.converged);
    EXPECT_EQ(a.contacts.size(), b.contacts.size()) << depth_mm;
    EXPECT_LT((a.spring_force_N - b.spring_force_N).norm(), 1e-6 * b.spring_force_N.norm()) << depth_mm;
    EXPECT_LT(RelativeError(a.sed_Pa, b.sed_Pa), 1e-6) << depth_mm;
  }
}

TEST(ComplianceContact, NoContactGivesZeroAndRejectsNonFiniteInput) {
  const TetMesh mesh = Block();
  ComplianceContact cc = MakeCompliance(mesh);
  const ComplianceStepResult& r = cc.Step({SphereAbove(0.004, -0.001)});
  ASSERT_TRUE(r.ok);
  EXPECT_TRUE(r.contacts.empty());
  EXPECT_LT(r.sed_Pa.cwiseAbs().maxCoeff(), 1e-12);
  const ComplianceStepResult& bad = cc.Step({SphereAbove(0.004, 0.0002)}, 0.0, Eigen::Vector3d(NAN, 0, 0));
  EXPECT_FALSE(bad.ok);
  EXPECT_FALSE(bad.error.empty());
}

TEST(ComplianceContact, WarmStartReachesTheColdAnswerInFewerIterations) {
  const TetMesh mesh = Block();
  ComplianceContact warm = MakeCompliance(mesh), cold = MakeCompliance(mesh);
  warm.Step({SphereAbove(0.004, 0.00040)});
  const int warm_iterations = warm.Step({SphereAbove(0.004, 0.00041)}).iterations;
  const ComplianceStepResult& c = cold.Step({SphereAbove(0.004, 0.00041)});
  EXPECT_LT(warm_iterations, c.iterations);
  EXPECT_LT((warm.last().spring_force_N - c.spring_force_N).norm(), 1e-7 * c.spring_force_N.norm());
}

// The monotone fallback: a step whose accelerated iterations run out goes on unaccelerated
// and reaches the answer the accelerated solve reaches with room enough (the penalty law
// has one answer here); without the option, or under force control, a step that runs out
// stays unconverged as before.
TEST(ComplianceContact, MonotoneFallbackGoesOnWhereTheAcceleratedIterationsRanOutToTheSameAnswer) {
  const TetMesh mesh = Block();
  const std::vector<geometry::RigidObject> objects{SphereAbove(0.002, 0.0003, 0.25 * kSide),
                                                   SphereAbove(0.002, 0.0002, 0.75 * kSide)};
  ComplianceContact roomy = MakeCompliance(mesh);
  const ComplianceStepResult reference = roomy.Step(objects);
  ASSERT_TRUE(reference.converged);
  ASSERT_GE(reference.iterations, 3);
  EXPECT_EQ(roomy.qp_counts().monotone_fallbacks, 0u);  // off by default

  ComplianceContactOptions short_of_it;
  short_of_it.max_iterations = reference.iterations - 1;
  ComplianceContact without = MakeCompliance(mesh, short_of_it);
  EXPECT_FALSE(without.Step(objects).converged);
  EXPECT_EQ(without.qp_counts().monotone_fallbacks, 0u);

  short_of_it.monotone_fallback = true;
  ComplianceContact with = MakeCompliance(mesh, short_of_it);
  const ComplianceStepResult& r = with.Step(objects);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(with.qp_counts().monotone_fallbacks, 1u);
  EXPECT_GT(r.iterations, short_of_it.max_iterations);
  EXPECT_LE(r.iterations, 2 * short_of_it.max_iterations);
  EXPECT_EQ(r.contacts.size(), reference.contacts.size());
  EXPECT_LT((r.spring_force_N - reference.spring_force_N).norm(), 1e-7 * reference.spring_force_N.norm());
  EXPECT_LT(RelativeError(r.sed_Pa, reference.sed_Pa), 1e-7);
  // A converged step does not reach it.
  EXPECT_TRUE(with.Step(objects).converged);
  EXPECT_EQ(with.qp_counts().monotone_fallbacks, 1u);

  // Force control keeps its own way out (the caller's displacement-controlled steps).
  ComplianceContactOptions one;
  one.max_iterations = 1;
  one.monotone_fallback = true;
  ComplianceContact forced = MakeCompliance(mesh, one);
  ComplianceContact::ForceControl control;
  control.target_N = 0.5;
  forced.StepToForce({SphereAbove(0.004, 0.0)}, control);
  EXPECT_EQ(forced.qp_counts().monotone_fallbacks, 0u);
}

// Step after step the QP keeps W's columns for rows whose direction holds, reuses its last
// factor while its matrix is unchanged, and predicts Anderson's moves without W: each
// warm step must still give what a fresh instance gives for the same scene.
TEST(ComplianceContact, KeptColumnsReusedFactorAndCombinedPredictionsGiveTheColdAnswer) {
  const TetMesh mesh = Block();
  ComplianceContact warm = MakeCompliance(mesh);
  std::vector<std::vector<geometry::RigidObject>> scenes;
  for (double depth : {0.00020, 0.00020, 0.00021, 0.00026, 0.00021, 0.00020}) scenes.push_back({PlaneAbove(depth)});
  for (double x : {0.50, 0.52, 0.55, 0.60, 0.60, 0.58}) scenes.push_back({SphereAbove(0.004, 0.0004, x * kSide)});
  for (size_t k = 0; k < scenes.size(); ++k) {
    const ComplianceStepResult& w = warm.Step(scenes[k]);
    ASSERT_TRUE(w.ok && w.converged) << k;
    ComplianceContact cold = MakeCompliance(mesh);
    const ComplianceStepResult& c = cold.Step(scenes[k]);
    ASSERT_TRUE(c.ok && c.converged) << k;
    // A plane's normals are fixed: one QP, the same answer to rounding. A sphere's turn
    // with the skin, and warm and cold outer iterations stop at different points within
    // the solve's tolerance (1.6e-7 seen in displacement, also before these shortcuts).
    const double tolerance = k < 6 ? 1e-12 : 1e-6;
    EXPECT_EQ(w.contacts.size(), c.contacts.size()) << k;
    EXPECT_LT((w.spring_force_N - c.spring_force_N).norm(), tolerance * c.spring_force_N.norm()) << k;
    const Eigen::MatrixXd uw = warm.candidate_displacements_m(), uc = cold.candidate_displacements_m();
    EXPECT_LT((uw - uc).norm(), tolerance * uc.norm()) << k;
    // The warm plane's SED reads kept columns, rounded to float as G is (1.1e-8 seen).
    EXPECT_LT(RelativeError(w.sed_Pa, c.sed_Pa), std::max(tolerance, 1e-7)) << k;
  }
  // The shortcuts ran: the repeated plane on the last factor and kept columns, the moving
  // sphere's accelerated forces predicted by combination.
  const ComplianceQpCounts& n = warm.qp_counts();
  EXPECT_GT(n.factor_reuses, 0u);
  EXPECT_GT(n.columns_computed, 0u);
  EXPECT_GT(n.combined_predictions, 0u);
  EXPECT_LT(n.factorizations + n.factor_reuses, 2 * n.qps + 10 * scenes.size());
}

// The SED's kept columns (a node whose force keeps its direction goes through one column
// G(:, node) d instead of G's three, single precision as G) give the three-column SED to
// G's precision, with node and face contact and with a budget of three columns; they are
// computed only when a node's direction repeats (a plane's, not a moving sphere's), and a node that turns goes back to
// three columns until its new direction repeats.
TEST(ComplianceContact, KeptSedColumnsGiveTheThreeColumnSed) {
  const TetMesh mesh = Block();
  const double rows = 3.0 * double(MakeCompliance(mesh).sed_nodes().size());
  for (const char* variant : {"nodes", "faces", "three columns"}) {
    ComplianceContactOptions o;
    if (std::string(variant) == "faces")
      o.face_samples = {{{0, 1, 2}, {0.5, 0.25, 0.25}}, {{3, 4, 5}, {0.2, 0.3, 0.5}}, {{7, 8, 9}, {0.4, 0.3, 0.3}}};
    if (std::string(variant) == "three columns") o.sed_kept_columns_MiB = 3.5 * rows * 4 / 1048576;
    ComplianceContactOptions none = o;
    none.sed_kept_columns_MiB = 0;
    ComplianceContact kept = MakeCompliance(mesh, o), plain = MakeCompliance(mesh, none);
    auto step = [&](const std::vector<geometry::RigidObject>& scene) {
      const ComplianceStepResult& a = kept.Step(scene);
      const ComplianceStepResult& b = plain.Step(scene);
      ASSERT_TRUE(a.ok && a.converged && b.ok && b.converged) << variant;
      EXPECT_EQ(a.spring_force_N, b.spring_force_N) << variant;  // the SED does not feed back
      EXPECT_LT(RelativeError(a.sed_Pa, b.sed_Pa), 1e-6) << variant;  // G's precision
    };
    auto reads_of = [&](const std::vector<geometry::RigidObject>& scene) {
      const std::uint64_t before = kept.qp_counts().sed_kept_reads;
      step(scene);
      return kept.qp_counts().sed_kept_reads - before;
    };
    for (double depth : {0.00020, 0.00021, 0.00026}) step({PlaneAbove(depth)});
    const std::uint64_t plane_reads = reads_of({PlaneAbove(0.00020)});
    const ComplianceQpCounts after_plane = kept.qp_counts();
    EXPECT_GT(after_plane.sed_columns_kept, 0u) << variant;
    EXPECT_GT(after_plane.sed_kept_reads, 2 * after_plane.sed_columns_kept) << variant;
    if (std::string(variant) == "three columns") {
      EXPECT_EQ(plane_reads, 3u);
    } else {
      EXPECT_GE(plane_reads, after_plane.sed_columns_kept) << variant;  // every loaded node
    }
    for (double x : {0.50, 0.52, 0.55, 0.60}) step({SphereAbove(0.004, 0.0004, x * kSide)});
    EXPECT_EQ(kept.qp_counts().sed_columns_kept, after_plane.sed_columns_kept) << variant;
    EXPECT_EQ(kept.qp_counts().sed_kept_reads, after_plane.sed_kept_reads) << variant;
    if (std::string(variant) != "three columns") {
      // The nodes the sphere turned take three columns, the others their kept ones; the
      // next plane step finds every node along the plane's normal again.
      const std::uint64_t turned = reads_of({PlaneAbove(0.00020)});
      EXPECT_LT(turned, plane_reads) << variant;
      EXPECT_EQ(reads_of({PlaneAbove(0.00021)}), plane_reads) << variant;
    }
    EXPECT_EQ(plain.qp_counts().sed_columns_kept + plain.qp_counts().sed_kept_reads, 0u) << variant;
  }
  // A budget that is not a positive size keeps nothing; a huge one is the whole G.
  for (const double budget_MiB : {-1.0, std::nan(""), 1e300}) {
    ComplianceContactOptions o, none;
    o.sed_kept_columns_MiB = budget_MiB;
    none.sed_kept_columns_MiB = 0;
    ComplianceContact odd = MakeCompliance(mesh, o), plain = MakeCompliance(mesh, none);
    for (double depth : {0.00020, 0.00021, 0.00022}) {
      const ComplianceStepResult& a = odd.Step({PlaneAbove(depth)});
      const ComplianceStepResult& b = plain.Step({PlaneAbove(depth)});
      ASSERT_TRUE(a.ok && b.ok) << budget_MiB;
      EXPECT_LT(RelativeError(a.sed_Pa, b.sed_Pa), 1e-6) << budget_MiB;
    }
    EXPECT_EQ(odd.qp_counts().sed_columns_kept > 0, budget_MiB > 0) << budget_MiB;
  }
}

TEST(ComplianceContact, TangentialLoadIsCarriedByTheContactsAndShearsTheBlock) {
  const TetMesh mesh = Block();
  ComplianceContact cc = MakeCompliance(mesh);
  const Eigen::Vector3d shear(0.05, 0, 0);
  const ComplianceStepResult& r = cc.Step({SphereAbove(0.004, 0.0004)}, 0.0, shear);
  ASSERT_TRUE(r.ok && r.converged);
  EXPECT_EQ(r.tangential_force_N, shear);
  // The contact nodes move along +x on average; without contact the load is not applied.
  double mean_ux = 0;
  for (const auto& c : r.contacts) {
    const auto& nodes = cc.candidate_nodes();
    const auto j = std::find(nodes.begin(), nodes.end(), c.node) - nodes.begin();
    mean_ux += cc.candidate_displacements_m()(0, j) / double(r.contacts.size());
  }
  EXPECT_GT(mean_ux, 1e-6);
  const ComplianceStepResult& none = cc.Step({SphereAbove(0.004, -0.001)}, 0.0, shear);
  EXPECT_TRUE(none.tangential_force_N.isZero());
  EXPECT_EQ(cc.candidate_displacements_m().norm(), 0.0);
}

// A load held on the contact points (a display's suction): alone it displaces the points by
// W f, and its SED is the one the same forces give as contact forces (the SED is from all
// forces); cleared, the contact is bit for bit as if it had never been set.
TEST(ComplianceContact, SampleLoadAloneIsWTimesTheLoadWithTheSedOfTheSameContactForces) {
  const TetMesh mesh = Block();
  ComplianceContact pressed = MakeCompliance(mesh), loaded = MakeCompliance(mesh), never = MakeCompliance(mesh);
  const ComplianceStepResult& r = pressed.Step({SphereAbove(0.004, 0.0004)});
  ASSERT_TRUE(r.ok && r.converged);
  ASSERT_GT(r.contacts.size(), 3u);
  const int c = loaded.num_samples();
  Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, c);
  for (const ActiveContact& a : r.contacts) f.col(a.sample) += a.spring_force_N * a.normal;
  loaded.SetSampleLoads(f);
  EXPECT_TRUE(loaded.has_sample_loads());
  const ComplianceStepResult& l = loaded.Step({});
  ASSERT_TRUE(l.ok && l.converged) << l.error;
  EXPECT_TRUE(l.contacts.empty());
  EXPECT_LT((l.sample_load_N - r.spring_force_N).norm(), 1e-12 * r.spring_force_N.norm());
  const Eigen::VectorXd f_vec = Eigen::Map<const Eigen::VectorXd>(f.data(), 3 * c);
  const Eigen::VectorXd w_f = loaded.compliance_m_N() * f_vec;
  const Eigen::Map<const Eigen::VectorXd> u(loaded.candidate_displacements_m().data(), 3 * c);
  EXPECT_LT(RelativeError(u, w_f), 1e-12);
  // The pressed step's own displacements are W times its last iterate's forces, which
  // differ from the reported k * depth within the penalty law's tolerance (1e-8).
  const Eigen::Map<const Eigen::VectorXd> u_pressed(pressed.candidate_displacements_m().data(), 3 * c);
  EXPECT_LT(RelativeError(u, u_pressed), 1e-6);
  EXPECT_LT(RelativeError(l.sed_Pa, r.sed_Pa), 1e-6);
  EXPECT_GT(l.sed_Pa.maxCoeff(), 0.0);

  // Cleared (or set to zero): the same answer as an instance that never held one.
  loaded.SetSampleLoads(Eigen::Matrix3Xd::Zero(3, c));
  EXPECT_FALSE(loaded.has_sample_loads());
  loaded.ResetWarmStart();
  const Eigen::VectorXd sed_loaded = loaded.Step({SphereAbove(0.004, 0.0003)}).sed_Pa;
  const Eigen::VectorXd sed_never = never.Step({SphereAbove(0.004, 0.0003)}).sed_Pa;
  EXPECT_EQ(sed_loaded, sed_never);
  EXPECT_THROW(loaded.SetSampleLoads(Eigen::Matrix3Xd::Zero(3, c - 1)), std::invalid_argument);
  Eigen::Matrix3Xd bad = Eigen::Matrix3Xd::Zero(3, c);
  bad(2, 0) = NAN;
  EXPECT_THROW(loaded.SetSampleLoads(bad), std::invalid_argument);
  ComplianceContact::ForceControl control;
  control.target_N = 0.1;
  loaded.SetSampleLoads(f);
  EXPECT_FALSE(loaded.StepToForce({SphereAbove(0.004, 0.0)}, control).ok);
}

// Force balance against a fixed rigid plate: the top pressed flat by exact contact cannot
// move, so a load pulling contact points toward the plate is carried by the plate alone:
// each loaded point's contact force grows by its load, and nothing else changes.
TEST(ComplianceContact, SampleLoadTowardAFixedPlateIsCarriedByItsContactForces) {
  const TetMesh mesh = Block();
  ComplianceContactOptions o;
  o.exact_contact = true;
  ComplianceContact cc = MakeCompliance(mesh, o);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::Vector3d(1, -1, -1).asDiagonal();  // normal -z, solid above
  pose.translation() = Eigen::Vector3d(0.5 * kSide, 0.5 * kSide, kHeight - 0.0002);
  const std::vector<geometry::RigidObject> plate{{"plate", std::make_shared<geometry::PlaneSdf>(), geometry::Trajectory(pose)}};
  const ComplianceStepResult before = cc.Step(plate);
  ASSERT_TRUE(before.ok && before.converged);
  const int c = cc.num_samples();
  ASSERT_EQ(int(before.contacts.size()), c);  // the whole top touches
  const Eigen::VectorXd u_before = Eigen::Map<const Eigen::VectorXd>(cc.candidate_displacements_m().data(), 3 * c);
  Eigen::Matrix3Xd f = Eigen::Matrix3Xd::Zero(3, c);
  f(2, c / 2) = 0.02, f(2, c / 3) = 0.01;  // toward the plate [N]
  cc.SetSampleLoads(f);
  const ComplianceStepResult after = cc.Step(plate);
  ASSERT_TRUE(after.ok && after.converged) << after.error;
  EXPECT_NEAR(after.spring_force_N.z() - before.spring_force_N.z(), -0.03, 1e-9);
  EXPECT_LT((after.sample_load_N - Eigen::Vector3d(0, 0, 0.03)).norm(), 1e-15);
  std::vector<double> force_before(size_t(c), 0.0), force_after(size_t(c), 0.0);
  for (const ActiveContact& a : before.contacts) force_before[size_t(a.sample)] = a.spring_force_N;
  for (const ActiveContact& a : after.contacts) force_after[size_t(a.sample)] = a.spring_force_N;
  for (int j = 0; j < c; ++j) EXPECT_NEAR(force_after[size_t(j)] - force_before[size_t(j)], f(2, j), 1e-9) << j;
  const Eigen::Map<const Eigen::VectorXd> u_after(cc.candidate_displacements_m().data(), 3 * c);
  EXPECT_LT((u_after - u_before).norm(), 1e-9 * u_before.norm());
  EXPECT_LT(RelativeError(after.sed_Pa, before.sed_Pa), 1e-9);
}

// Exact contact is the penalty law's limit k -> infinity: no penetration, a force only
// where the gap is closed, and the penalty answer approaches it from below as k grows.
void ExpectExactContact(const geometry::RigidObject& object) {
  const TetMesh mesh = Block();
  ComplianceContactOptions exact_options;
  exact_options.exact_contact = true;
  ComplianceContact exact = MakeCompliance(mesh, exact_options);
  const ComplianceStepResult& r = exact.Step({object});
  ASSERT_TRUE(r.ok && r.converged) << r.error;
  ASSERT_GT(r.contacts.size(), 3u);
  // Gaps at the final positions: >= 0 everywhere, ~0 where there is a force.
  std::set<int> touching;
  for (const auto& c : r.contacts) {
    EXPECT_GT(c.normal_force_N, 0.0);
    touching.insert(c.node);
  }
  for (size_t j = 0; j < exact.candidate_nodes().size(); ++j) {
    const Eigen::Vector3d x = mesh.rest_positions_m.col(exact.candidate_nodes()[j]) +
                              exact.candidate_displacements_m().col(Eigen::Index(j));
    const double gap = object.Evaluate(x, 0.0).distance_m;
    EXPECT_GT(gap, -1e-10);
    if (touching.count(exact.candidate_nodes()[j])) EXPECT_LT(std::abs(gap), 1e-10);
  }
  double previous = 0;
  for (double k : {1e4, 1e6, 1e8}) {
    ComplianceContactOptions o;
    ComplianceContact penalty(mesh, BlockTerms(mesh), testing::NodesWhere(mesh, 2, kHeight), SedVertices(mesh),
                              [&] { o.stiffness_N_m = k; return o; }());
    const double f = penalty.Step({object}).spring_force_N.norm();
    EXPECT_GT(f, previous);
    previous = f;
  }
  EXPECT_LT(std::abs(previous - r.spring_force_N.norm()) / r.spring_force_N.norm(), 1e-3);
}

TEST(ComplianceContact, ExactContactPlaneIsThePenaltyLimit) { ExpectExactContact(PlaneAbove(0.0002)); }
TEST(ComplianceContact, ExactContactSphereIsThePenaltyLimit) { ExpectExactContact(SphereAbove(0.004, 0.0004)); }

// Pseudo friction: a plane pressed (step 1), then slid along itself (step 2) drags the
// anchored contacts; the quasi-static full FE with PseudoFrictionForce is the reference.
std::vector<std::unique_ptr<ForceTerm>> FixedBottomTerms(const TetMesh& mesh) {
  std::vector<std::unique_ptr<ForceTerm>> terms;
  terms.push_back(std::make_unique<ElasticTetForce>(mesh, ElasticFormulation::kLinear));
  const auto bottom = testing::NodesWhere(mesh, 2, 0.0);
  terms.push_back(std::make_unique<BoneCouplingForce>(mesh.rest_positions_m, bottom, std::vector<Eigen::Vector3d>{},
                                                      SpringDamperParams{1e6, 0.0, 1.0}));
  return terms;
}

void ExpectFrictionLikeFullFe(const geometry::RigidObject& pressed) {
  constexpr double mu = 0.0;  // sticking springs (the compliance solver has no Coulomb cap)
  const TetMesh mesh = Block();
  const Eigen::Isometry3d pose0 = pressed.trajectory.Pose(0.0);
  std::vector<geometry::PoseKeyframe> keys(3);
  keys[0].t_s = 0, keys[1].t_s = 1, keys[2].t_s = 2;
  for (auto& key : keys) key.position_m = pose0.translation(), key.orientation = Eigen::Quaterniond(pose0.linear());
  keys[2].position_m.x() += 2e-5;  // slide along x (in the tilted plane: its tilt is about x)
  const std::vector<geometry::RigidObject> objects{{"plane", pressed.shape, geometry::Trajectory(keys)}};
  constexpr double kA = 0.3;

  auto terms = FixedBottomTerms(mesh);
  const auto top = testing::NodesWhere(mesh, 2, kHeight);
  terms.push_back(std::make_unique<PenaltyContactForce>(top, objects, ContactParams{kContactK, 0.0}));
  auto* contact = static_cast<PenaltyContactForce*>(terms.back().get());
  terms.push_back(std::make_unique<PseudoFrictionForce>(*contact, kA, mu));
  auto* friction = static_cast<PseudoFrictionForce*>(terms.back().get());
  IntegratorSettings settings;
  settings.kind = IntegratorKind::kQuasiStatic;
  settings.newton_iterations = 200;
  settings.newton_tolerance_m = 1e-15;
  Simulation sim(mesh, std::move(terms), settings, MakeLinearSolver("ldlt", {}));

  ComplianceContactOptions o;
  o.stiffness_N_m = kContactK;
  o.friction_anisotropy = kA;
  o.max_iterations = 200;
  ComplianceContact cc(mesh, FixedBottomTerms(mesh), top, SedVertices(mesh), o);
  for (double t : {1.0, 2.0}) {
    SCOPED_TRACE("t = " + std::to_string(t));
    EXPECT_TRUE(sim.Step(1.0).converged);
    sim.TotalForce();
    const ComplianceStepResult& r = cc.Step(objects, t);
    ASSERT_TRUE(r.ok) << r.error;
    EXPECT_TRUE(r.converged);
    cc.EndStep();
    Eigen::VectorXd u_full(3 * top.size()), u_cc(u_full.size());
    for (size_t j = 0; j < top.size(); ++j) {
      u_full.segment<3>(3 * Eigen::Index(j)) = sim.positions_m().segment<3>(3 * top[j]) - mesh.rest_positions_m.col(top[j]);
      u_cc.segment<3>(3 * Eigen::Index(j)) = cc.candidate_displacements_m().col(Eigen::Index(j));
    }
    EXPECT_LT(RelativeError(u_cc, u_full), 1e-6);
    EXPECT_LT((r.spring_force_N - contact->TotalSpringForce()).norm() / contact->TotalSpringForce().norm(), 1e-6);
    EXPECT_EQ(cc.num_anchors(), friction->num_anchors());
  }
  EXPECT_GT(cc.last().friction_force_N.norm(), 1e-3 * cc.last().spring_force_N.norm());  // friction did act
}

TEST(ComplianceContact, StickingFrictionPlaneEqualsFullFe) { ExpectFrictionLikeFullFe(PlaneAbove(0.0002)); }
TEST(ComplianceContact, StickingFrictionSphereEqualsFullFe) { ExpectFrictionLikeFullFe(SphereAbove(0.004, 0.0004)); }

TEST(ComplianceContact, RefusesCorotationalModel) {
  const TetMesh mesh = Block();
  std::vector<std::unique_ptr<ForceTerm>> terms;
  terms.push_back(std::make_unique<ElasticTetForce>(mesh, ElasticFormulation::kCorotational));
  testing::AddRollerSupport(mesh, terms, 1e6);
  EXPECT_THROW(ComplianceContact(mesh, std::move(terms), testing::NodesWhere(mesh, 2, kHeight), {}),
               std::invalid_argument);
}

class ComplianceCache : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("compliance_cache_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  ComplianceContactOptions Options() const {
    ComplianceContactOptions o;
    o.cache_dir = dir_.string();
    return o;
  }
  std::filesystem::path dir_;
};

TEST_F(ComplianceCache, RoundTripGivesIdenticalResults) {
  const TetMesh mesh = Block();
  const std::vector<geometry::RigidObject> sphere{SphereAbove(0.004, 0.0004)};
  ComplianceContact first = MakeCompliance(mesh, Options());
  EXPECT_FALSE(first.loaded_from_cache());
  ASSERT_TRUE(std::filesystem::exists(first.cache_file()));
  ComplianceContact second = MakeCompliance(mesh, Options());
  EXPECT_TRUE(second.loaded_from_cache());
  EXPECT_EQ(second.cache_file(), first.cache_file());
  EXPECT_EQ(first.compliance_m_N(), second.compliance_m_N());
  EXPECT_EQ(first.sed_node_map_m_N(), second.sed_node_map_m_N());
  const Eigen::VectorXd sed = first.Step(sphere).sed_Pa;
  EXPECT_EQ(second.Step(sphere).sed_Pa, sed);
  // A different model (stiffer material) must not pick up this file.
  TetMesh stiffer = Block();
  stiffer.materials[0].youngs_modulus_Pa *= 2;
  ComplianceContact other = MakeCompliance(stiffer, Options());
  EXPECT_FALSE(other.loaded_from_cache());
  EXPECT_NE(other.cache_file(), first.cache_file());
}

TEST_F(ComplianceCache, CorruptFileIsRejectedAndRebuilt) {
  const TetMesh mesh = Block();
  const std::vector<geometry::RigidObject> sphere{SphereAbove(0.004, 0.0004)};
  ComplianceContact first = MakeCompliance(mesh, Options());
  const Eigen::VectorXd sed = first.Step(sphere).sed_Pa;
  const std::string file = first.cache_file();
  {  // flip one byte in the middle of the payload
    std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(0, std::ios::end);
    const auto size = f.tellg();
    f.seekp(size / 2);
    char byte = 0;
    f.seekg(size / 2);
    f.read(&byte, 1);
    byte = char(byte ^ 0x5a);
    f.seekp(size / 2);
    f.write(&byte, 1);
  }
  ComplianceContact rebuilt = MakeCompliance(mesh, Options());
  EXPECT_FALSE(rebuilt.loaded_from_cache());
  EXPECT_NE(rebuilt.cache_rejected_reason(), "");
  EXPECT_EQ(rebuilt.Step(sphere).sed_Pa, sed);
  ComplianceContact again = MakeCompliance(mesh, Options());  // the rewritten file is good
  EXPECT_TRUE(again.loaded_from_cache());
  // A truncated file too.
  std::filesystem::resize_file(file, std::filesystem::file_size(file) / 3);
  ComplianceContact truncated = MakeCompliance(mesh, Options());
  EXPECT_FALSE(truncated.loaded_from_cache());
  EXPECT_EQ(truncated.Step(sphere).sed_Pa, sed);
}

}  // namespace
}  // namespace sedbridge::fem
