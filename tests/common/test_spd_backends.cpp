// Unit tests of common/sparse's factorization choice (SpdBackend): Eigen's
// simplicial LDLᵀ and CHOLMOD's supernodal LLᵀ solve the same systems to
// round-off, refuse the same singular and indefinite matrices, and kAutomatic
// chooses by the flop count it documents. Without CHOLMOD in the build the
// supernodal requests fall back to Eigen, and the same checks hold.
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <dlfcn.h>

#include <Eigen/Dense>
#include "tests/support/catch.h"

#include "common/sparse.h"

using Catch::Matchers::WithinAbs;

namespace {

cl::SpdBackend supernodal_or_fallback() {
  return cl::cholmod_available() ? cl::SpdBackend::kSupernodal : cl::SpdBackend::kSimplicial;
}

// A mass-spring Hessian on an nx × nx grid: 3 unknowns per node, each edge
// (structural and both diagonals) a full 3×3 block k (n nᵀ + ½ I) with a
// random direction n, plus a positive diagonal. SPD, with the fill pattern of
// lab 06's Newton Hessian.
cl::SparseMatrix grid_hessian(std::mt19937_64& rng, int nx) {
  std::uniform_real_distribution<double> weight(0.5, 2.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<cl::Triplet> triplets;
  auto node = [nx](int i, int j) { return i * nx + j; };
  auto add_block = [&](int a, int b, const Eigen::Matrix3d& block) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) triplets.emplace_back(3 * a + r, 3 * b + c, block(r, c));
    }
  };
  for (int a = 0; a < nx * nx; ++a) add_block(a, a, Eigen::Matrix3d::Identity() * weight(rng));
  const int offsets[4][2] = {{0, 1}, {1, 0}, {1, 1}, {1, -1}};
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < nx; ++j) {
      for (const auto& offset : offsets) {
        const int i2 = i + offset[0], j2 = j + offset[1];
        if (i2 >= nx || j2 < 0 || j2 >= nx) continue;
        const Eigen::Vector3d n = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
        const Eigen::Matrix3d block = weight(rng) * (n * n.transpose() + 0.5 * Eigen::Matrix3d::Identity());
        const int a = node(i, j), b = node(i2, j2);
        add_block(a, a, block);
        add_block(b, b, block);
        add_block(a, b, -block);
        add_block(b, a, -block);
      }
    }
  }
  return cl::assemble(3 * nx * nx, 3 * nx * nx, triplets);
}

double max_abs(const Eigen::MatrixXd& m) { return m.size() > 0 ? m.cwiseAbs().maxCoeff() : 0.0; }

}  // namespace

TEST_CASE("the simplicial and the supernodal factorization give the same solves", "[sparse][backend]") {
  std::mt19937_64 rng(3);
  for (const int nx : {1, 4, 12}) {
    CAPTURE(nx);
    const cl::SparseMatrix a = grid_hessian(rng, nx);
    const Eigen::Index n = a.rows();
    const cl::RowsX3 b = cl::RowsX3::Random(n, 3);
    const Eigen::MatrixXd expected = Eigen::MatrixXd(a).ldlt().solve(Eigen::MatrixXd(b));
    const double tolerance = 1e-10 * max_abs(expected);
    cl::SpdFactorization simplicial(cl::SpdBackend::kSimplicial);
    cl::SpdFactorization supernodal(cl::SpdBackend::kSupernodal);
    REQUIRE(simplicial.factor(a));
    REQUIRE(supernodal.factor(a));
    CHECK(simplicial.backend() == cl::SpdBackend::kSimplicial);
    CHECK(supernodal.backend() == supernodal_or_fallback());
    for (const cl::SpdFactorization* factor : {&simplicial, &supernodal}) {
      CAPTURE(cl::backend_name(factor->backend()));
      CHECK_THAT(max_abs(Eigen::MatrixXd(factor->solve3(b)) - expected), WithinAbs(0.0, tolerance));
      CHECK_THAT(max_abs(factor->solve(b.col(2)) - expected.col(2)), WithinAbs(0.0, tolerance));
    }
    // New values on the same pattern: refactor reuses each backend's analysis.
    cl::SparseMatrix scaled = a;
    scaled.diagonal() += Eigen::VectorXd::Constant(n, 3.0);
    const Eigen::MatrixXd rescaled = Eigen::MatrixXd(scaled).ldlt().solve(Eigen::MatrixXd(b));
    for (cl::SpdFactorization* factor : {&simplicial, &supernodal}) {
      CAPTURE(cl::backend_name(factor->backend()));
      REQUIRE(factor->refactor(scaled));
      CHECK_THAT(max_abs(Eigen::MatrixXd(factor->solve3(b)) - rescaled), WithinAbs(0.0, 1e-10 * max_abs(rescaled)));
      CHECK(factor->factorizations() == 2);
    }
  }
}

TEST_CASE("both factorizations refuse a singular or indefinite matrix instead of returning NaN", "[sparse][backend]") {
  // A free chain's Laplacian (constants are its null space), a 2 × 2 indefinite
  // matrix, a pivot below round-off, and a NaN.
  std::vector<cl::Triplet> chain;
  for (int i = 0; i + 1 < 30; ++i) {
    chain.emplace_back(i, i, 1.0);
    chain.emplace_back(i + 1, i + 1, 1.0);
    chain.emplace_back(i, i + 1, -1.0);
    chain.emplace_back(i + 1, i, -1.0);
  }
  const cl::SparseMatrix singular = cl::assemble(30, 30, chain);
  const cl::SparseMatrix indefinite = cl::assemble(2, 2, {{0, 0, 1.0}, {1, 1, -1.0}, {0, 1, 0.5}, {1, 0, 0.5}});
  const cl::SparseMatrix tiny_pivot = cl::assemble(2, 2, {{0, 0, 1.0}, {1, 1, 1e-18}});
  const cl::SparseMatrix not_finite =
      cl::assemble(2, 2, {{0, 0, 1.0}, {1, 1, 1.0}}) * std::numeric_limits<double>::quiet_NaN();
  for (const cl::SpdBackend backend : {cl::SpdBackend::kSimplicial, cl::SpdBackend::kSupernodal}) {
    CAPTURE(cl::backend_name(backend));
    int which = 0;
    for (const cl::SparseMatrix* matrix : {&singular, &indefinite, &tiny_pivot, &not_finite}) {
      CAPTURE(which++);
      cl::SpdFactorization factor(backend);
      CHECK_FALSE(factor.factor(*matrix));
      CHECK_FALSE(factor.ok());
      CHECK_THROWS_AS(factor.solve3(cl::RowsX3::Zero(matrix->rows(), 3)), std::logic_error);
      CHECK_THROWS_AS(factor.solve(Eigen::VectorXd::Zero(matrix->rows())), std::logic_error);
    }
    // A refactor with indefinite values on a pattern that factored before.
    cl::SparseMatrix spd = cl::assemble(2, 2, {{0, 0, 2.0}, {1, 1, 2.0}, {0, 1, 0.5}, {1, 0, 0.5}});
    cl::SpdFactorization factor(backend);
    REQUIRE(factor.factor(spd));
    spd.coeffRef(1, 1) = -2.0;
    CHECK_FALSE(factor.refactor(spd));
    CHECK_FALSE(factor.ok());
    CHECK_THROWS_AS(factor.solve(Eigen::VectorXd::Zero(2)), std::logic_error);
    // ... and definite values again on that pattern (lab 13's retry after a
    // refusal): the factor left by the refusal is refilled, and it solves.
    spd.coeffRef(1, 1) = 3.0;
    REQUIRE(factor.refactor(spd));
    const Eigen::Vector2d b(1.0, -2.0);
    const Eigen::Vector2d expected = Eigen::Matrix2d(Eigen::MatrixXd(spd)).ldlt().solve(b);
    CHECK_THAT((factor.solve(b) - expected).cwiseAbs().maxCoeff(), WithinAbs(0.0, 1e-14));
  }
}

TEST_CASE("the automatic choice is supernodal exactly when CHOLMOD is there and the flops are many", "[sparse][backend]") {
  std::mt19937_64 rng(5);
  const cl::SparseMatrix small = grid_hessian(rng, 3);
  const cl::SparseMatrix large = grid_hessian(rng, 36);  // 3888 unknowns
  cl::SpdFactorization small_automatic;
  cl::SpdFactorization large_automatic;
  REQUIRE(small_automatic.factor(small));
  REQUIRE(large_automatic.factor(large));
  CAPTURE(small_automatic.flops(), large_automatic.flops(), cl::kSupernodalFlops);
  REQUIRE(small_automatic.flops() < cl::kSupernodalFlops);
  REQUIRE(large_automatic.flops() >= cl::kSupernodalFlops);
  CHECK(small_automatic.backend() == cl::SpdBackend::kSimplicial);
  CHECK(large_automatic.backend() == supernodal_or_fallback());
  CHECK(small_automatic.choice() == cl::SpdBackend::kAutomatic);
  // The choice changes only the speed.
  cl::SpdFactorization reference(cl::SpdBackend::kSimplicial);
  REQUIRE(reference.factor(large));
  const cl::RowsX3 b = cl::RowsX3::Random(large.rows(), 3);
  const Eigen::MatrixXd expected = reference.solve3(b);
  CHECK_THAT(max_abs(Eigen::MatrixXd(large_automatic.solve3(b)) - expected), WithinAbs(0.0, 1e-9 * max_abs(expected)));
  // eigen() is Eigen's factor of the same matrix whichever backend holds it.
  const Eigen::MatrixXd many = Eigen::MatrixXd::Random(large.rows(), 5);
  const Eigen::MatrixXd many_expected = reference.eigen().solve(many);
  CHECK_THAT(max_abs(large_automatic.eigen().solve(many) - many_expected),
             WithinAbs(0.0, 1e-9 * max_abs(many_expected)));
  // ... and of the last matrix factored: after a refactor with other values
  // (2A: the solution halves), and after a refused one followed by 2A again.
  const cl::SparseMatrix doubled = 2.0 * large;
  REQUIRE(large_automatic.refactor(doubled));
  CHECK_THAT(max_abs(large_automatic.eigen().solve(many) - 0.5 * many_expected),
             WithinAbs(0.0, 1e-9 * max_abs(many_expected)));
  REQUIRE_FALSE(large_automatic.refactor(-1.0 * large));
  REQUIRE(large_automatic.refactor(doubled));
  CHECK_THAT(max_abs(large_automatic.eigen().solve(many) - 0.5 * many_expected),
             WithinAbs(0.0, 1e-9 * max_abs(many_expected)));
}

TEST_CASE("one BLAS thread gives the supernodal factorization's solves and a count below 1 is refused",
          "[sparse][backend]") {
  CHECK_THROWS_AS(cl::set_blas_threads(0), std::invalid_argument);
  // With CHOLMOD the course's BLAS is OpenBLAS (./course installs it), which lets its threads be set.
  if (cl::cholmod_available()) CHECK(cl::set_blas_threads(1));
  std::mt19937_64 rng(7);
  const cl::SparseMatrix matrix = grid_hessian(rng, 24);
  cl::SpdFactorization supernodal(cl::SpdBackend::kSupernodal), reference(cl::SpdBackend::kSimplicial);
  REQUIRE(supernodal.factor(matrix));
  REQUIRE(reference.factor(matrix));
  const cl::RowsX3 b = cl::RowsX3::Random(matrix.rows(), 3);
  const Eigen::MatrixXd expected = reference.solve3(b);
  CHECK_THAT(max_abs(Eigen::MatrixXd(supernodal.solve3(b)) - expected), WithinAbs(0.0, 1e-9 * max_abs(expected)));
}

TEST_CASE("a program that chose no BLAS threads factors with one", "[sparse][backend]") {
  // OpenBLAS's own default is every core, and its idle threads spin: a test
  // program's drape took 30 s and more under a second job instead of 4 s.
  using GetThreads = int (*)();
  const auto get_threads = reinterpret_cast<GetThreads>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
  if (!cl::cholmod_available() || get_threads == nullptr || std::getenv("OPENBLAS_NUM_THREADS") != nullptr) {
    SUCCEED("no OpenBLAS behind CHOLMOD, or OPENBLAS_NUM_THREADS chooses");
    return;
  }
  std::mt19937_64 rng(11);
  const cl::SparseMatrix matrix = grid_hessian(rng, 24);
  cl::SpdFactorization supernodal(cl::SpdBackend::kSupernodal);
  REQUIRE(supernodal.factor(matrix));
  CHECK(get_threads() == 1);
  // A program that chooses keeps its choice: the default applies once, first.
  CHECK(cl::set_blas_threads(2));
  cl::SpdFactorization again(cl::SpdBackend::kSupernodal);
  REQUIRE(again.factor(matrix));
  CHECK(get_threads() == 2);
  cl::set_blas_threads(1);
}

namespace {

// The threads of this process now (Linux: /proc/self/status).
int process_threads() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("Threads:", 0) == 0) return std::stoi(line.substr(8));
  }
  return -1;
}

}  // namespace

TEST_CASE("the supernodal factorization starts no OpenMP threads and leaves max-active-levels as it was",
          "[sparse][backend]") {
  // CHOLMOD 5 asks for four OpenMP threads in its own loops; common/sparse.cpp
  // runs them on the calling thread (SerialOpenMpRegions). OpenMP keeps the
  // threads of a region for the next one, so a region with four would leave
  // three more threads in the process. OpenBLAS starts its threads when loaded.
  if (!cl::cholmod_available()) return;
  using Get = int (*)();
  using Set = void (*)(int);
  const auto get_levels = reinterpret_cast<Get>(dlsym(RTLD_DEFAULT, "omp_get_max_active_levels"));
  const auto set_levels = reinterpret_cast<Set>(dlsym(RTLD_DEFAULT, "omp_set_max_active_levels"));
  REQUIRE(get_levels != nullptr);  // CHOLMOD links libgomp
  REQUIRE(set_levels != nullptr);
  set_levels(3);
  std::mt19937_64 rng(11);
  const cl::SparseMatrix matrix = grid_hessian(rng, 24);
  const int before = process_threads();
  REQUIRE(before > 0);
  cl::SpdFactorization supernodal(cl::SpdBackend::kSupernodal);
  REQUIRE(supernodal.factor(matrix));
  REQUIRE(supernodal.refactor(matrix));
  const Eigen::VectorXd x = supernodal.solve(Eigen::VectorXd::Ones(matrix.rows()));
  CHECK(x.allFinite());
  CHECK(process_threads() == before);
  CHECK(get_levels() == 3);
}

TEST_CASE("outside CHOLMOD an OpenMP region still gets libgomp's threads", "[sparse][backend]") {
  // common/sparse.cpp defines GOMP_parallel, libgomp's entry point for
  // `#pragma omp parallel`, so that CHOLMOD's regions run inline while it
  // factors; every other region (lab 03's and lab 12's sweeps) must still
  // reach libgomp and its team. A region asked for two threads runs its body
  // on two.
  if (!cl::cholmod_available()) return;
  using Body = void (*)(void*);
  using Parallel = void (*)(Body, void*, unsigned, unsigned);
  const auto parallel = reinterpret_cast<Parallel>(dlsym(RTLD_DEFAULT, "GOMP_parallel"));
  REQUIRE(parallel != nullptr);  // CHOLMOD links libgomp
  std::atomic<int> bodies{0};
  parallel([](void* count) { static_cast<std::atomic<int>*>(count)->fetch_add(1); }, &bodies, 2, 0);
  CHECK(bodies.load() == 2);
}
