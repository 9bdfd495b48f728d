#pragma once
// How well a position x solves one step, without a reference to compare it
// with (bench/README.md, "The step's residual"). A distance to a reference
// step needs the step to be unique; on 128² it is not (two minimisers 1e-2
// of the move apart), while a residual is 0 at every solution alike.
//
// Both residuals are displacements (m), mass-weighted RMS over the movable
// particles: with M the (movable) masses and m_tot = Σ_u m_u,
//     ‖v‖ := sqrt(vᵀ M v / m_tot)   for a displacement v (3 per unknown).
#include <Eigen/Core>

#include "common/sparse.h"
#include "labs/lab06_projective_dynamics/projective_dynamics.h"

namespace cl::bench {

// The implicit-Euler step's residual at x (m): the force imbalance ∇g(x) of
// lab 06's objective g (newton_gradient), in the M⁻¹ norm and scaled by Δt²
// into the units of the step,
//     r(x) = Δt² ‖∇g(x)‖_{M⁻¹} / sqrt(m_tot) = ‖Δt² M⁻¹ ∇g(x)‖,
// the mass-weighted RMS of the move one inertia-preconditioned gradient step
// would make. 0 exactly at a stationary point of g (any of its minimisers).
double step_residual(const lab06::Problem& problem, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y);

// The hard step's residual at x: the step minimises ½‖x − y‖²_M subject to
// φ_e(x) = ‖x_i − x_j‖ − L_e = 0 for every spring (its stiffness unused), so
// at a solution φ = 0 and M(x − y) = Jᵀμ for some μ (J = ∂φ/∂x). Two parts:
//   violation    sqrt(mean_e φ_e(x)²) over the springs with a movable end (m);
//   stationarity the part of d = x − y that no constraint force explains:
//                min_μ ‖d − M⁻¹Jᵀμ‖ (the norm above)
//                    = min_μ ‖M d − Jᵀμ‖_{M⁻¹} / sqrt(m_tot),
//                with μ from (J M⁻¹ Jᵀ + ε I) μ = J d, ε = 1e-10 × the mean
//                of J M⁻¹ Jᵀ's diagonal. The cloths' springs are redundant
//                (more springs than unknowns), so J M⁻¹ Jᵀ is singular; the
//                shift only leaves in the residual the directions of range(Jᵀ)
//                whose singular value² is below ε (m).
// Both parts are lengths, so the residual is one vector (φ, the unexplained
// move) with the norm sqrt(violation² + stationarity²) (m). Costs one sparse
// Cholesky of the springs' size; J M⁻¹ Jᵀ's pattern is the same at every x,
// so a caller that passes the same `factor` for one problem's calls pays its
// ordering and symbolic analysis once (SpdFactorization::refactor). NaN
// stationarity when the shifted matrix does not factor.
struct HardResidual {
  double violation = 0.0;     // m
  double stationarity = 0.0;  // m
  double norm() const;        // sqrt(violation² + stationarity²), m
};
HardResidual hard_residual(const lab06::Problem& problem, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y,
                           SpdFactorization* factor = nullptr);

}  // namespace cl::bench
