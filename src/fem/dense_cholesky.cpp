#include "fem/dense_cholesky.h"

#include <algorithm>
#include <cmath>

#include "common/hot_clones.h"

namespace sedbridge::fem {
namespace {

constexpr int kPanel = 8;

// a_j[i] -= sum_c p_c[i] * b_c over i in [begin, n), for the 8 panel columns p_c (b_c =
// p_c[j]): the trailing update's inner loop, 8 FMAs per load/store of a_j. __restrict:
// the panel and the updated columns never overlap, and without it GCC's alias checks for
// ten pointers exceed its limit and the loop stays scalar.
SEDBRIDGE_HOT_CLONES
void SubtractPanel8(int begin, int n, const double* __restrict p, int lda, const double* b, double* __restrict a_j) {
  const double *p0 = p, *p1 = p + lda, *p2 = p + 2 * lda, *p3 = p + 3 * lda;
  const double *p4 = p + 4 * lda, *p5 = p + 5 * lda, *p6 = p + 6 * lda, *p7 = p + 7 * lda;
  const double b0 = b[0], b1 = b[1], b2 = b[2], b3 = b[3], b4 = b[4], b5 = b[5], b6 = b[6], b7 = b[7];
  for (int i = begin; i < n; ++i)
    a_j[i] -= ((p0[i] * b0 + p1[i] * b1) + (p2[i] * b2 + p3[i] * b3)) +
              ((p4[i] * b4 + p5[i] * b5) + (p6[i] * b6 + p7[i] * b7));
}

// Two trailing columns j, j + 1 at once (rows from begin = j + 1 on): each panel load
// serves 16 FMAs.
SEDBRIDGE_HOT_CLONES
void SubtractPanel8Twice(int begin, int n, const double* __restrict p, int lda, const double* b, const double* c,
                         double* __restrict a_j, double* __restrict a_k) {
  const double *p0 = p, *p1 = p + lda, *p2 = p + 2 * lda, *p3 = p + 3 * lda;
  const double *p4 = p + 4 * lda, *p5 = p + 5 * lda, *p6 = p + 6 * lda, *p7 = p + 7 * lda;
  const double b0 = b[0], b1 = b[1], b2 = b[2], b3 = b[3], b4 = b[4], b5 = b[5], b6 = b[6], b7 = b[7];
  const double c0 = c[0], c1 = c[1], c2 = c[2], c3 = c[3], c4 = c[4], c5 = c[5], c6 = c[6], c7 = c[7];
  for (int i = begin; i < n; ++i) {
    const double q0 = p0[i], q1 = p1[i], q2 = p2[i], q3 = p3[i], q4 = p4[i], q5 = p5[i], q6 = p6[i], q7 = p7[i];
    a_j[i] -= ((q0 * b0 + q1 * b1) + (q2 * b2 + q3 * b3)) + ((q4 * b4 + q5 * b5) + (q6 * b6 + q7 * b7));
    a_k[i] -= ((q0 * c0 + q1 * c1) + (q2 * c2 + q3 * c3)) + ((q4 * c4 + q5 * c5) + (q6 * c6 + q7 * c7));
  }
}

// The same for a panel of w < 8 columns (the last one).
SEDBRIDGE_HOT_CLONES
void SubtractPanel(int w, int begin, int n, const double* __restrict p, int lda, const double* b,
                   double* __restrict a_j) {
  for (int c = 0; c < w; ++c) {
    const double* pc = p + c * lda;
    const double bc = b[c];
    for (int i = begin; i < n; ++i) a_j[i] -= pc[i] * bc;
  }
}

}  // namespace

SEDBRIDGE_HOT_CLONES
bool CholeskyFactorLower(int n, double* a, int lda) {
  auto at = [&](int i, int j) -> double& { return a[i + j * lda]; };
  double b[kPanel];
  for (int k0 = 0; k0 < n; k0 += kPanel) {
    const int w = n - k0 < kPanel ? n - k0 : kPanel;
    // Factor the panel's columns (every earlier panel's update is already in them).
    for (int c = 0; c < w; ++c) {
      const int k = k0 + c;
      double* col = &at(0, k);
      for (int d = k0; d < k; ++d) {  // the panel's earlier columns
        const double f = at(k, d);
        const double* __restrict pd = &at(0, d);
        double* __restrict out = col;
        for (int i = k; i < n; ++i) out[i] -= pd[i] * f;
      }
      const double pivot = col[k];
      if (!(pivot > 0) || !std::isfinite(pivot)) return false;
      const double diagonal = std::sqrt(pivot);
      col[k] = diagonal;
      const double inverse = 1.0 / diagonal;
      for (int i = k + 1; i < n; ++i) col[i] *= inverse;
    }
    // Trailing update: A(j:, j) -= L(j:, panel) L(j, panel)^T for every later column j.
    const double* panel = &at(0, k0);
    int j = k0 + w;
    if (w == kPanel) {
      double c[kPanel];
      for (; j + 1 < n; j += 2) {
        for (int q = 0; q < w; ++q) b[q] = at(j, k0 + q), c[q] = at(j + 1, k0 + q);
        // Row j of column j alone, then rows j + 1.. of both.
        double s = 0;
        for (int q = 0; q < w; ++q) s += panel[j + q * lda] * b[q];
        at(j, j) -= s;
        SubtractPanel8Twice(j + 1, n, panel, lda, b, c, &at(0, j), &at(0, j + 1));
      }
    }
    for (; j < n; ++j) {
      for (int q = 0; q < w; ++q) b[q] = at(j, k0 + q);
      if (w == kPanel)
        SubtractPanel8(j, n, panel, lda, b, &at(0, j));
      else
        SubtractPanel(w, j, n, panel, lda, b, &at(0, j));
    }
  }
  return true;
}

namespace {
// L y = b in place, column-oriented (contiguous columns of L): the first half of a solve,
// and all of an appended row's.
SEDBRIDGE_HOT_CLONES
void ForwardSolveLower(int n, const double* l, int lda, double* b) {
  for (int j = 0; j < n; ++j) {
    const double* __restrict col = l + j * lda;
    double* __restrict out = b;
    const double y = out[j] / col[j];
    out[j] = y;
    for (int i = j + 1; i < n; ++i) out[i] -= col[i] * y;
  }
}
}  // namespace

SEDBRIDGE_HOT_CLONES
void CholeskySolveLower(int n, const double* l, int lda, double* b) {
  ForwardSolveLower(n, l, lda, b);
  // L^T x = y, row of L^T = column of L (dot products).
  for (int j = n - 1; j >= 0; --j) {
    const double* col = l + j * lda;
    double s = b[j];
    for (int i = j + 1; i < n; ++i) s -= col[i] * b[i];
    b[j] = s / col[j];
  }
}

void UpdatableCholesky::Reserve(int n) {
  if (n <= lda_) return;
  const int lda = std::max(n, 2 * lda_);
  std::vector<double> l(size_t(lda) * size_t(lda));
  for (int j = 0; j < n_; ++j) std::copy_n(&l_[size_t(j) * size_t(lda_)], n_, &l[size_t(j) * size_t(lda)]);
  l_.swap(l);
  lda_ = lda;
}

bool UpdatableCholesky::Factor(int n, const double* a, int lda) {
  n_ = 0;
  Reserve(n);
  for (int j = 0; j < n; ++j) std::copy_n(a + size_t(j) * size_t(lda) + j, n - j, &l_[size_t(j) * size_t(lda_) + j]);
  if (!CholeskyFactorLower(n, l_.data(), lda_)) return false;
  n_ = n;
  return true;
}

bool UpdatableCholesky::Append(const double* column, double relative_pivot) {
  const int n = n_;
  Reserve(n + 1);
  // L y = column(0..n-1), then the pivot A(new, new) - y.y.
  scratch_.assign(column, column + n);
  double* y = scratch_.data();
  ForwardSolveLower(n, l_.data(), lda_, y);
  double pivot = column[n];
  for (int j = 0; j < n; ++j) pivot -= y[j] * y[j];
  if (!(pivot > relative_pivot * column[n]) || !std::isfinite(pivot)) return false;
  for (int j = 0; j < n; ++j) l_[size_t(n) + size_t(j) * size_t(lda_)] = y[j];
  l_[size_t(n) + size_t(n) * size_t(lda_)] = std::sqrt(pivot);
  n_ = n + 1;
  return true;
}

void UpdatableCholesky::Remove(int k) {
  const int n = n_;
  auto at = [&](int i, int j) -> double& { return l_[size_t(i) + size_t(j) * size_t(lda_)]; };
  // The trailing block absorbs column k below the diagonal: L33' L33'^T = L33 L33^T + x x^T
  // (rank-one update by rotations), then row and column k leave the storage.
  scratch_.resize(size_t(n));
  double* x = scratch_.data();
  for (int i = k + 1; i < n; ++i) x[i] = at(i, k);
  for (int j = k + 1; j < n; ++j) {
    const double d = at(j, j), r = std::hypot(d, x[j]);
    const double c = r / d, s = x[j] / d;
    at(j, j) = r;
    for (int i = j + 1; i < n; ++i) {
      const double l = (at(i, j) + s * x[i]) / c;
      x[i] = c * x[i] - s * l;
      at(i, j) = l;
    }
  }
  for (int j = 0; j < n; ++j) {
    if (j == k) continue;
    const int to_j = j < k ? j : j - 1;
    for (int i = j; i < n; ++i) {
      if (i == k) continue;
      at(i < k ? i : i - 1, to_j) = at(i, j);
    }
  }
  n_ = n - 1;
}

void UpdatableCholesky::Solve(double* b) const { CholeskySolveLower(n_, l_.data(), lda_, b); }

}  // namespace sedbridge::fem
