#include "sensors/simulated/elastic_pad_contact.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sensors/simulated/bessel.h"

namespace sedbridge::sensors {

namespace {

constexpr double kPi = 3.14159265358979323846;
// Active-set changes before the iteration is given up (a contact settles in a handful).
constexpr int kMaxPivotRounds = 60;

// Love's term: x ln((y + r(x, y)) / (y' + r(x, y'))) for the rectangle's corner pair.
double Term(double x, double y_hi, double y_lo) {
  return x * std::log((y_hi + std::hypot(x, y_hi)) / (y_lo + std::hypot(x, y_lo)));
}

// The layer's reach [thicknesses]: a bonded layer's deflection under a load decays
// exponentially beyond a few h; past this, the influence is taken as zero.
constexpr double kLayerReach = 25;
// Correction table entries per thickness: its transform lives below k ~ 10 / h, so the
// correction is smooth on h / 10 and linear interpolation on h / 20 is well inside 1e-3.
constexpr double kLayerTablePerThickness = 20;
// Hankel integration: up to t = kh = 20 (C - 1 ~ t^2 e^-2t is below 1e-14 there), at least
// 30 Simpson points per period of the Bessel functions' oscillation.
constexpr double kLayerTMax = 20;
constexpr double kPointsPerPeriod = 30;

// C(t) - 1 for the bonded layer (header), in a form that neither overflows nor cancels.
double LayerCMinusOne(double t, double nu) {
  const double a = 3 - 4 * nu, s = 5 - 12 * nu + 8 * nu * nu;
  const double e = std::exp(-2 * t);
  const double den = 0.5 * a * (1 / e + e) + 2 * t * t + s;
  return (-a * e - 2 * t - 2 * t * t - s) / den;
}

// Simpson nodes and weights on [0, kLayerTMax] fine enough for offsets up to r_max.
void HankelGrid(double r_max_over_h, std::vector<double>* t, std::vector<double>* w) {
  int n = static_cast<int>(std::ceil(kLayerTMax * kPointsPerPeriod * (r_max_over_h + 1) / (2 * kPi)));
  n = std::max(64, n + (n & 1));
  const double dt = kLayerTMax / n;
  t->resize(static_cast<size_t>(n) + 1);
  w->resize(t->size());
  for (int i = 0; i <= n; ++i) {
    (*t)[static_cast<size_t>(i)] = i * dt;
    (*w)[static_cast<size_t>(i)] = dt / 3 * (i == 0 || i == n ? 1 : (i % 2 ? 4 : 2));
  }
}

// The r-independent part of the layer's Hankel sum: w_i J1(t_i c / h) / t_i (C(t_i) - 1),
// with J1(tc/h) / t = (c / h) J1(x) / x.
std::vector<double> LayerWeights(const std::vector<double>& t, const std::vector<double>& w, double disk_m,
                                 const ElasticLayer& layer) {
  const double c_over_h = disk_m / layer.thickness_m;
  std::vector<double> out(t.size());
  for (size_t i = 0; i < t.size(); ++i)
    out[i] = w[i] * c_over_h * BesselJ1OverX(t[i] * c_over_h) * LayerCMinusOne(t[i], layer.poisson_ratio);
  return out;
}

// (2 c / E*) sum_i weight_i J0(t_i r / h).
double LayerCorrectionOn(const std::vector<double>& t, const std::vector<double>& weight, double r_m, double disk_m,
                         double contact_modulus_Pa, const ElasticLayer& layer) {
  const double r_over_h = r_m / layer.thickness_m;
  double sum = 0;
  for (size_t i = 0; i < t.size(); ++i) sum += weight[i] * BesselJ0(t[i] * r_over_h);
  return 2 * disk_m / contact_modulus_Pa * sum;
}

}  // namespace

double LayerCorrection_m_per_Pa(double r_m, double disk_m, double contact_modulus_Pa, const ElasticLayer& layer) {
  if (!(layer.thickness_m > 0)) return 0;
  std::vector<double> t, w;
  HankelGrid(r_m / layer.thickness_m + disk_m / layer.thickness_m, &t, &w);
  return LayerCorrectionOn(t, LayerWeights(t, w, disk_m, layer), r_m, disk_m, contact_modulus_Pa, layer);
}

ElasticPadContact::ElasticPadContact(double cell_m, double contact_modulus_Pa, ElasticLayer layer)
    : cell_m_(cell_m), contact_modulus_Pa_(contact_modulus_Pa) {
  if (!(cell_m > 0) || !(contact_modulus_Pa > 0))
    throw std::invalid_argument("ElasticPadContact: cell size and contact modulus must be positive");
  if (!(layer.thickness_m >= 0) || !(layer.poisson_ratio >= 0 && layer.poisson_ratio <= 0.5))
    throw std::invalid_argument("ElasticPadContact: layer thickness must be >= 0 and Poisson's ratio in [0, 0.5]");
  if (layer.thickness_m > 0) {
    const double h = layer.thickness_m, disk_m = cell_m / std::sqrt(kPi);  // the cell's area
    const int entries = static_cast<int>(kLayerReach * kLayerTablePerThickness) + 1;
    correction_step_m_ = h / kLayerTablePerThickness;
    std::vector<double> t, w;
    HankelGrid(kLayerReach + disk_m / h, &t, &w);
    const std::vector<double> weight = LayerWeights(t, w, disk_m, layer);
    correction_.resize(static_cast<size_t>(entries));
    for (int k = 0; k < entries; ++k)
      correction_[static_cast<size_t>(k)] =
          LayerCorrectionOn(t, weight, k * correction_step_m_, disk_m, contact_modulus_Pa, layer);
  }
}

double ElasticPadContact::Influence(int di, int dj) const {
  // Deflection at (x, y) under unit pressure on |xi| <= c, |eta| <= c (Love 1929):
  // u = 1 / (pi E*) [ (x+c) ln(..) + (y+c) ln(..) + (x-c) ln(..) + (y-c) ln(..) ].
  // Cell centres sit at whole multiples of 2c, so no x +- c or y +- c is zero.
  const double c = 0.5 * cell_m_;
  const double x = di * cell_m_, y = dj * cell_m_;
  const double sum = Term(x + c, y + c, y - c) + Term(y + c, x + c, x - c) + Term(x - c, y - c, y + c) +
                     Term(y - c, x - c, x + c);
  const double love = sum / (kPi * contact_modulus_Pa_);
  if (correction_.empty()) return love;
  const double at = std::hypot(x, y) / correction_step_m_;
  const size_t k = static_cast<size_t>(at);
  if (k + 1 >= correction_.size()) return 0;  // beyond the layer's reach
  const double f = at - static_cast<double>(k);
  return love + (1 - f) * correction_[k] + f * correction_[k + 1];
}

bool ElasticPadContact::Solve(int n, const std::vector<double>& penetration_m, std::vector<double>* pressure_Pa) {
  const int cells = n * n;
  pressure_Pa->assign(static_cast<size_t>(cells), 0.0);
  std::vector<int> candidates;
  for (int k = 0; k < cells; ++k)
    if (penetration_m[static_cast<size_t>(k)] > 0) candidates.push_back(k);
  if (last_n_ != n) last_active_.assign(static_cast<size_t>(cells), 1), last_n_ = n;
  if (candidates.empty()) return true;
  const int m = static_cast<int>(candidates.size());
  // The influence among the candidates (translation invariant: one table by offset).
  if (table_n_ != n) {
    table_.resize(static_cast<size_t>(n) * n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) table_[static_cast<size_t>(i) * n + j] = Influence(i, j);
    table_n_ = n;
  }
  const std::vector<double>& table = table_;
  Eigen::MatrixXd K(m, m);
  for (int a = 0; a < m; ++a)
    for (int b = 0; b < m; ++b) {
      const int ia = candidates[a] / n, ja = candidates[a] % n, ib = candidates[b] / n, jb = candidates[b] % n;
      K(a, b) = table[static_cast<size_t>(std::abs(ia - ib)) * n + std::abs(ja - jb)];
    }
  Eigen::VectorXd d(m), p = Eigen::VectorXd::Zero(m);
  std::vector<char> active(static_cast<size_t>(m));
  for (int a = 0; a < m; ++a) {
    d[a] = penetration_m[static_cast<size_t>(candidates[a])];
    active[static_cast<size_t>(a)] = last_active_[static_cast<size_t>(candidates[a])];
  }
  bool settled = false;
  for (int round = 0; round < kMaxPivotRounds && !settled; ++round) {
    std::vector<int> idx;
    for (int a = 0; a < m; ++a)
      if (active[static_cast<size_t>(a)]) idx.push_back(a);
    p.setZero();
    if (!idx.empty()) {
      const int s = static_cast<int>(idx.size());
      Eigen::MatrixXd Ka(s, s);
      Eigen::VectorXd da(s);
      for (int r = 0; r < s; ++r) {
        da[r] = d[idx[r]];
        for (int c = 0; c < s; ++c) Ka(r, c) = K(idx[r], idx[c]);
      }
      const Eigen::VectorXd pa = Ka.llt().solve(da);
      for (int r = 0; r < s; ++r) p[idx[r]] = pa[r];
    }
    // Cells pulling (p < 0) leave; cells the surface would pass through (u < d) join.
    const Eigen::VectorXd u = K * p;
    const double tol_m = 1e-9 * d.maxCoeff();
    settled = true;
    for (int a = 0; a < m; ++a) {
      const bool in = active[static_cast<size_t>(a)];
      if (in && p[a] < 0) active[static_cast<size_t>(a)] = 0, settled = false;
      if (!in && u[a] < d[a] - tol_m) active[static_cast<size_t>(a)] = 1, settled = false;
    }
  }
  for (int k = 0; k < cells; ++k) last_active_[static_cast<size_t>(k)] = 1;
  if (!settled || !p.allFinite()) {
    ++failures_;
    return false;
  }
  for (int a = 0; a < m; ++a) {
    (*pressure_Pa)[static_cast<size_t>(candidates[a])] = std::max(0.0, p[a]);
    last_active_[static_cast<size_t>(candidates[a])] = active[static_cast<size_t>(a)];
  }
  return true;
}

}  // namespace sedbridge::sensors
