// The simulated pad's elastic half-space and layer against closed forms: Love's uniformly
// loaded square, Hertz's sphere, the thin layer's confined columns, the thick layer's half-space.
#include "sensors/simulated/elastic_pad_contact.h"
#include "sensors/simulated/bessel.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace sedbridge::sensors {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(ElasticPadContact, SquareCentreDeflectionIsLoves) {
  // A square of side 2c under pressure p sinks 8 ln(1 + sqrt 2) / pi * c p / E* at its
  // centre (Johnson, Contact Mechanics §3.9: 2.24 c p / E*); far away, as a point load
  // P / (pi E* r).
  const double cell_m = 0.2e-3, e_star = 313e3, c = 0.5 * cell_m;
  const ElasticPadContact h(cell_m, e_star);
  EXPECT_NEAR(h.Influence(0, 0), 8 * std::log(1 + std::sqrt(2.0)) / kPi * c / e_star, 1e-12 * c / e_star);
  EXPECT_NEAR(h.Influence(0, 0) * e_star / c, 2.244, 1e-3);
  const double far = h.Influence(30, 40);
  const double point = cell_m * cell_m / (kPi * e_star * 50 * cell_m);
  EXPECT_NEAR(far / point, 1.0, 1e-3);
  EXPECT_DOUBLE_EQ(h.Influence(3, 4), h.Influence(4, 3));
}

TEST(ElasticPadContact, SpherePressIsHertz) {
  // R = 5 mm, 0.2 mm deep into E* = 313 kPa: F = 4/3 E* sqrt(R) d^1.5 = 0.0834 N, contact
  // radius a = sqrt(R d) = 1 mm, centre pressure 3 F / (2 pi a^2). The geometric overlap
  // (radius sqrt(2 R d) = 1.41 mm) is wider than the contact: the pivoting must find a.
  const double cell_m = 0.125e-3, e_star = 313e3, R = 5e-3, depth = 0.2e-3;
  const int n = 25, centre = 12;
  std::vector<double> penetration(n * n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double r2 = (std::pow(i - centre, 2) + std::pow(j - centre, 2)) * cell_m * cell_m;
      penetration[size_t(i * n + j)] = depth - r2 / (2 * R);
    }
  ElasticPadContact h(cell_m, e_star);
  std::vector<double> p;
  ASSERT_TRUE(h.Solve(n, penetration, &p));
  double force = 0, outer_m = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double pij = p[size_t(i * n + j)];
      EXPECT_GE(pij, 0.0);
      force += pij * cell_m * cell_m;
      if (pij > 0) outer_m = std::max(outer_m, std::hypot(i - centre, j - centre) * cell_m);
    }
  const double hertz_N = 4.0 / 3.0 * e_star * std::sqrt(R) * std::pow(depth, 1.5);
  const double a = std::sqrt(R * depth);
  EXPECT_NEAR(force / hertz_N, 1.0, 0.03);
  EXPECT_NEAR(outer_m, a, 1.0 * cell_m);
  EXPECT_NEAR(p[size_t(centre * n + centre)] / (3 * hertz_N / (2 * kPi * a * a)), 1.0, 0.05);
  // Warm-started again: the same answer; nothing touching: no pressure.
  std::vector<double> again;
  ASSERT_TRUE(h.Solve(n, penetration, &again));
  for (size_t k = 0; k < p.size(); ++k) EXPECT_NEAR(again[k], p[k], 1e-9 * p[size_t(centre * n + centre)]);
  std::vector<double> apart(penetration.size(), -1e-4);
  ASSERT_TRUE(h.Solve(n, apart, &again));
  for (double v : again) EXPECT_EQ(v, 0.0);
  EXPECT_EQ(h.failures(), 0);
}

TEST(Bessel, ApproximationsMatchTheLibraryTo1e7) {
  for (double x = 0; x < 200; x += 0.01) {
    ASSERT_NEAR(BesselJ0(x), std::cyl_bessel_j(0.0, x), 1e-7) << x;
    const double j1_over_x = x > 0 ? std::cyl_bessel_j(1.0, x) / x : 0.5;
    ASSERT_NEAR(BesselJ1OverX(x), j1_over_x, 1e-7) << x;
  }
  EXPECT_EQ(BesselJ0(-2.5), BesselJ0(2.5));
}

// Deflection at the centre of a (2 half + 1)^2-cell square under unit pressure.
double CentreDeflection(const ElasticPadContact& h, int half) {
  double w = 0;
  for (int i = -half; i <= half; ++i)
    for (int j = -half; j <= half; ++j) w += h.Influence(i, j);
  return w;
}

TEST(ElasticPadContact, ThinLayerUnderAWideLoadIsAConfinedColumn) {
  // A layer 1 mm thick under pressure 40 mm wide: away from the edges each column is
  // compressed with its sides held, w = p h / E_oed, E_oed = E (1 - nu) / ((1 + nu)(1 - 2 nu))
  // = E* (1 - nu)^2 / (1 - 2 nu) (Winkler's foundation, the thin limit of the layer).
  const double cell_m = 0.25e-3, e_star = 313e3, h_m = 1e-3;
  for (double nu : {0.0, 0.3, 0.45}) {
    const ElasticPadContact layer(cell_m, e_star, {h_m, nu});
    const double e_oed = e_star * (1 - nu) * (1 - nu) / (1 - 2 * nu);
    EXPECT_NEAR(CentreDeflection(layer, 80) / (h_m / e_oed), 1.0, 0.01) << "nu " << nu;
    EXPECT_EQ(layer.Influence(0, 101), 0.0);  // beyond 25 h: the layer's reach
  }
}

// Against CalculiX: a layer of thickness h bonded to a rigid base under a uniform pressure
// p on a disk of radius c, centre deflection w in units of p c / E*, by axisymmetric
// quadratic elements out to 40 h (tools/ccx/layer_reference.py; ccx 2.20, the same to 5
// digits with the mesh refined twice, 2026-11-26). The layer's table sums over a pixelated
// disk of cells c / 25 wide; measured within 0.01-0.6 % of ccx (the half-space's exact 2
// less 0.6 % is the pixelated disk's).
TEST(ElasticPadContact, LayerMatchesCalculixUnderADiskLoad) {
  struct Case {
    double h_over_c, nu, ccx;
  };
  const Case cases[] = {{0.5, 0.2, 0.47480}, {1, 0.2, 0.92450}, {2, 0.2, 1.38605}, {4, 0.2, 1.68110},
                        {1, 0.45, 0.69607}, {2, 0.45, 1.23592}, {100, 0.2, 1.98707}};
  const double c = 1e-3, e_star = 313e3, cell = c / 25;
  for (const Case& k : cases) {
    const ElasticPadContact layer(cell, e_star, {k.h_over_c * c, k.nu});
    double w = 0;
    for (int i = -25; i <= 25; ++i)
      for (int j = -25; j <= 25; ++j)
        if (std::hypot(i, j) * cell < c) w += layer.Influence(i, j);
    EXPECT_NEAR(w * e_star / c / k.ccx, 1.0, 0.01) << "h/c " << k.h_over_c << " nu " << k.nu;
  }
}

TEST(ElasticPadContact, ThickLayerIsTheHalfSpace) {
  const double cell_m = 0.25e-3, e_star = 313e3;
  // 100 m thick: within r of a load, a layer deflects as the half-space less a shift of
  // order r / h relative (the base's), here < 1e-4.
  const ElasticPadContact half_space(cell_m, e_star), thick(cell_m, e_star, {100.0, 0.45});
  for (int i : {0, 1, 7, 40}) EXPECT_NEAR(thick.Influence(i, 3) / half_space.Influence(i, 3), 1.0, 1e-3) << i;
  EXPECT_NEAR(LayerCorrection_m_per_Pa(0, 1e-4, e_star, {}), 0.0, 0.0);  // no layer, no correction
}

TEST(ElasticPadContact, LayerSphereTendsToTheHalfSpacesAndStiffensAsTheLayerThins) {
  // A sphere pressed 0.2 mm (Hertz contact radius a = 1 mm): a 1 m layer carries the
  // half-space's force; thinner layers, propped by the base, carry more at the same depth
  // (a / h = 0.1 already +12 % for nu = 0.45), and a 1 mm layer several times Hertz's.
  const double cell_m = 0.125e-3, e_star = 313e3, R = 5e-3, depth = 0.2e-3;
  const int n = 25, centre = 12;
  std::vector<double> penetration(n * n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      penetration[size_t(i * n + j)] =
          depth - (std::pow(i - centre, 2) + std::pow(j - centre, 2)) * cell_m * cell_m / (2 * R);
  auto force_N = [&](ElasticPadContact& contact) {
    std::vector<double> p;
    EXPECT_TRUE(contact.Solve(n, penetration, &p));
    double f = 0;
    for (double v : p) f += v * cell_m * cell_m;
    return f;
  };
  ElasticPadContact half_space(cell_m, e_star);
  const double half_space_N = force_N(half_space);
  double last_N = 0;
  for (double h_mm : {1000.0, 30.0, 10.0, 3.0, 1.0}) {
    ElasticPadContact layer(cell_m, e_star, {h_mm * 1e-3, 0.45});
    const double f = force_N(layer);
    if (h_mm == 1000.0) {
      EXPECT_NEAR(f / half_space_N, 1.0, 0.005);
    }
    EXPECT_GT(f, last_N * 1.02) << h_mm;
    last_N = f;
  }
  EXPECT_GT(last_N, 3 * half_space_N);
}

}  // namespace
}  // namespace sedbridge::sensors
