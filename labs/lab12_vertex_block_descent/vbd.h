#pragma once
// Lab 12 — vertex block descent. The contract for the student's code.
// Derivation: labs/lab12_vertex_block_descent/README.md. Source: A. H. Chen,
// Z. Liu, Y. Yang, C. Yuksel, "Vertex Block Descent", ACM TOG 43(4)
// (SIGGRAPH 2024): the per-vertex local system, its guard, the graph
// colouring and the parallel sweep.
//
// One implicit-Euler step of size Δt minimises lab 06's objective
//     g(x) = Σ_{movable p} m_p ‖x_p − y_p‖² / (2Δt²) + Σ_e k_e/2 (‖x_i − x_j‖ − L_e)².
// Vertex block descent is block coordinate descent on g: one vertex i at a
// time, every other vertex held, one Newton step on i's own 3 × 3 block
//     f_i = −(m_i/Δt²)(x_i − y_i) − Σ_{e ∋ i} ∂E_e/∂x_i       (the force, N)
//     H_i =  (m_i/Δt²) I          + Σ_{e ∋ i} ∂²E_e/∂x_i²     (N/m)
//     x_i ← x_i + H_i⁻¹ f_i.
// Vertices of one colour share no spring, so they are independent: a colour
// is one parallel loop.
//
// Units: positions in m, inverse masses in 1/kg (0 = pinned), stiffness in N/m,
// time in s. Shapes: positions are 3 × n, one column per particle.
#include <vector>

#include <Eigen/Core>

#include "../lab06_projective_dynamics/projective_dynamics.h"
#include "common/constraints.h"

namespace cl::lab12 {

// The springs at each particle, in compressed rows: particle p's springs are
// springs[offsets[p]] … springs[offsets[p + 1] − 1], in increasing spring
// index. Given code (make_adjacency, descent.cpp).
struct Adjacency {
  std::vector<int> offsets;  // n + 1 entries
  std::vector<int> springs;  // 2 m entries: each spring at both its ends
};
// Throws std::invalid_argument for a spring with an end outside [0, n).
Adjacency make_adjacency(int particles, const std::vector<Spring>& springs);

// A vertex's local system: the force f_i = −∂g/∂x_i and the 3 × 3 block H_i.
struct VertexBlock {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();      // N
  Eigen::Matrix3d hessian = Eigen::Matrix3d::Zero();    // N/m, symmetric
};

// TODO(lab12.1) — vertex i's force and Hessian block at x, for the prediction y:
//
//     inertia (movable i only):  f −= (m_i/Δt²)(x_i − y_i),   H += (m_i/Δt²) I
//     each spring e = (a, b) at the vertex, l = ‖x_a − x_b‖, n = (x_a − x_b)/l:
//         f −= ± k (l − L) n     (+ when the vertex is the spring's end a = i,
//                                 − when it is end b = j: lab 06's gradient)
//         H += k [n nᵀ + max(0, 1 − L/l)(I − n nᵀ)]          (lab 06's clamped block)
//
// exactly the i-th block of lab 06's newton_gradient (negated) and the i-th
// diagonal block of its clamped newton_hessian. The clamp: the true block has
// eigenvalue k (1 − L/l) across the spring, negative when it is compressed
// (l < L); dropping it keeps H_i positive definite (m_i/Δt² > 0 plus positive
// semidefinite blocks), so Δx = H_i⁻¹ f_i descends (fᵀ H⁻¹ f > 0) and the
// vertex's g never rises for a small enough step (README.md, "Why the clamp").
// Coincident ends (l == 0, Eigen's norm()) use n = (1, 0, 0) for x_a − x_b, as
// lab 06 does (so end a is pushed along +x, end b along −x), with the across
// term 0 (rest length > 0) or 1 (rest length 0); a zero-rest
// spring (L = 0) has the block k I for every l. Never NaN for finite input.
// A pinned vertex (inv_mass 0) gets the springs' terms only (no inertia).
// Throws std::invalid_argument for a vertex outside [0, n) or x, y not 3 × n.
VertexBlock vertex_block(const lab06::Problem& problem, const Adjacency& adjacency, const Eigen::Matrix3Xd& x,
                         const Eigen::Matrix3Xd& y, int vertex);

// The guard's relative threshold (README.md, "The guard"): H_i counts as
// near-singular when |det H_i| ≤ kSingularDeterminant · (‖H_i‖_max)³.
constexpr double kSingularDeterminant = 1e-12;

// TODO(lab12.2) — the vertex update Δx_i = H_i⁻¹ f_i (the 3 × 3 solve, e.g.
// Eigen's LDLT of the symmetric H_i, or its inverse()).
//
// The paper's guard: the update is taken only when |det H_i| > ε. Here ε is
// relative, ε = kSingularDeterminant · s³ with s the largest |entry| of H_i,
// so that the test does not depend on the units of k and m. Returns a zero
// vector (a documented no-op) when
//   - inv_mass ≤ 0 (a pinned vertex never moves),
//   - H_i or f_i is not finite, or s == 0, or |det H_i| ≤ ε,
//   - the computed Δx is not finite.
// Never NaN.
Eigen::Vector3d vertex_update(const VertexBlock& block, double inv_mass);

// TODO(lab12.3) — a greedy colouring of the particles: visit p = 0, 1, …, n−1
// in order and give p the smallest colour c ≥ 0 that none of its already
// coloured neighbours (the other ends of its springs) has. No spring joins two
// particles of one colour (a spring with i == j cannot be coloured: throws).
// Deterministic: the result depends only on n and the springs. Pinned
// particles are coloured too (the sweep skips them).
// Returns n colours. Throws std::invalid_argument for an end outside [0, n)
// or i == j.
std::vector<int> colour_particles(int particles, const std::vector<Spring>& springs);

// The movable particles of each colour, colours in increasing order and
// particles in increasing index within a colour (given code, descent.cpp).
// Colours with no movable particle are left out.
std::vector<std::vector<int>> colour_groups(const std::vector<int>& colours, const Eigen::VectorXd& inv_mass);

// TODO(lab12.4) — one sweep of vertex block descent: for each group in
// order, each of its particles p (in parallel: an OpenMP parallel for over the
// group) gets x_p += vertex_update(vertex_block(problem, adjacency, x, y, p),
// problem.inv_mass[p]).
// A particle of a group reads only its own column and those of its spring
// neighbours, which are of other colours: within a group the updates do not
// depend on each other's order, and the result is bit for bit the same on any
// number of threads (no reduction in the loop). Groups are read as given
// (colour_groups' output); a group must be an independent set, which is not
// checked here.
// x: 3 × n, updated in place; y: 3 × n. Throws std::invalid_argument when x
// or y is mis-sized (before anything is changed).
void vbd_sweep(const lab06::Problem& problem, const Adjacency& adjacency, const std::vector<std::vector<int>>& groups,
               const Eigen::Matrix3Xd& y, Eigen::Matrix3Xd& x);

}  // namespace cl::lab12
