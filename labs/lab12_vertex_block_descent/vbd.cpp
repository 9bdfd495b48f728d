// Lab 12 — your code. Read vbd.h (the contract) and README.md (the
// derivations) first. Grade with:  ./course grade lab12
//
// The five functions below are the pieces of vertex block descent; the given
// code (descent.cpp) runs them inside the step. Besides the tests named in
// each block, tests/lab12_vertex_block_descent/test_minimiser.cpp (8 pts)
// runs whole sweeps and needs all five.
#include "vbd.h"

#include "common/not_implemented.h"

namespace cl::lab12 {

// TODO(lab12.1) [3 pts] Vertex i's force f_i = −∂g/∂x_i and its 3 × 3 block
// H_i: the inertia term (movable i only), then each spring at i (the
// adjacency's list) with lab 06's gradient and its clamped block. Check the
// vertex index and the shapes of x and y; throw std::invalid_argument.
// Graded by tests/lab12_vertex_block_descent/test_block.cpp (3 pts).
VertexBlock vertex_block(const lab06::Problem& problem, const Adjacency& adjacency, const Eigen::Matrix3Xd& x,
                         const Eigen::Matrix3Xd& y, int vertex) {
  (void)problem, (void)adjacency, (void)x, (void)y, (void)vertex;
  not_implemented("vertex_block", __FILE__);
}

// TODO(lab12.2) [1 pt] d = H⁻¹ f, or a zero vector for a pinned vertex, a
// non-finite block, a near-singular H (|det H| <= kSingularDeterminant · s³,
// s the largest |entry|) or a non-finite result.
// Graded by tests/lab12_vertex_block_descent/test_update.cpp (the first case).
Eigen::Vector3d vertex_newton_step(const VertexBlock& block, double inv_mass) {
  (void)block, (void)inv_mass;
  not_implemented("vertex_newton_step", __FILE__);
}

// TODO(lab12.3) [2 pts] The guarded vertex update: d from vertex_newton_step,
// then α = 1, 1/2, 1/4, … (at most kMaxHalvings halvings) until
// vertex_energy_change(…, α d) <= −kSufficientDecrease · α · fᵀd; return α d,
// or a zero vector when d is zero or no α passes.
// Graded by tests/lab12_vertex_block_descent/test_update.cpp (the other cases).
Eigen::Vector3d vertex_update(const lab06::Problem& problem, const Adjacency& adjacency, const Eigen::Matrix3Xd& x,
                              const Eigen::Matrix3Xd& y, int vertex) {
  (void)problem, (void)adjacency, (void)x, (void)y, (void)vertex;
  not_implemented("vertex_update", __FILE__);
}

// TODO(lab12.4) [2 pts] The greedy colouring: particles in index order, each
// the smallest colour none of its coloured neighbours has.
// Graded by tests/lab12_vertex_block_descent/test_colouring.cpp (2 pts).
std::vector<int> colour_particles(int particles, const std::vector<Spring>& springs) {
  (void)particles, (void)springs;
  not_implemented("colour_particles", __FILE__);
}

// TODO(lab12.5) [4 pts] One sweep: groups in order, the particles of a group
// in an OpenMP parallel for, each x_p += vertex_update(problem, adjacency, x, y, p).
// Graded by tests/lab12_vertex_block_descent/test_sweep.cpp (3 pts) and
// test_parallel.cpp (1 pt: the colours run in OpenMP parallel regions).
void vbd_sweep(const lab06::Problem& problem, const Adjacency& adjacency, const std::vector<std::vector<int>>& groups,
               const Eigen::Matrix3Xd& y, Eigen::Matrix3Xd& x) {
  (void)problem, (void)adjacency, (void)groups, (void)y, (void)x;
  not_implemented("vbd_sweep", __FILE__);
}

}  // namespace cl::lab12
