#pragma once
// One configuration of the accuracy study simulated: the surface displacement at the study's
// common points, the instruments' force, the step time and the volume error, frame by frame.
// A configuration's task writes it to its run folder (trajectory.bin) and the study reads it
// back to measure the errors, so the numbers are the same however the tasks ran.
#include <filesystem>
#include <string>
#include <vector>

#include "engine/types.hpp"

namespace vdmsim {

struct Trajectory {
  std::vector<vdm::NodeMat> u;           // samples x 3 (m)
  std::vector<vdm::Vec3> force;          // force of the organ on the instruments (N)
  std::vector<double> step_ms, volume_rel;
  int nodes = 0;
  int unconverged = 0;                   // steps whose solve (or contact active set) did not converge
  bool failed = false;
  std::string failure;
};

// The study's common surface points: the nodes of the coarse (level 3, 642-node) liver.
vdm::NodeMat accuracy_sample_points();

// Simulates the scene at `path`; samples the surface displacement at `points` every frame.
// A scene that does not load or a simulation that fails gives `failed` with the reason.
Trajectory simulate_trajectory(const std::string& path, const vdm::NodeMat& points);

// The trajectory as a binary file (native doubles, bit for bit) and back; false with `error`
// (the file named) when it cannot be written or is not a whole trajectory.
bool write_trajectory(const std::filesystem::path& path, const Trajectory& trajectory, std::string& error);
bool read_trajectory(const std::filesystem::path& path, Trajectory& trajectory, std::string& error);

}  // namespace vdmsim
