#include <algorithm>
#include <cmath>
#include <limits>

#include "fem/column_products.h"
#include "fem/compliance_contact.h"

// The contact QP of one outer iteration of ComplianceContact's step. With the gaps
// linearized about the current positions (normals frozen, tangential part held) the contact
// problem is a convex QP in the normal forces:
//   min 1/2 l^T (N^T W N + I/k) l + q^T l,  l >= 0,
// whose optimality conditions are exactly the penalty law l_p = k max(0, -gap_p). It is
// solved by a primal active-set method (Lawson-Hanson style): the objective falls at every
// change of the active set, so it cannot cycle (a plain semismooth Newton on max(0, .) does
// cycle here: N^T W N is not an M-matrix). Its matrix is gathered from T, W's columns along
// the rows' directions (kept while a row's sample and direction hold), and its Cholesky
// factor is updated by rows while few change.

namespace sedbridge::fem {

using column_products::AddThreeColumns;
using column_products::SetThreeColumns;

void ComplianceContact::CandidateDisplacements(bool normal_forces_only) {
  u_c_.setZero();
  if (!normal_forces_only || num_objects_ <= 0) {
    op_->AddWTimes(loaded_, [](int j) { return j; }, [&](int j) { return Eigen::Vector3d(f_c_.segment<3>(3 * j)); }, u_c_, op_scratch_);
    return;
  }
  // A sample's force is the sum of its pairs' l_p n_p: where every such pair's row still
  // has its column of T (the last QP's, same direction), sum those columns instead of
  // reading three columns of W.
  const int no = num_objects_;
  std::vector<int>& from_w = from_w_;
  std::vector<int>& from_t = from_t_;
  from_w.clear();
  from_t.clear();
  for (int j : loaded_) {
    bool cached = true;
    for (int o = 0; o < no && cached; ++o) {
      const int p = j * no + o;
      if (lambda_N_[p] > 0) cached = CachedRowColumn(p, j, normal_.col(p)) >= 0;
    }
    if (!cached) {
      from_w.push_back(j);
      continue;
    }
    for (int o = 0; o < no; ++o)
      if (lambda_N_[j * no + o] > 0) from_t.push_back(j * no + o);
  }
  op_->AddWTimes(from_w, [](int j) { return j; }, [&](int j) { return Eigen::Vector3d(f_c_.segment<3>(3 * j)); }, u_c_, op_scratch_);
  AddColumnsOfT(from_t, [&](int p) { return t_slot_of_row_[size_t(p)]; }, [&](int p) { return lambda_N_[p]; }, u_c_);
}

int ComplianceContact::CachedRowColumn(int r, int sample, const Eigen::Vector3d& dir) const {
  if (size_t(r) >= t_slot_of_row_.size()) return -1;
  const int slot = t_slot_of_row_[size_t(r)];
  return slot >= 0 && t_has_column_[size_t(slot)] && t_sample_[size_t(slot)] == sample && t_dir_[size_t(slot)] == dir
             ? slot
             : -1;
}

int ComplianceContact::RowColumn(int r) {
  const int sample = row_node_[size_t(r)];
  const Eigen::Vector3d dir = row_dir_.col(r);
  int& slot = t_slot_of_row_[size_t(r)];
  if (slot < 0) {  // a new slot (grows only while a larger contact set appears)
    slot = int(t_sample_.size());
    t_sample_.push_back(-1);
    t_dir_.emplace_back();
    t_has_column_.push_back(0);
  }
  const size_t k = size_t(slot);
  if (t_sample_[k] != sample || t_dir_[k] != dir) {
    // A direction not seen before for this row (a curved object's normals turn every outer
    // iteration): no column; W serves this use directly, which is cheaper for one use.
    t_sample_[k] = sample;
    t_dir_[k] = dir;
    t_has_column_[k] = 0;
    return -1;
  }
  if (t_has_column_[k]) return slot;
  // The same sample and direction a second time: it is likely to hold (a plane), so the
  // column is worth its one pass over W.
  if (slot >= T_.cols()) T_.conservativeResize(op_->W().rows(), std::max<Eigen::Index>(std::max(32, slot + 1), 2 * T_.cols()));
  const Eigen::Index n = op_->W().rows();
  const double* w = op_->W().data() + 3 * Eigen::Index(sample) * n;
  SetThreeColumns(int(n), w, w + n, w + 2 * n, dir[0], dir[1], dir[2], T_.col(slot).data());
  t_has_column_[k] = 1;
  ++qp_counts_.columns_computed;
  return slot;
}

template <typename Items, typename SlotOf, typename CoefficientOf>
void ComplianceContact::AddColumnsOfT(const Items& items, const SlotOf& slot_of, const CoefficientOf& coefficient_of,
                                      Eigen::VectorXd& y) const {
  // Three columns per pass over y.
  const double* column[3];
  double coefficient[3];
  int k = 0;
  const int n = int(T_.rows());
  for (int item : items) {
    const double l = coefficient_of(item);
    if (l == 0) continue;
    column[k] = T_.col(slot_of(item)).data();
    coefficient[k] = l;
    if (++k == 3) {
      AddThreeColumns(n, column[0], column[1], column[2], coefficient[0], coefficient[1], coefficient[2], y.data());
      k = 0;
    }
  }
  for (; k > 0 && k < 3; ++k) column[k] = column[0], coefficient[k] = 0.0;
  if (k == 3) AddThreeColumns(n, column[0], column[1], column[2], coefficient[0], coefficient[1], coefficient[2], y.data());
}

double ComplianceContact::QpEntry(int r, int slot_r, int q, int slot_q) const {
  const int i_r = row_node_[size_t(r)], i_q = row_node_[size_t(q)];
  // From q's column of T, else r's (J is symmetric), else W's block.
  if (slot_q >= 0) return row_dir_.col(r).dot(Eigen::Map<const Eigen::Vector3d>(T_.col(slot_q).data() + 3 * i_r));
  if (slot_r >= 0) return row_dir_.col(q).dot(Eigen::Map<const Eigen::Vector3d>(T_.col(slot_r).data() + 3 * i_q));
  return row_dir_.col(r).dot(op_->W().block<3, 3>(3 * i_r, 3 * i_q) * row_dir_.col(q));
}

bool ComplianceContact::UpdateFactor(int rows) {
  const int m = int(passive_.size());
  std::vector<int>& slot = passive_slot_;
  // Which of the factor's rows are still passive, with the sample, direction and
  // compliance they were factored with (a plane's rows, step after step).
  std::vector<int>& slot_of = row_slot_;  // passive row -> its slot + 2 (0: not passive)
  slot_of.assign(size_t(rows), 0);
  for (int a = 0; a < m; ++a) slot_of[size_t(passive_[size_t(a)])] = slot[size_t(a)] + 2;
  const int f = int(factor_rows_.size());
  int kept = 0;
  std::vector<char>& keep = factor_keep_;
  keep.assign(size_t(f), 0);
  for (int a = 0; a < f; ++a) {
    const int r = factor_rows_[size_t(a)];
    const FactorRow& key = factor_keys_[size_t(a)];
    if (r < rows && slot_of[size_t(r)] && key.sample == row_node_[size_t(r)] && key.dir == row_dir_.col(r) &&
        key.compliance == row_compliance_[r]) {
      keep[size_t(a)] = 1;
      slot_of[size_t(r)] = -slot_of[size_t(r)];  // marked: in the factor
      ++kept;
    }
  }
  const int changes = (f - kept) + (m - kept);
  // Rank-one changes cost O(m^2) each, a new factor O(m^3 / 3): update while few change.
  const bool update = m > 0 && kept > 0 && changes <= std::max(4, m / 8);
  if (update) {
    if (changes == 0) ++qp_counts_.factor_reuses;
    for (int a = f - 1; a >= 0; --a) {
      if (keep[size_t(a)]) continue;
      factor_.Remove(a);
      factor_rows_.erase(factor_rows_.begin() + a);
      factor_keys_.erase(factor_keys_.begin() + a);
      ++qp_counts_.factor_updates;
    }
    std::vector<double>& column = factor_column_;
    bool appended = true;
    for (int b = 0; b < m && appended; ++b) {
      const int q = passive_[size_t(b)];
      if (slot_of[size_t(q)] < 0) continue;  // in the factor already
      column.clear();
      for (int r : factor_rows_) column.push_back(QpEntry(r, std::abs(slot_of[size_t(r)]) - 2, q, slot[size_t(b)]));
      column.push_back(QpEntry(q, slot[size_t(b)], q, slot[size_t(b)]) + row_compliance_[q]);
      appended = factor_.Append(column.data());
      if (appended) {
        factor_rows_.push_back(q);
        factor_keys_.push_back({row_node_[size_t(q)], row_dir_.col(q), row_compliance_[q]});
        slot_of[size_t(q)] = -slot_of[size_t(q)];
        ++qp_counts_.factor_updates;
      }
    }
    if (appended) {
      // The QP goes on in the factor's row order.
      for (int a = 0; a < m; ++a) {
        passive_[size_t(a)] = factor_rows_[size_t(a)];
        slot[size_t(a)] = std::abs(slot_of[size_t(factor_rows_[size_t(a)])]) - 2;
      }
      return true;
    }
    // A nearly dependent row: factor anew.
  }
  // J = D^T W_PP D in the passive order, then its Cholesky factor.
  J_.resize(m, m);
  for (int b = 0; b < m; ++b) {
    const int q = passive_[size_t(b)];
    for (int a = b; a < m; ++a) J_(a, b) = QpEntry(passive_[size_t(a)], slot[size_t(a)], q, slot[size_t(b)]);
    J_(b, b) += row_compliance_[q];
  }
  factor_rows_.clear();
  factor_keys_.clear();
  if (m == 0) {
    factor_.Clear();
    return true;
  }
  ++qp_counts_.factorizations;
  if (!factor_.Factor(m, J_.data(), m)) return false;
  factor_rows_ = passive_;
  for (int q : passive_) factor_keys_.push_back({row_node_[size_t(q)], row_dir_.col(q), row_compliance_[q]});
  return true;
}

bool ComplianceContact::SolveLinearizedQp(int no, const Eigen::Vector3d& tau, const ForceControl* control) {
  const int rows = BuildQpRows(no, tau);
  ++qp_counts_.qps;
  // Rows keep their columns of T from earlier QPs where their sample and direction have not
  // changed (a plane's rows, step after step); the slot map is per row index.
  t_slot_of_row_.resize(size_t(rows), -1);
  if (control && !StartForceControl(rows, *control)) return false;
  double delta = 0;
  bool ok = true;
  const bool solved = RunActiveSet(rows, control, &delta, &ok);
  if (!ok) return false;
  TakeQpForces();
  // u_new_ = W f for exactly these forces when the set settled (reused as the next
  // iteration's displacements). Not while sample loads are held: the reuse paths are
  // proven for normal forces alone, and a display's load is solved a few times, not per scan.
  prediction_valid_ = solved && !has_sample_loads();
  qp_offset_change_m_ = delta;
  return true;  // not solved: out of inner iterations, the outer loop reports non-convergence
}

int ComplianceContact::BuildQpRows(int no, const Eigen::Vector3d& tau) {
  const double k = options_.stiffness_N_m;
  const bool friction = options_.friction_anisotropy > 0;
  const double k_t = options_.friction_anisotropy * k;
  const Eigen::MatrixXd& W = op_->W();
  const Eigen::Matrix3Xd& rest = op_->sample_rest_positions_m();
  // Exact contact: no penalty compliance; a whisper of it keeps the QP matrix definite when
  // two contacts act on one node along dependent normals.
  const double inverse_k = options_.exact_contact ? (W.size() ? kExactContactRegularization * W.diagonal().maxCoeff() : 0.0) : 1.0 / k;
  const Eigen::Index pairs = lambda_N_.size();
  const int c = num_samples();
  // Forces held fixed in this QP: the tangential load (shares of the current normal
  // forces). u_t_ = W held.
  held_.setZero(3 * c);
  for (Eigen::Index p = 0; p < pairs; ++p)
    if (lambda_N_[p] > 0) held_.segment<3>(3 * (int(p) / no)) += lambda_N_[p] * tau;
  for (int j : load_samples_) held_.segment<3>(3 * j) += sample_load_N_.col(j);
  // Only samples with a normal force or a sample load hold a share, and loaded_ lists them
  // (this iteration's forces, in order).
  u_t_.setZero(3 * c);
  op_->AddWTimes(loaded_, [](int j) { return j; }, [&](int j) { return Eigen::Vector3d(held_.segment<3>(3 * j)); }, u_t_, op_scratch_);
  // Rows: force lambda_r along dir_r at node_r with "gap" g_r (linearized about the current
  // positions) and compliance c_r: lambda_r = -g_r(new) / c_r. Normal rows are bounded
  // (lambda >= 0: the penalty never pulls); friction rows (two tangent directions of an
  // anchored contact, gap = offset from the anchor) are free.
  bounded_rows_ = int(pairs);
  int rows = int(pairs);
  if (friction)
    for (Eigen::Index p = 0; p < pairs; ++p) rows += sticking_[size_t(p)] ? 2 : 0;
  row_node_.resize(size_t(rows));
  row_dir_.resize(3, rows);
  row_gap_.resize(rows);
  row_lambda_.resize(rows);
  row_compliance_.resize(rows);
  // Block copies, and the node of pair p = j * no + o without an integer division per pair
  // (570 of them per QP with face contact).
  for (int j = 0, p = 0; p < int(pairs); ++j)
    for (int o = 0; o < no; ++o) row_node_[size_t(p++)] = j;
  row_dir_.leftCols(pairs) = normal_;
  row_gap_.head(pairs) = phi_m_;
  row_lambda_.head(pairs) = lambda_N_;
  row_compliance_.head(pairs).setConstant(inverse_k);
  if (friction) {
    int r = int(pairs);
    for (Eigen::Index p = 0; p < pairs; ++p) {
      if (!sticking_[size_t(p)]) continue;
      const int j = int(p) / no;
      const Eigen::Vector3d n = normal_.col(p);
      const Eigen::Vector3d t1 = n.unitOrthogonal(), t2 = n.cross(t1);
      const Eigen::Vector3d offset = rest.col(j) + u_c_.segment<3>(3 * j) - anchor_world_.col(p);
      for (const Eigen::Vector3d& t : {t1, t2}) {
        row_node_[size_t(r)] = j;
        row_dir_.col(r) = t;
        row_gap_[r] = t.dot(offset);
        row_lambda_[r] = t.dot(friction_.col(p));
        row_compliance_[r] = 1.0 / k_t;
        ++r;
      }
    }
  }
  return rows;
}

bool ComplianceContact::StartForceControl(int rows, const ForceControl& control) {
  // The rows' forces must push target_N along the direction; the objects' move delta (the
  // multiplier of that constraint) closes each gap by delta * push_r. The active-set
  // iterates all carry the target (convex combinations of points that do), so start from
  // one that does: the warm forces scaled to it, else the row that closes first as the
  // objects move.
  row_push_.setZero(rows);
  double carried = 0;
  for (int r = 0; r < bounded_rows_; ++r) {
    row_push_[r] = control.direction_unit.dot(row_dir_.col(r));
    if (row_lambda_[r] > 0) carried += row_push_[r] * row_lambda_[r];
  }
  if (carried > 0) {
    for (int r = 0; r < bounded_rows_; ++r) row_lambda_[r] *= control.target_N / carried;
    return true;
  }
  int first = -1;
  double closes_at = std::numeric_limits<double>::infinity();
  for (int r = 0; r < bounded_rows_; ++r) {
    row_lambda_[r] = 0;
    if (row_push_[r] > kMinPush && row_gap_[r] / row_push_[r] < closes_at) closes_at = row_gap_[r] / row_push_[r], first = r;
  }
  if (first < 0) return false;
  row_lambda_[first] = control.target_N / row_push_[first];
  return true;
}

void ComplianceContact::PredictDisplacements(const Eigen::VectorXd& l) {
  u_new_ = u_t_;
  with_column_.clear();
  without_column_.clear();
  for (size_t a = 0; a < passive_.size(); ++a) (passive_slot_[a] >= 0 ? with_column_ : without_column_).push_back(int(a));
  AddColumnsOfT(with_column_, [&](int a) { return passive_slot_[size_t(a)]; },
                [&](int a) { return l[passive_[size_t(a)]]; }, u_new_);
  op_->AddWTimes(without_column_, [&](int a) { return row_node_[size_t(passive_[size_t(a)])]; },
                 [&](int a) {
                   const int r = passive_[size_t(a)];
                   return Eigen::Vector3d(l[r] * row_dir_.col(r));
                 },
                 u_new_, op_scratch_);
}

bool ComplianceContact::RunActiveSet(int rows, const ForceControl* control, double* delta, bool* ok) {
  const double k = options_.stiffness_N_m;
  passive_.clear();
  for (int r = 0; r < rows; ++r)
    if (r >= bounded_rows_ || row_lambda_[r] > 0) passive_.push_back(r);
  // Work lists are members: no allocation once they have grown (the step is real time).
  std::vector<int>& before_add = before_add_;
  before_add.clear();
  int most_violated = -1;
  bool batch_added = false;
  largest_ = 0;
  for (int inner = 0; inner < 4 * rows + 10; ++inner) {
    // Unconstrained minimizer on the passive set.
    const int m = int(passive_.size());
    rhs_.resize(m);
    std::vector<int>& slot = passive_slot_;
    slot.resize(size_t(m));
    for (int a = 0; a < m; ++a) slot[size_t(a)] = RowColumn(passive_[size_t(a)]);
    if (!UpdateFactor(rows)) return *ok = false;
    for (int b = 0; b < m; ++b) {
      const int q = passive_[size_t(b)], i = row_node_[size_t(q)];
      rhs_[b] = -row_gap_[q] + row_dir_.col(q).dot(u_c_.segment<3>(3 * i) - u_t_.segment<3>(3 * i));
    }
    if (m) {
      z_ = rhs_;
      factor_.Solve(z_.data());
      if (control) {  // J l = rhs + delta push, push . l = target
        push_passive_.resize(m);
        for (int a = 0; a < m; ++a) push_passive_[a] = row_push_[passive_[size_t(a)]];
        y_ = push_passive_;
        factor_.Solve(y_.data());
        const double denominator = push_passive_.dot(y_);
        if (!(denominator > 0)) return *ok = false;
        *delta = (control->target_N - push_passive_.dot(z_)) / denominator;
        z_ += *delta * y_;
      }
    } else {
      if (control) return *ok = false;
      z_.resize(0);
    }
    if (!z_.allFinite()) return *ok = false;
    // Infeasible: step from l toward z until the first bounded force reaches zero, drop it.
    double alpha = 1;
    for (int a = 0; a < m; ++a) {
      const int r = passive_[size_t(a)];
      if (r < bounded_rows_ && z_[a] <= 0) alpha = std::min(alpha, row_lambda_[r] / (row_lambda_[r] - z_[a]));
    }
    if (alpha < 1) {
      if (alpha <= 0 && batch_added) {
        // A row added in the last batch wants a negative force at once: add only the
        // most violated one instead (Lawson-Hanson's rule, which always makes progress).
        passive_ = before_add;
        passive_.push_back(most_violated);
        batch_added = false;
        continue;
      }
      std::vector<int>& kept = kept_;
      kept.clear();
      for (int a = 0; a < m; ++a) {
        const int r = passive_[size_t(a)];
        row_lambda_[r] += alpha * (z_[a] - row_lambda_[r]);
        if (r >= bounded_rows_) {
          kept.push_back(r);
          continue;
        }
        if (z_[a] <= 0 && row_lambda_[r] <= 1e-14 * (1 + std::abs(z_[a]))) row_lambda_[r] = 0;
        if (row_lambda_[r] > 0) kept.push_back(r);
      }
      passive_.swap(kept);
      batch_added = false;
      continue;
    }
    for (int a = 0; a < m; ++a) row_lambda_[passive_[size_t(a)]] = z_[a];
    // Optimal on the passive set: any other normal row predicted to penetrate joins it.
    PredictDisplacements(row_lambda_);
    for (int a = 0; a < m; ++a)
      if (passive_[size_t(a)] < bounded_rows_) largest_ = std::max(largest_, z_[a]);
    const double gap_tolerance = options_.exact_contact
                                     ? 1e-3 * options_.relative_tolerance * kExactGapScale_m
                                     : 1e-3 * options_.relative_tolerance * std::max(largest_, kMinForceScale_N) / k;
    before_add = passive_;
    most_violated = -1;
    double worst = -gap_tolerance;
    std::vector<char>& in_passive = in_passive_;
    in_passive.assign(size_t(rows), 0);
    for (int r : passive_) in_passive[size_t(r)] = 1;
    for (int r = 0; r < bounded_rows_; ++r) {
      if (in_passive[size_t(r)]) continue;
      const int i = row_node_[size_t(r)];
      double gap = row_gap_[r] + row_dir_.col(r).dot(u_new_.segment<3>(3 * i) - u_c_.segment<3>(3 * i));
      if (control) gap -= *delta * row_push_[r];
      if (gap < -gap_tolerance) passive_.push_back(r);
      if (gap < worst) worst = gap, most_violated = r;
    }
    if (most_violated < 0) return true;
    batch_added = passive_.size() > before_add.size() + 1;
  }
  return false;
}

void ComplianceContact::TakeQpForces() {
  // Back to pairs: normal forces, and the friction of spring pairs from their rows.
  const Eigen::Index pairs = lambda_N_.size();
  for (Eigen::Index p = 0; p < pairs; ++p) lambda_N_[p] = std::max(0.0, row_lambda_[p]);
  if (options_.friction_anisotropy > 0) {
    friction_.setZero();
    int r = bounded_rows_;
    for (Eigen::Index p = 0; p < pairs; ++p) {
      if (!sticking_[size_t(p)]) continue;
      friction_.col(p) = row_lambda_[r] * row_dir_.col(r) + row_lambda_[r + 1] * row_dir_.col(r + 1);
      r += 2;
    }
  }
}

}  // namespace sedbridge::fem
