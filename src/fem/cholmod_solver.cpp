#include "fem/cholmod_solver.h"

#include "fem/supernodal_triangular_solve.h"

#include <omp.h>

#include <Eigen/CholmodSupport>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <vector>

// OpenBLAS's thread controls, weak: with another BLAS behind libblas.so.3 they are null.
extern "C" void openblas_set_num_threads(int) __attribute__((weak));
extern "C" int openblas_get_num_threads() __attribute__((weak));

namespace sedbridge::fem {
namespace {

// Eigen keeps the cholmod_factor protected; the solve below needs it to call
// cholmod_solve2 (reusable workspace: no allocation per solve) and the statistics.
// Factorize also takes a cholmod_sparse view: Eigen's factorize(const SparseMatrix&) made
// the system matrix (held as CSR) into a temporary column-major copy on every call, a fifth
// of a corotational press's time in copying and first-touch page faults (perf, model B).
class SupernodalFactor : public Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> {
 public:
  cholmod_factor* factor() const { return m_cholmodFactor; }

  void FactorizeView(cholmod_sparse& a) {
    cholmod_factorize_p(&a, m_shiftOffset, nullptr, 0, m_cholmodFactor, &cholmod());
    m_info = m_cholmodFactor->minor == m_cholmodFactor->n ? Eigen::Success : Eigen::NumericalIssue;
    m_factorizationIsOk = true;
  }
};

// The lower triangle of a symmetric matrix stored as compressed CSR, read as CSC without a
// copy (the CSR arrays of a symmetric matrix read as CSC describe the same matrix).
cholmod_sparse SymmetricView(const SystemMatrix::Csr& m) {
  cholmod_sparse a;
  std::memset(&a, 0, sizeof(a));
  a.nrow = size_t(m.rows());
  a.ncol = size_t(m.cols());
  a.nzmax = size_t(m.nonZeros());
  a.p = const_cast<int*>(m.outerIndexPtr());
  a.i = const_cast<int*>(m.innerIndexPtr());
  a.x = const_cast<double*>(m.valuePtr());
  a.stype = -1;  // only entries with row >= column are read
  a.itype = CHOLMOD_INT;
  a.xtype = CHOLMOD_REAL;
  a.dtype = CHOLMOD_DOUBLE;
  a.sorted = 1;
  a.packed = 1;
  return a;
}

// The factor as SupernodalTriangularSolve reads it; false when CHOLMOD holds it in another
// form (simplicial, LDL^T, complex or long indices), which CHOLMOD's own solve then answers.
bool SupernodalView(const cholmod_factor* L, SupernodalFactorView* f) {
  if (!L->is_super || !L->is_ll || L->xtype != CHOLMOD_REAL || L->itype != CHOLMOD_INT) return false;
  f->n = int(L->n);
  f->nsuper = int(L->nsuper);
  f->super = static_cast<const int*>(L->super);
  f->pi = static_cast<const int*>(L->pi);
  f->px = static_cast<const int*>(L->px);
  f->s = static_cast<const int*>(L->s);
  f->x = static_cast<const double*>(L->x);
  f->perm = static_cast<const int*>(L->Perm);
  return true;
}

const char* OrderingName(int ordering) {
  switch (ordering) {
    case CHOLMOD_NATURAL: return "natural";
    case CHOLMOD_GIVEN: return "given";
    case CHOLMOD_AMD: return "amd";
    case CHOLMOD_METIS: return "metis";
    case CHOLMOD_NESDIS: return "nesdis";
    case CHOLMOD_COLAMD: return "colamd";
    case CHOLMOD_POSTORDERED: return "postordered";
  }
  return "unknown";
}

std::atomic<bool> blas_threads_chosen{false};

// One BLAS thread unless the user or the program chose otherwise. OpenBLAS's workers
// spin, then yield, while they wait for work; on a machine with other load (or next to our
// own OpenMP team) a 2-thread solve of model B measured 0.5 ms to 170 ms, and the fronts
// of these models are too small for a second thread to pay (docs/performance.md).
void DefaultBlasThreadsOnce() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (!blas_threads_chosen && !std::getenv("OPENBLAS_NUM_THREADS") && openblas_set_num_threads)
      openblas_set_num_threads(1);
  });
}

}  // namespace

struct CholmodSolver::Impl {
  SupernodalFactor llt;
  bool analyzed = false;
  // cholmod_solve2 workspace and result, kept between solves.
  cholmod_dense* x = nullptr;
  cholmod_dense* y = nullptr;
  cholmod_dense* e = nullptr;
  // The subtree-parallel triangular solves, scheduled for `scheduled_threads` threads.
  SupernodalTriangularSolve subtrees;
  int scheduled_threads = 0;
  std::vector<float> single_values;  // L's values rounded to float (set_single_precision)

  ~Impl() {
    // Before llt's destructor ends the cholmod_common these were allocated with.
    cholmod_common& c = llt.cholmod();
    if (x) cholmod_free_dense(&x, &c);
    if (y) cholmod_free_dense(&y, &c);
    if (e) cholmod_free_dense(&e, &c);
  }
};

CholmodSolver::CholmodSolver(CholmodOrdering ordering) : impl_(std::make_unique<Impl>()) {
  DefaultBlasThreadsOnce();
  cholmod_common& c = impl_->llt.cholmod();
  c.print = 0;  // failures are reported through LinearSolveReport, not printed
  switch (ordering) {
    case CholmodOrdering::kBest:
      // The analysis runs once per matrix pattern, so trying both costs little.
      c.nmethods = 2;
      c.method[0].ordering = CHOLMOD_AMD;
      c.method[1].ordering = CHOLMOD_METIS;
      break;
    case CholmodOrdering::kAmd:
      c.nmethods = 1;
      c.method[0].ordering = CHOLMOD_AMD;
      break;
    case CholmodOrdering::kMetis:
      c.nmethods = 1;
      c.method[0].ordering = CHOLMOD_METIS;
      break;
  }
  c.postorder = 1;  // postorder the elimination tree: larger supernodes
}

CholmodSolver::~CholmodSolver() = default;

void CholmodSolver::Prepare(const SystemMatrix& A) {
  // The CSR arrays of a symmetric matrix read as CSC describe the same matrix.
  const auto& m = A.csr();
  const Eigen::Map<const Eigen::SparseMatrix<double>> a(m.rows(), m.cols(), m.nonZeros(), m.outerIndexPtr(),
                                                        m.innerIndexPtr(), m.valuePtr());
  if (!impl_->analyzed) {
    impl_->llt.analyzePattern(a);
    impl_->analyzed = impl_->llt.factor() != nullptr;
  }
  if (!impl_->analyzed) {
    ok_ = false;
    return;
  }
  // Debian's libcholmod opens OpenMP teams of a fixed 4 threads (CHOLMOD_OMP_NUM_THREADS)
  // inside the numeric factorization. On 2 busy cores that made it 2-4x slower (B: 42 ms
  // against 11 ms with OMP_THREAD_LIMIT=1, docs/performance.md). Dynamic teams (an ICV of
  // this thread only) let libgomp shrink them to the idle cores (cores - load average).
  const int dynamic = omp_get_dynamic();
  omp_set_dynamic(1);
  cholmod_sparse view = SymmetricView(m);
  impl_->llt.FactorizeView(view);
  omp_set_dynamic(dynamic);
  ok_ = impl_->llt.info() == Eigen::Success;
  impl_->single_values.clear();
  SupernodalFactorView f;
  if (ok_ && single_precision_ && SupernodalView(impl_->llt.factor(), &f))
    impl_->single_values.assign(f.x, f.x + impl_->llt.factor()->xsize);
}

LinearSolveReport CholmodSolver::Solve(const SystemMatrix&, const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  LinearSolveReport report;
  if (!ok_) {
    report.converged = false;
    return report;
  }
  if (b.isZero(0.0)) {  // at rest: nothing to solve (as DirectLdltSolver)
    x.setZero(b.size());
    return report;
  }
  const int threads = omp_get_max_threads();
  // Inside a parallel region (a caller solving columns on its threads) the team is not ours.
  const bool single = !impl_->single_values.empty();
  const bool subtrees = single || solve_path_ == CholmodSolvePath::kSubtrees ||
                        (solve_path_ == CholmodSolvePath::kAuto && threads > 1 && !omp_in_parallel());
  SupernodalFactorView f;
  if (subtrees && SupernodalView(impl_->llt.factor(), &f)) {
    if (impl_->scheduled_threads != threads) {
      impl_->subtrees.Analyze(f, threads);
      impl_->scheduled_threads = threads;
    }
    x.resize(b.size());
    if (single)
      impl_->subtrees.SolveSingle(f, impl_->single_values.data(), b.data(), x.data());
    else
      impl_->subtrees.Solve(f, b.data(), x.data());
    report.converged = x.allFinite();
    return report;
  }
  cholmod_common& c = impl_->llt.cholmod();
  cholmod_dense rhs;
  std::memset(&rhs, 0, sizeof(rhs));
  rhs.nrow = size_t(b.size());
  rhs.ncol = 1;
  rhs.nzmax = size_t(b.size());
  rhs.d = size_t(b.size());
  rhs.x = const_cast<double*>(b.data());  // read only by cholmod_solve2
  rhs.xtype = CHOLMOD_REAL;
  rhs.dtype = CHOLMOD_DOUBLE;
  if (!cholmod_solve2(CHOLMOD_A, impl_->llt.factor(), &rhs, nullptr, &impl_->x, nullptr, &impl_->y, &impl_->e, &c)) {
    report.converged = false;
    return report;
  }
  x = Eigen::Map<const Eigen::VectorXd>(static_cast<const double*>(impl_->x->x), b.size());
  report.converged = x.allFinite();
  return report;
}

double CholmodSolver::solve_serial_fraction() const {
  return impl_->scheduled_threads > 0 ? impl_->subtrees.serial_fraction() : 1.0;
}

double CholmodSolver::factor_nonzeros() const {
  return impl_->analyzed ? impl_->llt.cholmod().lnz : 0.0;
}

double CholmodSolver::factor_stored_entries() const {
  const cholmod_factor* f = impl_->llt.factor();
  return f ? double(f->xsize) : 0.0;
}

double CholmodSolver::factor_flops() const { return impl_->analyzed ? impl_->llt.cholmod().fl : 0.0; }

std::string CholmodSolver::ordering_used() const {
  const cholmod_factor* f = impl_->llt.factor();
  return f ? OrderingName(f->ordering) : "";
}

bool SetBlasThreads(int threads) {
  if (!openblas_set_num_threads || threads < 1) return false;
  blas_threads_chosen = true;
  openblas_set_num_threads(threads);
  return true;
}

int BlasThreads() { return openblas_get_num_threads ? openblas_get_num_threads() : 0; }

}  // namespace sedbridge::fem
