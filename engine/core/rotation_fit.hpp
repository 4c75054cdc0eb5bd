#pragma once
// The rotation nearest a deformation gradient F (the rotation R maximising tr(R^T F), F's
// polar factor where det F > 0), fitted from a warm start: the core's local step, once per
// tetrahedron per iteration.
//
// By turning the start q about the torque tau = sum_k R e_k x F e_k (Mueller, Chentanez, Kim
// and Macklin 2016) with Newton's step: with M = F R^T, tr(R^T F) near R is
// tr M + tau . w - w^T H w / 2 for a turn w, where H = tr(M) I - sym(M), so the turn is
// H^-1 tau. Where H is not positive (far from the answer) the step is Mueller et al.'s,
// tau / tr(M), which converges from anywhere, but only linearly (about tenfold per iteration
// near the answer, where Newton's step doubles the digits: from a warm start two or three
// iterations).
//
// Four at a time with AVX2 where the CPU has it (engine/simd4.hpp): lane by lane the same
// operations as one at a time, so the same bits either way.
#include <Eigen/Geometry>

namespace vdm::core {

// R for F, q turned to it (q: the start, a unit quaternion).
Eigen::Matrix3d nearest_rotation(const Eigen::Matrix3d& F, Eigen::Quaterniond& q);

// The same for four: F[k], q[k] -> R[k].
void nearest_rotations4(const Eigen::Matrix3d* F, Eigen::Quaterniond* const* q, Eigen::Matrix3d* R);

}  // namespace vdm::core
