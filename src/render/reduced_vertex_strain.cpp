#include "render/reduced_vertex_strain.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sedbridge::render {

namespace {

constexpr int C = kStrainComponents;

/// sqrt(D) for the tet SED W = 1/2 eps^T D eps, D = 2 mu diag(1, 1, 1, 2, 2, 2) + lambda on
/// the normal block.
Eigen::Matrix<double, C, C> RootElasticity(double mu, double lambda) {
  Eigen::Matrix<double, C, C> D = Eigen::Matrix<double, C, C>::Zero();
  for (int c = 0; c < 3; ++c) D(c, c) = 2.0 * mu, D(c + 3, c + 3) = 4.0 * mu;
  D.topLeftCorner<3, 3>().array() += lambda;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, C, C>> eig(D);
  return eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal() * eig.eigenvectors().transpose();
}

using Root = Eigen::Matrix<double, C, C>;

/// y = L^T eps of vertex v: its elements' rows of m (6 a row block), each multiplied by its
/// element's root (sqrt of weight times elastic matrix), stacked.
Eigen::MatrixXd ScaledStrains(const ElementStrainInfluence& in, int v, const std::vector<Root>& root,
                              const Eigen::MatrixXd& m) {
  const int first = in.vertex_start[size_t(v)], K = in.vertex_start[size_t(v) + 1] - first;
  Eigen::MatrixXd y(C * K, m.cols());
  for (int k = 0; k < K; ++k)
    y.middleRows<C>(C * k) = root[size_t(k)] * m.middleRows<C>(C * in.vertex_element[size_t(first + k)]);
  return y;
}

}  // namespace

ElementStrainInfluence ReduceStrainPerVertex(const ElementStrainInfluence& in, double dropped_share,
                                             ReducedVertexStrainStats* stats) {
  CheckElementStrainInfluence(in);
  if (!(dropped_share >= 0 && dropped_share < 1)) throw std::invalid_argument("strain reduction: dropped share in [0, 1)");
  const int vertices = int(in.vertex_start.size()) - 1;
  // Each segment's strain change per actuator (the first segment's, or the linear one, at one
  // unit of command when there are no knots).
  std::vector<Eigen::MatrixXd> changes;
  if (in.knot_command.empty()) {
    changes.push_back(in.strain_per_command);
  } else {
    for (size_t k = 0; k < in.strain_at_knot.size(); ++k)
      changes.push_back(k ? Eigen::MatrixXd(in.strain_at_knot[k] - in.strain_at_knot[k - 1]) : in.strain_at_knot[k]);
  }
  // Per vertex: its basis (rows of B: 6K stacked, scaled strains -> coordinates), and the
  // coordinates of each matrix, gathered into pseudo-elements afterwards.
  std::vector<Eigen::MatrixXd> basis(static_cast<size_t>(vertices));
  std::vector<std::vector<Root>> roots(static_cast<size_t>(vertices));
  ReducedVertexStrainStats s;
  int pseudo = 0;
  for (int v = 0; v < vertices; ++v) {
    const int first = in.vertex_start[size_t(v)], K = in.vertex_start[size_t(v) + 1] - first;
    if (K == 0) continue;
    auto& root = roots[size_t(v)];
    for (int k = 0; k < K; ++k) {
      const int e = in.vertex_element[size_t(first + k)];
      root.push_back(std::sqrt(std::max(in.vertex_weight[size_t(first + k)], 0.0)) * RootElasticity(in.mu_Pa[e], in.lambda_Pa[e]));
    }
    Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(C * K, C * K);
    for (const Eigen::MatrixXd& m : changes) {
      const Eigen::MatrixXd y = ScaledStrains(in, v, root, m);
      gram.selfadjointView<Eigen::Lower>().rankUpdate(y);  // not a general product: no OpenMP team
    }
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(gram.selfadjointView<Eigen::Lower>());  // ascending
    const Eigen::VectorXd energy = eig.eigenvalues().cwiseMax(0.0);
    const double total = energy.sum();
    int keep = 0;
    double dropped = total;
    while (keep < C * K && dropped > dropped_share * total) dropped -= energy[C * K - 1 - keep], ++keep;
    s.largest_dropped_share = std::max(s.largest_dropped_share, total > 0 ? std::max(dropped, 0.0) / total : 0.0);
    // Whole pseudo-elements: the kept directions, the next leading ones up to a multiple of
    // six, the last of them the preload's part outside the others (its SED at rest is then
    // kept exactly) unless it has none.
    const int rank = std::min(C * K, (keep + 1 + C - 1) / C * C);
    Eigen::MatrixXd b(C * K, rank);
    b.leftCols(rank - 1) = eig.eigenvectors().rightCols(rank - 1);
    const Eigen::VectorXd whole = ScaledStrains(in, v, root, in.preload_strain);
    Eigen::VectorXd preload = whole - b.leftCols(rank - 1) * (b.leftCols(rank - 1).transpose() * whole);
    b.col(rank - 1) = preload.norm() > 1e-9 * std::max(whole.norm(), 1e-300) ? Eigen::VectorXd(preload.normalized())
                                                                           : Eigen::VectorXd(eig.eigenvectors().col(C * K - rank));
    basis[size_t(v)] = b.transpose();
    pseudo += rank / C;
  }
  ElementStrainInfluence out;
  out.command_offset = in.command_offset;
  out.knot_command = in.knot_command;
  out.mu_Pa = Eigen::VectorXd::Constant(pseudo, 0.5);
  out.lambda_Pa = Eigen::VectorXd::Zero(pseudo);
  out.vertex_start.assign(1, 0);
  for (int v = 0, g = 0; v < vertices; ++v) {
    for (Eigen::Index p = 0; p < basis[size_t(v)].rows() / C; ++p) out.vertex_element.push_back(g++), out.vertex_weight.push_back(1.0);
    out.vertex_start.push_back(int(out.vertex_element.size()));
  }
  // A matrix's coordinates: z = B L^T eps per vertex, in pseudo-elements whose SED
  // mu (z0^2 + z1^2 + z2^2 + 2 (z3^2 + z4^2 + z5^2)) is 1/2 |z|^2 with mu 1/2 and the
  // last three halved in square: divided by sqrt 2.
  auto coordinates = [&](const Eigen::MatrixXd& m) {
    Eigen::MatrixXd out_m(C * pseudo, m.cols());
    Eigen::Index row = 0;
    for (int v = 0; v < vertices; ++v) {
      const Eigen::MatrixXd& b = basis[size_t(v)];
      if (b.rows() == 0) continue;
      Eigen::MatrixXd z = b.lazyProduct(ScaledStrains(in, v, roots[size_t(v)], m));
      for (Eigen::Index r = 0; r < z.rows(); ++r)
        if (r % C >= 3) z.row(r) /= std::sqrt(2.0);
      out_m.middleRows(row, z.rows()) = z;
      row += z.rows();
    }
    return out_m;
  };
  out.preload_strain = coordinates(in.preload_strain);
  out.strain_per_command = coordinates(in.strain_per_command);
  for (const Eigen::MatrixXd& m : in.strain_at_knot) out.strain_at_knot.push_back(coordinates(m));
  if (stats) *stats = s;
  return out;
}

}  // namespace sedbridge::render
