#pragma once
// The rotation between two directions, compiled in one place (engine/rotation.cpp): Eigen's
// Quaterniond::FromTwoVectors instantiates a JacobiSVD (its case of opposite directions), which
// was about half of the compile time of each file that called it.
#include <Eigen/Geometry>

namespace vdm {

// The smallest rotation taking the direction of `from` to that of `to` (neither needs unit
// length); for opposite directions, a half turn about an axis perpendicular to both. Exactly
// Eigen::Quaterniond::FromTwoVectors(from, to).
Eigen::Quaterniond rotation_between(const Eigen::Vector3d& from, const Eigen::Vector3d& to);

}  // namespace vdm
