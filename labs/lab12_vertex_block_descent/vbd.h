#pragma once
// Lab 12 — vertex block descent. The contract for the student's code.
// Derivation: labs/lab12_vertex_block_descent/README.md. Source: A. H. Chen,
// Z. Liu, Y. Yang, C. Yuksel, "Vertex Block Descent", ACM TOG 43(4)
// (SIGGRAPH 2024): the per-vertex local system, its guard, the graph
// colouring and the parallel sweep; the per-vertex backtracking is the one
// in the authors' Gaia code, there compiled out by default (README.md).
//
// One implicit-Euler step of size Δt minimises lab 06's objective
//     g(x) = Σ_{movable p} m_p ‖x_p − y_p‖² / (2Δt²) + Σ_e k_e/2 (‖x_i − x_j‖ − L_e)².
// Vertex block descent is block coordinate descent on g: one vertex i at a
// time, every other vertex held, one Newton step on i's own 3 × 3 block
//     f_i = −(m_i/Δt²)(x_i − y_i) − Σ_{e ∋ i} ∂E_e/∂x_i       (the force, N)
//     H_i =  (m_i/Δt²) I          + Σ_{e ∋ i} ∂²E_e/∂x_i²     (N/m)
//     d_i = H_i⁻¹ f_i,   x_i ← x_i + α d_i,
// α the first of 1, 1/2, 1/4, … that lowers the vertex's own energy enough
// (the backtracking of vertex_update). Every update then lowers g or leaves
// it as it is, so a sweep never raises g (README.md, "The line search").
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
// semidefinite blocks), so d = H_i⁻¹ f_i is a descent direction
// (fᵀ H⁻¹ f > 0): a small enough step along it lowers g, which is what
// vertex_update's backtracking relies on (README.md, "Why the clamp").
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

// TODO(lab12.2) — the vertex's Newton step d = H_i⁻¹ f_i (the 3 × 3 solve,
// e.g. Eigen's LDLT of the symmetric H_i, or its inverse()).
//
// The paper's guard: the step is taken only when |det H_i| > ε. Here ε is
// relative, ε = kSingularDeterminant · s³ with s the largest |entry| of H_i,
// so that the test does not depend on the units of k and m. Returns a zero
// vector (a documented no-op) when
//   - inv_mass ≤ 0 (a pinned vertex never moves),
//   - H_i or f_i is not finite, or s == 0, or |det H_i| ≤ ε,
//   - the computed d is not finite.
// Never NaN.
Eigen::Vector3d vertex_newton_step(const VertexBlock& block, double inv_mass);

// The change of the vertex's own energy when x_i moves by `step`, every other
// vertex held (given code, descent.cpp):
//     ΔE_i(s) = E_i(x_i + s) − E_i(x_i),
//     E_i(z)  = (m_i/(2Δt²)) ‖z − y_i‖² (movable i only) + Σ_{e ∋ i} k_e/2 (‖z − x_j‖ − L_e)²,
// x_j the spring's other end. The terms of g without x_i cancel, so ΔE_i(s)
// is exactly g(x with x_i + s) − g(x). Each term's difference is written as
// a product (‖r + s‖² − ‖r‖² = s·(2r + s); l' − l = s·(2e + s)/(l' + l)), not
// as a difference of two energies, so that a small step's change is not lost
// to round-off in a large E_i. In J. Throws what vertex_block throws.
double vertex_energy_change(const lab06::Problem& problem, const Adjacency& adjacency, const Eigen::Matrix3Xd& x,
                            const Eigen::Matrix3Xd& y, int vertex, const Eigen::Vector3d& step);

// The backtracking's constants (README.md, "The line search"): Armijo's
// sufficient-decrease fraction c, and the last trial α = 2^−kMaxHalvings.
constexpr double kSufficientDecrease = 1e-4;
constexpr int kMaxHalvings = 60;

// TODO(lab12.3) — the guarded vertex update: the Newton step, shortened until
// it lowers the vertex's own energy enough (a backtracking line search):
//
//     block = vertex_block(problem, adjacency, x, y, vertex)
//     d = vertex_newton_step(block, inv_mass[vertex]);  f_iᵀ d ≤ 0 (d = 0): return 0
//     for j = 0, 1, …, kMaxHalvings, α = 2^−j:
//         if vertex_energy_change(…, α d) ≤ −kSufficientDecrease · α · f_iᵀ d:  return α d
//     return 0   (no α passed: the vertex stays where it is)
//
// Why: the clamp makes H_i positive definite, so f_iᵀ d = dᵀ H_i d > 0 and d
// points downhill — but only a small enough step of a descent direction is
// sure to descend. With springs far from their rest length the full step can
// overshoot and raise g (three particles, README.md: 40.55 J to 79.78 J in
// one sweep). α = 2^−j scales d exactly (a power of two), and the full step
// (α = 1) is kept wherever it passes, as it does near the minimum. An update
// therefore lowers g by at least c α f_iᵀ d, or is a no-op: never a rise
// (beyond the round-off of g's own sum).
// Returns the step Δx_i (m) to add to x_i; never NaN. Throws what
// vertex_block throws.
Eigen::Vector3d vertex_update(const lab06::Problem& problem, const Adjacency& adjacency, const Eigen::Matrix3Xd& x,
                              const Eigen::Matrix3Xd& y, int vertex);

// TODO(lab12.4) — a greedy colouring of the particles: visit p = 0, 1, …, n−1
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

// TODO(lab12.5) — one sweep of vertex block descent: for each group in
// order, each of its particles p (in parallel: an OpenMP parallel for over the
// group) gets x_p += vertex_update(problem, adjacency, x, y, p).
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
