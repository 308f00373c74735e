#include "render/boxed_damped_step.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <vector>

namespace sedbridge::render {

Eigen::VectorXd BoxedDampedStep(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, const Eigen::VectorXd& u,
                                const Eigen::VectorXd& box) {
  // A primal active set from d = 0 (feasible: u is in the box): move toward the minimizer
  // over the variables not held, as far as the box allows; a variable that blocks is held at
  // its bound; at a minimizer, a held variable whose gradient would take it back inside is
  // let go. Each move lowers the model (a convex quadratic), so it ends at the box's
  // minimizer; a few rounds, as few variables meet a bound in a step.
  const Eigen::Index m = H.rows();
  enum Hold : char { kFree, kAtLower, kAtUpper };
  std::vector<char> held(size_t(m), kFree);
  Eigen::VectorXd d = Eigen::VectorXd::Zero(m);
  const Eigen::Index max_rounds = 4 * m + 4;
  for (Eigen::Index round = 0; round < max_rounds; ++round) {
    std::vector<Eigen::Index> solve;
    for (Eigen::Index a = 0; a < m; ++a)
      if (held[size_t(a)] == kFree) solve.push_back(a);
    const Eigen::Index k = Eigen::Index(solve.size());
    if (k > 0) {
      Eigen::MatrixXd Hs(k, k);
      Eigen::VectorXd rhs(k);
      for (Eigen::Index i = 0; i < k; ++i) {
        double r = -g[solve[size_t(i)]];
        for (Eigen::Index a = 0; a < m; ++a)
          if (held[size_t(a)] != kFree) r -= H(solve[size_t(i)], a) * d[a];
        rhs[i] = r;
        for (Eigen::Index j = 0; j < k; ++j) Hs(i, j) = H(solve[size_t(i)], solve[size_t(j)]);
      }
      const Eigen::LDLT<Eigen::MatrixXd> ldlt(Hs);
      Eigen::VectorXd target = ldlt.solve(rhs);
      for (Eigen::Index i = 0; i < k; ++i)
        if (!std::isfinite(target[i])) target[i] = d[solve[size_t(i)]];
      // As far toward the target as the box allows; the variables that meet a bound there
      // block and are held, all of them at once (from a cold start most commands sit at 0
      // with the target below it: each would otherwise cost a round and a factorization).
      double alpha = 1;
      std::vector<double> reach(size_t(k), 2.0);  // the fraction of the way at which each meets a bound
      for (Eigen::Index i = 0; i < k; ++i) {
        const Eigen::Index a = solve[size_t(i)];
        const double p = target[i] - d[a];
        if (p < 0 && u[a] + target[i] < 0) reach[size_t(i)] = std::max(0.0, (-u[a] - d[a]) / p);
        else if (p > 0 && u[a] + target[i] > box[a]) reach[size_t(i)] = std::max(0.0, (box[a] - u[a] - d[a]) / p);
        alpha = std::min(alpha, reach[size_t(i)]);
      }
      bool blocked = false;
      for (Eigen::Index i = 0; i < k; ++i) {
        const Eigen::Index a = solve[size_t(i)];
        d[a] += alpha * (target[i] - d[a]);
        if (reach[size_t(i)] <= alpha + 1e-12) {
          held[size_t(a)] = target[i] < d[a] ? kAtLower : kAtUpper;
          d[a] = held[size_t(a)] == kAtLower ? -u[a] : box[a] - u[a];
          blocked = true;
        }
      }
      if (blocked) continue;
    }
    // At the minimizer over the free variables: let go the held one whose gradient points
    // most into the box.
    const Eigen::VectorXd q = g + H * d;
    Eigen::Index release = -1;
    double most = 0;
    for (Eigen::Index a = 0; a < m; ++a) {
      const double inward = held[size_t(a)] == kAtLower ? -q[a] : held[size_t(a)] == kAtUpper ? q[a] : 0.0;
      if (inward > most) most = inward, release = a;
    }
    if (release < 0) break;
    held[size_t(release)] = kFree;
  }
  return d;
}

}  // namespace sedbridge::render
