#include "common/sparse.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#ifndef _WIN32
#include <dlfcn.h>  // the BLAS's and OpenMP's setters, looked up at run time
#endif

#ifdef CL_HAVE_CHOLMOD
#include <cholmod.h>
#endif

namespace cl {

namespace {
std::atomic<bool> blas_threads_chosen{false};
}  // namespace

bool set_blas_threads(int threads) {
  if (threads < 1) throw std::invalid_argument("set_blas_threads: threads " + std::to_string(threads) + " < 1");
  blas_threads_chosen = true;
#ifdef _WIN32
  return false;  // no run-time lookup there; only CHOLMOD's supernodal factor calls the BLAS
#else
  void* symbol = dlsym(RTLD_DEFAULT, "openblas_set_num_threads");
  if (symbol == nullptr) return false;
  using SetThreads = void (*)(int);
  reinterpret_cast<SetThreads>(symbol)(threads);
  return true;
#endif
}

#ifdef CL_HAVE_CHOLMOD  // only CHOLMOD's factorization calls it (without, it would warn)
namespace {
// The first CHOLMOD factorization of a process whose program chose no BLAS
// threads (and whose environment names none) makes the BLAS serial: see
// set_blas_threads. A test program that factors a drape under a second job
// (./course test builds the sanitizer alongside) otherwise took 30 s and more
// for what one thread does in 4 s.
void default_blas_threads() {
  if (blas_threads_chosen.exchange(true)) return;
  if (std::getenv("OPENBLAS_NUM_THREADS") != nullptr) return;
  set_blas_threads(1);
}
}  // namespace
#endif

MovableMap make_movable_map(const Eigen::VectorXd& inv_mass) {
  MovableMap map;
  map.unknown_of.assign(static_cast<std::size_t>(inv_mass.size()), -1);
  for (Eigen::Index p = 0; p < inv_mass.size(); ++p) {
    const double w = inv_mass[p];
    if (!std::isfinite(w) || w < 0.0) {
      throw std::invalid_argument("make_movable_map: inv_mass[" + std::to_string(p) +
                                  "] must be finite and >= 0 (got " + std::to_string(w) + ")");
    }
    if (w > 0.0) {
      map.unknown_of[static_cast<std::size_t>(p)] = map.unknowns();
      map.particle_of.push_back(static_cast<int>(p));
    }
  }
  return map;
}

SparseMatrix assemble(Eigen::Index rows, Eigen::Index cols, const std::vector<Triplet>& triplets) {
  for (std::size_t t = 0; t < triplets.size(); ++t) {
    const Triplet& entry = triplets[t];
    if (entry.row() < 0 || entry.row() >= rows || entry.col() < 0 || entry.col() >= cols) {
      throw std::invalid_argument("assemble: triplet " + std::to_string(t) + " at (" +
                                  std::to_string(entry.row()) + ", " + std::to_string(entry.col()) +
                                  ") is outside " + std::to_string(rows) + " x " + std::to_string(cols));
    }
    if (!std::isfinite(entry.value())) {
      throw std::invalid_argument("assemble: triplet " + std::to_string(t) + " is not finite");
    }
  }
  SparseMatrix matrix(rows, cols);
  matrix.setFromTriplets(triplets.begin(), triplets.end());  // sums duplicates
  return matrix;
}

RowsX3 gather_rows(const Eigen::Matrix3Xd& values, const MovableMap& map) {
  RowsX3 rows(map.unknowns(), 3);
  for (int u = 0; u < map.unknowns(); ++u) rows.row(u) = values.col(map.particle_of[static_cast<std::size_t>(u)]).transpose();
  return rows;
}

void scatter_rows(const RowsX3& rows, const MovableMap& map, Eigen::Matrix3Xd& values) {
  for (int u = 0; u < map.unknowns(); ++u) values.col(map.particle_of[static_cast<std::size_t>(u)]) = rows.row(u).transpose();
}

Eigen::VectorXd gather_stacked(const Eigen::Matrix3Xd& values, const MovableMap& map) {
  Eigen::VectorXd stacked(3 * map.unknowns());
  for (int u = 0; u < map.unknowns(); ++u) {
    stacked.segment<3>(3 * u) = values.col(map.particle_of[static_cast<std::size_t>(u)]);
  }
  return stacked;
}

void scatter_stacked(const Eigen::VectorXd& stacked, const MovableMap& map, Eigen::Matrix3Xd& values) {
  for (int u = 0; u < map.unknowns(); ++u) {
    values.col(map.particle_of[static_cast<std::size_t>(u)]) = stacked.segment<3>(3 * u);
  }
}

const char* backend_name(SpdBackend backend) {
  switch (backend) {
    case SpdBackend::kSimplicial: return "simplicial-ldlt";
    case SpdBackend::kSupernodal: return "supernodal-llt";
    case SpdBackend::kAutomatic: break;
  }
  return "automatic";
}

#ifdef CL_HAVE_CHOLMOD
bool cholmod_available() { return true; }

namespace {

// CHOLMOD 5 (Debian 12's SuiteSparse 5.12) opens OpenMP regions of a fixed
// num_threads(4) inside its supernodal factorization (CHOLMOD_OMP_NUM_THREADS
// in cholmod_core.h), whatever the machine has and omp_set_num_threads says.
// Those regions only clear and copy (the arithmetic is in the BLAS, see
// set_blas_threads), yet on 2 cores their four threads, woken and put to sleep
// once per supernode, doubled Newton's iteration at 128² (bench/trade, one
// thread: 375 ms per iteration with them, 186 ms without). While CHOLMOD runs,
// this guard sets max-active-levels to 0, so every region it opens runs on the
// calling thread alone. libgomp keeps that setting process-wide, so the guard
// acts only outside active parallel regions (omp_get_active_level() == 0: no
// other OpenMP thread is running), and puts the old value back. Inside an
// active region CHOLMOD's regions are nested and already serial unless nesting
// was switched on. The functions are looked up at run time, like the BLAS's
// setter: common is compiled without OpenMP, and without an OpenMP runtime in
// the process the guard does nothing.
//
// A region that runs on one thread still costs a system call: libgomp ends
// every region with its team's final barrier, whose last thread wakes the
// others with futex(FUTEX_WAKE) whether or not any sleeps (libgomp's
// config/linux/bar.c). CHOLMOD opens a few regions per supernode: about
// 4,700 wake calls in each factorization of lab 13's 128² Schur complement
// (strace), about 8 % of lab 13's iteration there. So while the guard is up, the
// calling thread's regions skip libgomp altogether: GOMP_parallel below (the
// one entry point CHOLMOD calls) runs the region's body on the calling thread,
// which is what a team of one does (omp_get_thread_num() = 0 and
// omp_get_num_threads() = 1 there, so CHOLMOD's loops take every iteration).
thread_local int serial_regions_here = 0;  // guards up on this thread

class SerialOpenMpRegions {
 public:
  SerialOpenMpRegions() {
    using Get = int (*)();
    static const auto active_level = reinterpret_cast<Get>(dlsym(RTLD_DEFAULT, "omp_get_active_level"));
    static const auto get_levels = reinterpret_cast<Get>(dlsym(RTLD_DEFAULT, "omp_get_max_active_levels"));
    static const auto set_levels = reinterpret_cast<Set>(dlsym(RTLD_DEFAULT, "omp_set_max_active_levels"));
    if (active_level == nullptr || get_levels == nullptr || set_levels == nullptr || active_level() != 0) return;
    set_ = set_levels;
    saved_ = get_levels();
    set_(0);
    ++serial_regions_here;
  }
  ~SerialOpenMpRegions() {
    if (set_ == nullptr) return;
    --serial_regions_here;
    set_(saved_);
  }
  SerialOpenMpRegions(const SerialOpenMpRegions&) = delete;
  SerialOpenMpRegions& operator=(const SerialOpenMpRegions&) = delete;

 private:
  using Set = void (*)(int);
  Set set_ = nullptr;
  int saved_ = 0;
};

}  // namespace
}  // namespace cl

// libgomp's entry point for `#pragma omp parallel`, interposed (the program's
// definition comes first in the dynamic linker's search, so CHOLMOD's calls
// land here; see SerialOpenMpRegions). Under a guard: the body on this thread.
// Otherwise: libgomp's own (RTLD_NEXT), so lab 12's parallel sweeps are
// untouched. Weak: a program with its own (lab 12's test that counts regions)
// keeps it, and CHOLMOD then runs through libgomp as before.
extern "C" __attribute__((weak)) void GOMP_parallel(void (*body)(void*), void* data, unsigned threads,
                                                     unsigned flags) {
  using Parallel = void (*)(void (*)(void*), void*, unsigned, unsigned);
  static const auto libgomp = reinterpret_cast<Parallel>(dlsym(RTLD_NEXT, "GOMP_parallel"));
  if (cl::serial_regions_here > 0 || libgomp == nullptr) {
    body(data);
    return;
  }
  libgomp(body, data, threads, flags);
}

namespace cl {
namespace {

// CHOLMOD's header over compressed-column arrays of an n × n symmetric
// matrix whose lower triangle (rows sorted in each column) is what counts.
cholmod_sparse lower_triangle(std::size_t n, std::size_t entries, int* outer, int* inner, double* values) {
  cholmod_sparse view{};
  view.nrow = view.ncol = n;
  view.nzmax = entries;
  view.p = outer;
  view.i = inner;
  view.x = values;
  view.stype = -1;
  view.itype = CHOLMOD_INT;
  view.xtype = CHOLMOD_REAL;
  view.dtype = CHOLMOD_DOUBLE;
  view.sorted = 1;
  view.packed = 1;
  return view;
}

}  // namespace

// One CHOLMOD workspace and factor per SpdFactorization that uses it.
struct SpdFactorization::Cholmod {
  cholmod_common common;
  cholmod_factor* factor = nullptr;
  Cholmod() {
    default_blas_threads();
    cholmod_start(&common);
    common.print = 0;  // library code never prints: failures are return values here
    common.supernodal = CHOLMOD_SUPERNODAL;
    // Coarser supernodes than CHOLMOD's defaults (nrelax 4, 16, 48; zrelax
    // 0.8, 0.1, 0.05): two supernodes merge while the result has at most 16
    // columns, or at most 64 with ≤ 30 % explicit zeros, or 128 with ≤ 20 %.
    // Fewer, larger supernodes mean fewer (and larger) BLAS calls and fewer of
    // the per-supernode OpenMP regions that SerialOpenMpRegions runs on one
    // thread (then each still cost a system call on its way out; now none,
    // see GOMP_parallel). Measured on the
    // curtains at k = 1e6, one thread, idle: lab 06's Newton iteration 0.130 →
    // 0.092 s on 128², 0.026 → 0.016 s on 64², 0.0050 → 0.0031 s on 32²;
    // lab 13's 0.137 → 0.104 s on 128². Only the numeric factorization's
    // blocking changes: the fill-reducing ordering, the exact column counts
    // (kSupernodalFlops's test) and the result, to round-off, are the same.
    common.nrelax[0] = 16;
    common.nrelax[1] = 64;
    common.nrelax[2] = 128;
    common.zrelax[0] = 0.8;
    common.zrelax[1] = 0.3;
    common.zrelax[2] = 0.2;
  }
  ~Cholmod() {
    if (factor != nullptr) cholmod_free_factor(&factor, &common);
    cholmod_finish(&common);
  }
  Cholmod(const Cholmod&) = delete;
  Cholmod& operator=(const Cholmod&) = delete;

  // S = tril(P A Pᵀ), the matrix CHOLMOD's supernodal numeric factorization
  // reads (P: the analysis's fill-reducing ordering). cholmod_factorize makes
  // it from a lower triangle with two transposes, each a fresh allocation, on
  // every call: 7 % of lab 13's iteration at 128² (perf, settled steps).
  // Its pattern depends only on A's, so it is made once per analysis
  // (permute), with `source`, the entry of A each of its values comes from;
  // a numeric factorization then only gathers the values (numeric). The
  // values and their places are those the transposes give, so the factor is
  // the same to the bit (checked on the curtains' matrices when written).
  std::vector<int> permuted_outer, permuted_inner, source;
  std::vector<double> permuted_values;

  void permute(const SparseMatrix& a) {
    const auto n = static_cast<int>(a.rows());
    const int* order = static_cast<const int*>(factor->Perm);
    std::vector<int> position(static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k) position[static_cast<std::size_t>(order == nullptr ? k : order[k])] = k;
    const int* outer = a.outerIndexPtr();
    const int* inner = a.innerIndexPtr();
    // Column j of S holds the entries whose permuted row and column meet at
    // (max, min): count, place, then sort each column by row.
    permuted_outer.assign(static_cast<std::size_t>(n) + 1, 0);
    auto each_lower = [&](auto&& visit) {
      for (int j = 0; j < n; ++j) {
        for (int p = outer[j]; p < outer[j + 1]; ++p) {
          if (inner[p] < j) continue;  // the upper triangle: CHOLMOD ignores it (stype -1)
          const int r = position[static_cast<std::size_t>(inner[p])], c = position[static_cast<std::size_t>(j)];
          visit(std::max(r, c), std::min(r, c), p);
        }
      }
    };
    each_lower([&](int, int column, int) { ++permuted_outer[static_cast<std::size_t>(column) + 1]; });
    for (std::size_t j = 0; j + 1 < permuted_outer.size(); ++j) permuted_outer[j + 1] += permuted_outer[j];
    const auto entries = static_cast<std::size_t>(permuted_outer.back());
    permuted_inner.resize(entries);
    source.resize(entries);
    std::vector<int> next(permuted_outer.begin(), permuted_outer.end() - 1);
    each_lower([&](int row, int column, int p) {
      const auto slot = static_cast<std::size_t>(next[static_cast<std::size_t>(column)]++);
      permuted_inner[slot] = row;
      source[slot] = p;
    });
    std::vector<std::pair<int, int>> column;
    for (int j = 0; j < n; ++j) {
      const auto at = static_cast<std::size_t>(j);
      const auto begin = static_cast<std::size_t>(permuted_outer[at]), end = static_cast<std::size_t>(permuted_outer[at + 1]);
      column.clear();
      for (std::size_t k = begin; k < end; ++k) column.emplace_back(permuted_inner[k], source[k]);
      std::sort(column.begin(), column.end());
      for (std::size_t k = begin; k < end; ++k) std::tie(permuted_inner[k], source[k]) = column[k - begin];
    }
    permuted_values.resize(entries);
  }

  // The numeric factorization of `a` (the analysed pattern) into `factor`:
  // cholmod_factorize's supernodal branch, without its transposes. Returns
  // CHOLMOD's verdict; `factor->minor` < n when `a` is not positive definite.
  bool numeric(const SparseMatrix& a) {
    const double* values = a.valuePtr();
    for (std::size_t k = 0; k < source.size(); ++k) permuted_values[k] = values[source[k]];
    cholmod_sparse s = lower_triangle(static_cast<std::size_t>(a.rows()), permuted_values.size(),
                                      permuted_outer.data(), permuted_inner.data(), permuted_values.data());
    double beta[2] = {0.0, 0.0};
    common.status = CHOLMOD_OK;
    return cholmod_super_numeric(&s, nullptr, beta, factor, &common) != 0;
  }
};

namespace {

// CHOLMOD's view of a compressed Eigen matrix (no copy): its lower triangle.
cholmod_sparse view_of(const SparseMatrix& a) {
  return lower_triangle(static_cast<std::size_t>(a.rows()), static_cast<std::size_t>(a.nonZeros()),
                        const_cast<int*>(a.outerIndexPtr()), const_cast<int*>(a.innerIndexPtr()),
                        const_cast<double*>(a.valuePtr()));
}

// Solves A X = B for B's columns (column-major, n × columns) in place.
void cholmod_solve_columns(cholmod_factor* factor, cholmod_common& common, double* data, Eigen::Index rows,
                           Eigen::Index columns) {
  cholmod_dense b{};
  b.nrow = static_cast<std::size_t>(rows);
  b.ncol = static_cast<std::size_t>(columns);
  b.nzmax = b.nrow * b.ncol;
  b.d = b.nrow;
  b.x = data;
  b.xtype = CHOLMOD_REAL;
  b.dtype = CHOLMOD_DOUBLE;
  const SerialOpenMpRegions serial;
  cholmod_dense* x = cholmod_solve(CHOLMOD_A, factor, &b, &common);
  if (x == nullptr) throw std::runtime_error("SpdFactorization: CHOLMOD's solve failed (out of memory?)");
  std::copy(static_cast<const double*>(x->x), static_cast<const double*>(x->x) + rows * columns, data);
  cholmod_free_dense(&x, &common);
}

// CHOLMOD's AMD order of `a`'s lower triangle (order[k]: the row of `a` that
// comes k-th), for Eigen's simplicial factorization. It leaves fewer entries
// in L than Eigen's AMD (a port of CSparse's) on the course's matrices: PD's A
// on the 128² curtain 514,225 instead of 574,742 (0.89×), on 64² 98,169
// instead of 105,344 (0.93×); METIS gave 552,288 at 128². Each solve3 reads
// every entry of L twice, so that is the solve's cost. Returns false if
// CHOLMOD fails (out of memory): Eigen's own AMD then.
bool cholmod_amd_order(const SparseMatrix& a, std::vector<int>& order) {
  cholmod_common common;
  cholmod_start(&common);
  common.print = 0;
  common.nmethods = 1;
  common.method[0].ordering = CHOLMOD_AMD;
  common.postorder = 1;
  common.supernodal = CHOLMOD_SIMPLICIAL;  // the order and column counts only
  cholmod_sparse view = view_of(a);
  cholmod_factor* symbolic = nullptr;
  {
    const SerialOpenMpRegions serial;
    symbolic = cholmod_analyze(&view, &common);
  }
  const bool ok = symbolic != nullptr;
  if (ok) {
    const int* perm = static_cast<const int*>(symbolic->Perm);
    order.assign(perm, perm + a.rows());
    cholmod_free_factor(&symbolic, &common);
  }
  cholmod_finish(&common);
  return ok;
}

}  // namespace
#else
bool cholmod_available() { return false; }
struct SpdFactorization::Cholmod {};
#endif

namespace {
std::atomic<long long> simplicial_count{0}, supernodal_count{0};
}  // namespace

SpdBackendCounts spd_backend_counts() {
  SpdBackendCounts counts;
  counts.simplicial = simplicial_count.load();
  counts.supernodal = supernodal_count.load();
  return counts;
}

double SpdFactorization::Ldlt::flops() const {
  double sum = 0.0;
  for (Eigen::Index j = 0; j < m_nonZerosPerCol.size(); ++j) {
    const double below = static_cast<double>(m_nonZerosPerCol[j]);
    sum += below * below;
  }
  return sum;
}

void SpdFactorization::Ldlt::analyze_in_order(const SparseMatrix& a, const std::vector<int>& order) {
  // What Eigen's analyzePattern does after its own ordering (its ordering()
  // computes P⁻¹ too, then P and the permuted upper triangle).
  m_Pinv.resize(a.rows());
  std::copy(order.begin(), order.end(), m_Pinv.indices().data());
  m_P = m_Pinv.inverse();
  CholMatrixType permuted(a.rows(), a.cols());
  permuted.selfadjointView<Eigen::Upper>() = a.selfadjointView<Eigen::Lower>().twistedBy(m_P);
  analyzePattern_preordered(permuted, true);
}

SpdFactorization::SpdFactorization(SpdBackend choice) : choice_(choice) {}
SpdFactorization::~SpdFactorization() = default;

bool SpdFactorization::factor(const SparseMatrix& a) {
  ++factorizations_;
  ok_ = false;
  size_ = 0;
  if (a.rows() != a.cols()) {
    throw std::invalid_argument("SpdFactorization::factor: the matrix is " + std::to_string(a.rows()) + " x " +
                                std::to_string(a.cols()) + ", not square");
  }
  SparseMatrix copy;
  const SparseMatrix* matrix = &a;
  if (!a.isCompressed()) {
    copy = a;
    copy.makeCompressed();
    matrix = &copy;
  }
  analyzed_outer_.clear();
  analyzed_inner_.clear();
  backend_ = SpdBackend::kSimplicial;
#ifdef CL_HAVE_CHOLMOD
  // kAutomatic with CHOLMOD: CHOLMOD's analysis first (its column counts give
  // the flop count), Eigen's only if the count is small, so that a large
  // matrix is analysed once. Below kSmallest rows even a dense factor has
  // fewer than kSupernodalFlops flops (n³/3): Eigen's analysis alone.
  constexpr Eigen::Index kSmallest = 300;
  std::vector<int> order;  // the simplicial factor's ordering, when CHOLMOD's analysis already made one
  if (choice_ == SpdBackend::kSupernodal || (choice_ == SpdBackend::kAutomatic && matrix->rows() >= kSmallest)) {
    if (!cholmod_) cholmod_ = std::make_unique<Cholmod>();
    if (cholmod_->factor != nullptr) cholmod_free_factor(&cholmod_->factor, &cholmod_->common);
    cholmod_sparse view = view_of(*matrix);
    const SerialOpenMpRegions serial;
    cholmod_->factor = cholmod_analyze(&view, &cholmod_->common);
    if (cholmod_->factor == nullptr) return false;
    const int* counts = static_cast<const int*>(cholmod_->factor->ColCount);
    flops_ = 0.0;
    for (std::size_t j = 0; j < cholmod_->factor->n; ++j) {
      const double below = static_cast<double>(counts[j] - 1);
      flops_ += below * below;
    }
    if (choice_ == SpdBackend::kSupernodal || flops_ >= kSupernodalFlops) {
      backend_ = SpdBackend::kSupernodal;
      cholmod_->permute(*matrix);
    } else {
      // Eigen's factor, below, in the order this analysis chose (not a second analysis).
      const int* perm = static_cast<const int*>(cholmod_->factor->Perm);
      order.assign(perm, perm + matrix->rows());
      cholmod_free_factor(&cholmod_->factor, &cholmod_->common);
    }
  }
#endif
  if (backend_ == SpdBackend::kSimplicial) {
#ifdef CL_HAVE_CHOLMOD
    if (!order.empty() || cholmod_amd_order(*matrix, order)) {
      ldlt_.analyze_in_order(*matrix, order);
    } else {
      ldlt_.analyzePattern(*matrix);
    }
#else
    ldlt_.analyzePattern(*matrix);
#endif
    flops_ = ldlt_.flops();
  }
  analyzed_outer_.assign(matrix->outerIndexPtr(), matrix->outerIndexPtr() + matrix->outerSize() + 1);
  analyzed_inner_.assign(matrix->innerIndexPtr(), matrix->innerIndexPtr() + matrix->nonZeros());
  return numeric(*matrix);
}

bool SpdFactorization::same_pattern(const SparseMatrix& a) const {
  if (a.rows() != a.cols() || a.outerSize() + 1 != static_cast<Eigen::Index>(analyzed_outer_.size())) return false;
  if (!a.isCompressed()) return false;
  return std::equal(analyzed_outer_.begin(), analyzed_outer_.end(), a.outerIndexPtr()) &&
         a.nonZeros() == static_cast<Eigen::Index>(analyzed_inner_.size()) &&
         std::equal(analyzed_inner_.begin(), analyzed_inner_.end(), a.innerIndexPtr());
}

bool SpdFactorization::refactor(const SparseMatrix& a) {
  if (analyzed_outer_.empty() || !same_pattern(a)) return factor(a);
  ++factorizations_;
  ok_ = false;
  size_ = 0;
  return numeric(a);
}

bool SpdFactorization::numeric(const SparseMatrix& a) {
  if (backend_ == SpdBackend::kSimplicial) {
    ++simplicial_count;
    ldlt_.factorize(a);
    return accept_pivots(a.rows());
  }
#ifdef CL_HAVE_CHOLMOD
  ++supernodal_count;
  cholmod_factor* factor = cholmod_->factor;
  const SerialOpenMpRegions serial;
  // Not positive definite: CHOLMOD stops at column `minor` < n.
  if (!cholmod_->numeric(a) || cholmod_->common.status != CHOLMOD_OK || factor->minor < factor->n) {
    return false;
  }
  // (min_j L_jj / max_j L_jj)² = min d / max d of the LDLᵀ form: the same floor
  // as accept_pivots. NaN fails the comparison too.
  const double rcond = cholmod_rcond(factor, &cholmod_->common);
  if (!(rcond > static_cast<double>(a.rows()) * 1e-15)) return false;
  ldlt_stale_ = true;
  ok_ = true;
  size_ = a.rows();
  return true;
#else
  return false;
#endif
}

bool SpdFactorization::accept_pivots(Eigen::Index rows) {
  if (ldlt_.info() != Eigen::Success) return false;
  const Eigen::VectorXd& d = ldlt_.vectorD();
  // A pivot that is not clearly positive means A is singular or indefinite to
  // working precision; solving with it would amplify round-off without bound.
  const double largest = d.size() > 0 ? d.cwiseAbs().maxCoeff() : 0.0;
  const double floor = largest * static_cast<double>(d.size()) * 1e-15;
  for (Eigen::Index k = 0; k < d.size(); ++k) {
    if (!std::isfinite(d[k]) || !(d[k] > floor)) return false;
  }
  inverse_d_ = d.cwiseInverse();
  share_rows();
  ok_ = true;
  size_ = rows;
  return true;
}

// Columns j and j + 1 of L often have the same rows below j + 1 (a
// supernode: column j's rows are j + 1 and then column j + 1's). Then column
// j + 1's row list is column j's without its first entry, and a run of such
// columns needs one list, each column starting one entry later. On PD's
// curtains that is 117,187 indices instead of 574,742 at 128² (27,773 instead
// of 105,344 at 64²), so solve3 reads 8 bytes an entry of L instead of 12;
// the values, and the order in which solve3 uses them, are unchanged.
// Checked entry by entry, so any pattern is right (a column that does not
// nest gets a list of its own). Made after every numeric factorization:
// Eigen writes L's row indices there, and one pass over them costs little
// next to the factorization itself.
void SpdFactorization::share_rows() {
  const SparseMatrix& lower = ldlt_.matrixL().nestedExpression();
  const int* outer = lower.outerIndexPtr();
  const int* inner = lower.innerIndexPtr();
  const auto n = static_cast<int>(lower.outerSize());
  column_rows_.resize(static_cast<std::size_t>(n));
  nests_next_.assign(static_cast<std::size_t>(n), 0);
  shared_rows_.clear();
  for (int j = 0; j < n; ++j) {
    const int count = outer[j + 1] - outer[j];
    const bool nested = j > 0 && outer[j] - outer[j - 1] == count + 1 && inner[outer[j - 1]] == j &&
                        std::equal(inner + outer[j], inner + outer[j + 1], inner + outer[j - 1] + 1);
    if (nested) {
      column_rows_[static_cast<std::size_t>(j)] = column_rows_[static_cast<std::size_t>(j) - 1] + 1;
      nests_next_[static_cast<std::size_t>(j) - 1] = 1;
    } else {
      column_rows_[static_cast<std::size_t>(j)] = static_cast<int>(shared_rows_.size());
      shared_rows_.insert(shared_rows_.end(), inner + outer[j], inner + outer[j + 1]);
    }
  }
}

void SpdFactorization::require_factor(Eigen::Index rows) const {
  if (!ok_) throw std::logic_error("SpdFactorization: no factor (factor() failed or was not called)");
  if (rows != size_) {
    throw std::invalid_argument("SpdFactorization: right-hand side has " + std::to_string(rows) +
                                " rows, the factor " + std::to_string(size_));
  }
}

const Eigen::SimplicialLDLT<SparseMatrix>& SpdFactorization::eigen() const {
#ifdef CL_HAVE_CHOLMOD
  if (backend_ == SpdBackend::kSupernodal && ok_ && ldlt_stale_) {
    // The factored matrix's lower triangle, put back in A's places from the
    // permuted copy CHOLMOD read (Cholmod::numeric; ok_ means it is the last
    // one's): no copy of A's values on each factorization for a call that
    // seldom comes. The upper triangle stays 0: Eigen's LDLᵀ reads the lower.
    std::vector<double> values(analyzed_inner_.size(), 0.0);
    for (std::size_t k = 0; k < cholmod_->source.size(); ++k) {
      values[static_cast<std::size_t>(cholmod_->source[k])] = cholmod_->permuted_values[k];
    }
    const Eigen::Map<const SparseMatrix> matrix(size_, size_, static_cast<Eigen::Index>(values.size()),
                                                analyzed_outer_.data(), analyzed_inner_.data(), values.data());
    ldlt_.compute(SparseMatrix(matrix));
    ldlt_stale_ = false;
  }
#endif
  return ldlt_;
}

RowsX3 SpdFactorization::solve3(const RowsX3& b) const {
  require_factor(b.rows());
#ifdef CL_HAVE_CHOLMOD
  if (backend_ == SpdBackend::kSupernodal) {
    Eigen::MatrixX3d columns = b;  // CHOLMOD's dense layout: column-major
    cholmod_solve_columns(cholmod_->factor, cholmod_->common, columns.data(), columns.rows(), 3);
    return columns;
  }
#endif
  // A = Pᵀ L D Lᵀ P with L unit lower triangular, stored without its diagonal.
  // y = P b; L z = y; w = D⁻¹ z; Lᵀ u = w; x = Pᵀ u — each loop over L's
  // columns moves all three coordinates together. Each entry's value is read
  // into a local once (a store through `row` may alias `value`, so the
  // compiler would reload it after each of the three), and D⁻¹ (kept since
  // the factorization: no division here) is applied as the backward pass
  // reaches each row — the same products as a separate pass. P and Pᵀ are the
  // gather into y and the write of each finished row into x (not Eigen's
  // permutation products: two more n × 3 temporaries and passes).
  //
  // The passes cost what they read: 12 bytes an entry of L (value and row
  // index; 6.9 MB at 128², beyond L2) and a row of y per entry. So the row
  // indices come from the shared lists (share_rows: 8 bytes an entry), and
  // where column j + 1 nests in column j (nests_next_) the two columns go
  // through their common rows together: each such row of y is read (and in
  // the forward pass written) once for both. With CHOLMOD's order
  // (cholmod_amd_order: fewer entries), lab 06's PD iteration, its executable
  // against the one before (--iterations 100, two sessions of 5–7
  // alternating pairs, ratio of the medians of wall time per iteration, a
  // shared noisy machine): 64² 0.33 → 0.29 ms (0.87×, 0.88×), 128² 1.91 →
  // 1.45 ms and 1.75 → 1.42 ms (0.76×, 0.81×). The solve alone, timed inside
  // the iteration against the previous solve3 in one process (CPU time):
  // 0.63–0.74× at 64², 0.61–0.65× at 128²; bench_lab06's BM_Solve3OnePass
  // (the factor hot in cache): 0.55–0.62× at 128², 0.57–0.71× at 32².
  //
  // The forward pass subtracts in the same order as one column at a time (a
  // row gets column j's product, then column j + 1's): the same bits for the
  // same factor. The backward pass's pair subtracts column j + 1's result from
  // column j's sum after their common rows rather than before them: round-off.
  const Eigen::Index n = size_;
  const auto& order = ldlt_.permutationPinv().indices();  // row j of P b is row order[j] of b
  const bool permuted = order.size() == n;                // Eigen keeps none for the natural order
  RowsX3 y(n, 3);
  RowsX3 x(n, 3);
  const double* source = b.data();
  double* data = y.data();
  double* solution = x.data();
  for (Eigen::Index j = 0; j < n; ++j) {
    const double* from = source + 3 * (permuted ? order[j] : j);
    data[3 * j] = from[0];
    data[3 * j + 1] = from[1];
    data[3 * j + 2] = from[2];
  }
  const SparseMatrix& lower = ldlt_.matrixL().nestedExpression();
  const int* outer = lower.outerIndexPtr();
  const int* column_rows = column_rows_.data();
  const int* shared_rows = shared_rows_.data();
  const char* nests_next = nests_next_.data();
  const double* value = lower.valuePtr();
  const double* inverse_d = inverse_d_.data();
  for (Eigen::Index j = 0; j < n; ++j) {
    const double y0 = data[3 * j], y1 = data[3 * j + 1], y2 = data[3 * j + 2];
    const int* rows = shared_rows + column_rows[j];
    const double* column = value + outer[j];
    const int count = outer[j + 1] - outer[j];
    if (nests_next[j]) {
      // Column j's first row is j + 1: finish it, then both columns together
      // (column j + 1's entry k - 1 is on column j's row k).
      const double l = column[0];
      const double z0 = data[3 * j + 3] - l * y0, z1 = data[3 * j + 4] - l * y1, z2 = data[3 * j + 5] - l * y2;
      data[3 * j + 3] = z0;
      data[3 * j + 4] = z1;
      data[3 * j + 5] = z2;
      const double* next = value + outer[j + 1] - 1;
      for (int k = 1; k < count; ++k) {
        const double a = column[k], c = next[k];
        double* row = data + 3 * rows[k];
        row[0] = (row[0] - a * y0) - c * z0;
        row[1] = (row[1] - a * y1) - c * z1;
        row[2] = (row[2] - a * y2) - c * z2;
      }
      ++j;
      continue;
    }
    for (int k = 0; k < count; ++k) {
      const double l = column[k];
      double* row = data + 3 * rows[k];
      row[0] -= l * y0;
      row[1] -= l * y1;
      row[2] -= l * y2;
    }
  }
  auto finish = [&](Eigen::Index j, double s0, double s1, double s2) {
    data[3 * j] = s0;
    data[3 * j + 1] = s1;
    data[3 * j + 2] = s2;
    double* to = solution + 3 * (permuted ? order[j] : j);
    to[0] = s0;
    to[1] = s1;
    to[2] = s2;
  };
  for (Eigen::Index j = n - 1; j >= 0; --j) {
    const int* rows = shared_rows + column_rows[j];
    const double* column = value + outer[j];
    const int count = outer[j + 1] - outer[j];
    double s0 = data[3 * j] * inverse_d[j], s1 = data[3 * j + 1] * inverse_d[j], s2 = data[3 * j + 2] * inverse_d[j];
    if (j > 0 && nests_next[j - 1]) {
      // Columns j - 1 and j: the common rows for both, then row j for j - 1.
      const Eigen::Index i = j - 1;
      const double* previous = value + outer[i] + 1;  // entry k on column j's row k
      double t0 = data[3 * i] * inverse_d[i], t1 = data[3 * i + 1] * inverse_d[i], t2 = data[3 * i + 2] * inverse_d[i];
      for (int k = 0; k < count; ++k) {
        const double a = column[k], c = previous[k];
        const double* row = data + 3 * rows[k];
        s0 -= a * row[0];
        s1 -= a * row[1];
        s2 -= a * row[2];
        t0 -= c * row[0];
        t1 -= c * row[1];
        t2 -= c * row[2];
      }
      const double l = previous[-1];
      finish(j, s0, s1, s2);
      finish(i, t0 - l * s0, t1 - l * s1, t2 - l * s2);
      --j;
      continue;
    }
    for (int k = 0; k < count; ++k) {
      const double l = column[k];
      const double* row = data + 3 * rows[k];
      s0 -= l * row[0];
      s1 -= l * row[1];
      s2 -= l * row[2];
    }
    finish(j, s0, s1, s2);
  }
  return x;
}

Eigen::VectorXd SpdFactorization::solve(const Eigen::VectorXd& b) const {
  require_factor(b.rows());
#ifdef CL_HAVE_CHOLMOD
  if (backend_ == SpdBackend::kSupernodal) {
    Eigen::VectorXd x = b;
    cholmod_solve_columns(cholmod_->factor, cholmod_->common, x.data(), x.rows(), 1);
    return x;
  }
#endif
  return ldlt_.solve(b);
}

}  // namespace cl
