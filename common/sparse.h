#pragma once
// Sparse tools shared by the implicit labs (06 projective dynamics, 07 KKT and
// Schur, 09 geometric stiffness): which particles are unknowns, assembly from
// triplets, and one symmetric positive definite factorization reused for many
// solves (Eigen's simplicial LDLᵀ, or CHOLMOD's supernodal LLᵀ for large
// factors). Derivations: labs/lab06_projective_dynamics/README.md.
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

namespace cl {

using SparseMatrix = Eigen::SparseMatrix<double>;  // column-major
using Triplet = Eigen::Triplet<double>;
// One row per unknown, one column per coordinate (x, y, z); row-major so that
// an unknown's three values sit together in memory.
using RowsX3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

// Pinned particles (inverse mass 0) are not unknowns: their positions are data.
// Unknowns are the movable particles in scene order.
struct MovableMap {
  std::vector<int> unknown_of;   // per particle: its unknown index, or -1 when pinned
  std::vector<int> particle_of;  // per unknown: its particle index
  int unknowns() const { return static_cast<int>(particle_of.size()); }
};

// Builds the map from inverse masses (> 0: movable). Throws std::invalid_argument
// for a negative or non-finite inverse mass.
MovableMap make_movable_map(const Eigen::VectorXd& inv_mass);

// A rows × cols sparse matrix from triplets; duplicates are summed (that is how
// per-element contributions add up). Throws std::invalid_argument, naming the
// triplet, for an index out of range or a non-finite value.
SparseMatrix assemble(Eigen::Index rows, Eigen::Index cols, const std::vector<Triplet>& triplets);

// Unknown rows of a 3 × n per-particle array (positions, velocities, forces).
RowsX3 gather_rows(const Eigen::Matrix3Xd& values, const MovableMap& map);
// Writes unknown rows back into the movable columns; pinned columns are untouched.
void scatter_rows(const RowsX3& rows, const MovableMap& map, Eigen::Matrix3Xd& values);

// The same, stacked as one vector of 3 entries per unknown (x, y, z), for
// systems that couple the coordinates (a Jacobian's columns 3u, 3u+1, 3u+2).
Eigen::VectorXd gather_stacked(const Eigen::Matrix3Xd& values, const MovableMap& map);
void scatter_stacked(const Eigen::VectorXd& stacked, const MovableMap& map, Eigen::Matrix3Xd& values);

// Which factorization holds an SpdFactorization's factor.
//   kSimplicial  Eigen's SimplicialLDLT with an AMD ordering (CHOLMOD's AMD
//                when the suite has CHOLMOD, else Eigen's): one column of L at
//                a time. No dependency, and the fastest for small factors.
//   kSupernodal  CHOLMOD's supernodal LLᵀ (SuiteSparse): columns of L with the
//                same pattern are grouped into dense blocks factored by the BLAS
//                (level 3), so it is only as fast as the BLAS it links
//                (OpenBLAS on Debian: libopenblas-dev). Only when the suite was
//                built with CHOLMOD (cholmod_available()); otherwise kSimplicial.
//   kAutomatic   kSupernodal when CHOLMOD is available and the factorization's
//                flop count is at least kSupernodalFlops, else kSimplicial.
enum class SpdBackend { kSimplicial, kSupernodal, kAutomatic };
const char* backend_name(SpdBackend backend);  // "simplicial-ldlt", "supernodal-llt", "automatic"
// True when the suite was built with CHOLMOD (Debian's libsuitesparse-dev).
bool cholmod_available();
// Sets the threads of the BLAS behind the supernodal factorization where the
// BLAS offers it (OpenBLAS's openblas_set_num_threads, looked up at run time,
// so any BLAS links); returns whether it could. OpenBLAS otherwise takes every
// core, and its waiting threads spin: a benchmark that times serial methods
// side by side sets 1, or a second job on the machine slows it many-fold.
// A program that never calls it gets 1 at its first supernodal factorization,
// unless OPENBLAS_NUM_THREADS is set (then OpenBLAS's own reading of it stands).
bool set_blas_threads(int threads);

// The flop count (Σ_j c_j², c_j the entries of L below the diagonal in column
// j, in CHOLMOD's ordering) from which kAutomatic takes the supernodal
// factorization. Measured with bench/bench_lab06 (BM_FactorBackends, CPU
// time, OpenBLAS): PD's A at 64² (4·10⁶) factors faster with Eigen, Newton's
// Hessian at 32² (1.2·10⁷) twice as fast with CHOLMOD, 6× at 128² (10⁹),
// both before CHOLMOD got the coarser supernodes it has now (common/sparse.cpp),
// which made it faster still.
inline constexpr double kSupernodalFlops = 1e7;

// How many numeric factorizations each backend has done in this process, over
// every SpdFactorization: for the bench's record of which one ran.
struct SpdBackendCounts {
  long long simplicial = 0, supernodal = 0;
};
SpdBackendCounts spd_backend_counts();

// A sparse factorization of a symmetric positive definite matrix, kept for
// many solves: Eigen's simplicial LDLᵀ or CHOLMOD's supernodal LLᵀ (above).
// Both answer the same questions the same way; only their speed differs.
class SpdFactorization {
 public:
  explicit SpdFactorization(SpdBackend choice = SpdBackend::kAutomatic);
  ~SpdFactorization();
  SpdFactorization(const SpdFactorization&) = delete;  // neither factor is copied
  SpdFactorization& operator=(const SpdFactorization&) = delete;

  // Factors `a` (square, symmetric; the lower triangle is read). Returns false,
  // and keeps no factor, when `a` is not positive definite to working
  // precision (a pivot of D, or the square of a diagonal entry of L, that is
  // not finite and > n·1e-15 times the largest), e.g. a singular Schur
  // complement. Counts every call in factorizations().
  bool factor(const SparseMatrix& a);
  // The same for a matrix whose values changed but whose sparsity pattern did
  // not (Newton's Hessian, a KKT matrix): the ordering and symbolic analysis
  // of the last factor() (and its choice of backend) are reused and only the
  // numeric factorization is redone. When the pattern differs (or nothing was
  // factored yet) it is factor(a). Counts in factorizations() like factor().
  bool refactor(const SparseMatrix& a);
  bool ok() const { return ok_; }
  int factorizations() const { return factorizations_; }
  Eigen::Index size() const { return size_; }
  SpdBackend choice() const { return choice_; }
  // The backend of the last analysis: kSimplicial or kSupernodal (kSimplicial
  // before any).
  SpdBackend backend() const { return backend_; }
  // The last analysis's flop count (as kSupernodalFlops counts it, in the
  // ordering of the backend that analysed last); 0 before any.
  double flops() const { return flops_; }

  // Solves A X = B for three right-hand sides at once. Simplicial: ONE pass
  // over the factor, each entry of L loaded once and applied to all three
  // columns; supernodal: CHOLMOD's blocked solve of the three columns.
  // Throws std::logic_error without a factor and std::invalid_argument when B
  // has the wrong number of rows.
  RowsX3 solve3(const RowsX3& b) const;
  // One right-hand side. Same errors.
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;

  // Eigen's own object, e.g. to compare with Eigen's column-by-column solve or
  // to solve many columns at once. When CHOLMOD holds the factor, Eigen's of
  // the same matrix is computed at the first call after each factorization
  // (the cost of a second factorization; ask for SpdBackend::kSimplicial to
  // avoid it).
  const Eigen::SimplicialLDLT<SparseMatrix>& eigen() const;

 private:
  // SimplicialLDLT with its symbolic analysis's column counts readable (the
  // flop count), and an analysis in a given fill-reducing order.
  class Ldlt : public Eigen::SimplicialLDLT<SparseMatrix> {
   public:
    double flops() const;
    // analyzePattern(a) with the order `order` (order[k]: the row of a that
    // is row k of P a Pᵀ) in place of Eigen's AMD.
    void analyze_in_order(const SparseMatrix& a, const std::vector<int>& order);
  };
  struct Cholmod;  // CHOLMOD's state (common/sparse.cpp); null unless used

  void require_factor(Eigen::Index rows) const;
  bool same_pattern(const SparseMatrix& a) const;
  bool numeric(const SparseMatrix& a);
  bool accept_pivots(Eigen::Index rows);
  void share_rows();

  SpdBackend choice_;
  SpdBackend backend_ = SpdBackend::kSimplicial;
  mutable Ldlt ldlt_;              // supernodal: computed by eigen() on demand
  Eigen::VectorXd inverse_d_;      // simplicial: 1 / D, for solve3
  // Simplicial, for solve3: column j of L's row indices are
  // shared_rows_[column_rows_[j] ...] (as many as the column has entries), one
  // list per run of columns with nested patterns (share_rows).
  std::vector<int> column_rows_, shared_rows_;
  std::vector<char> nests_next_;  // per column j: column j + 1's list is j's without its first entry
  mutable bool ldlt_stale_ = false;  // supernodal: ldlt_ is not this factor's
  std::unique_ptr<Cholmod> cholmod_;
  bool ok_ = false;
  int factorizations_ = 0;
  Eigen::Index size_ = 0;
  double flops_ = 0.0;
  // The pattern the symbolic analysis was made for (compressed column arrays).
  std::vector<int> analyzed_outer_, analyzed_inner_;
};

}  // namespace cl
