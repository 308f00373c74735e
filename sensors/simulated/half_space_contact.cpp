#include "sensors/simulated/half_space_contact.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sedbridge::sensors {

namespace {

constexpr double kPi = 3.14159265358979323846;
// Active-set changes before the iteration is given up (a contact settles in a handful).
constexpr int kMaxPivotRounds = 60;

// Love's term: x ln((y + r(x, y)) / (y' + r(x, y'))) for the rectangle's corner pair.
double Term(double x, double y_hi, double y_lo) {
  return x * std::log((y_hi + std::hypot(x, y_hi)) / (y_lo + std::hypot(x, y_lo)));
}

}  // namespace

HalfSpaceContact::HalfSpaceContact(double cell_m, double contact_modulus_Pa)
    : cell_m_(cell_m), contact_modulus_Pa_(contact_modulus_Pa) {
  if (!(cell_m > 0) || !(contact_modulus_Pa > 0))
    throw std::invalid_argument("HalfSpaceContact: cell size and contact modulus must be positive");
}

double HalfSpaceContact::Influence(int di, int dj) const {
  // Deflection at (x, y) under unit pressure on |xi| <= c, |eta| <= c (Love 1929):
  // u = 1 / (pi E*) [ (x+c) ln(..) + (y+c) ln(..) + (x-c) ln(..) + (y-c) ln(..) ].
  // Cell centres sit at whole multiples of 2c, so no x +- c or y +- c is zero.
  const double c = 0.5 * cell_m_;
  const double x = di * cell_m_, y = dj * cell_m_;
  const double sum = Term(x + c, y + c, y - c) + Term(y + c, x + c, x - c) + Term(x - c, y - c, y + c) +
                     Term(y - c, x - c, x + c);
  return sum / (kPi * contact_modulus_Pa_);
}

bool HalfSpaceContact::Solve(int n, const std::vector<double>& penetration_m, std::vector<double>* pressure_Pa) {
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
