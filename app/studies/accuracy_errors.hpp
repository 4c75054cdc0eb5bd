#pragma once
// The accuracy study's measures: a configuration's trajectory against its scenario's
// reference (and baseline) over the frames where the instrument pushes or pulls.
#include <vector>

#include "app/studies/accuracy.hpp"
#include "app/studies/accuracy_trajectory.hpp"

namespace vdmsim {

// The loaded frames: the reference's instrument force at least 1 % of its peak.
std::vector<int> loaded_frames(const Trajectory& reference);

// Fills `row`'s errors (displacement RMS and max, force, volume), its node count and its
// measured median and p95 step time over the loaded frames; the force is compared after
// multiplying it by `force_scale`.
void compare_with_reference(const Trajectory& reference, const std::vector<int>& loaded, const Trajectory& trajectory,
                            double force_scale, AccuracyRow& row);

// RMS difference (mm) of two trajectories' surface displacements over the loaded frames.
double rms_difference_mm(const Trajectory& a, const Trajectory& b, const std::vector<int>& loaded);

// Least-squares factor s with s F ~ F_ref over the loaded frames. For fem and mass_spring
// with prescribed motions (kinematic contact, grasping) every force scales with E while the
// displacements do not depend on it, so the run at E gives the run at s E.
double matching_scale(const Trajectory& reference, const std::vector<int>& loaded, const Trajectory& trajectory);

}  // namespace vdmsim
