#pragma once
// The model ladder's measures: a rung's trajectory against its case's reference FEM.
//   punch: the dent (the largest relative error of the top's mean u_z at 1.5, 2, 3, 4 radii)
//          and the force, at the final step;
//   beams: the largest relative error of |u| at A, B and C at the final step;
//   liver_probe: the surface displacement's relative L2 error at the study's common points
//          over the loaded frames, and the probe force's RMS error over its peak.
#include <string>

#include "app/studies/accuracy_trajectory.hpp"
#include "app/studies/ladder.hpp"

namespace vdmsim {

struct LadderRow {
  LadderConfig config;
  std::string folder;            // the rung's run folder, relative to DIR
  int nodes = 0;                 // the model's nodes (the FEM's: its tet mesh's; else the surface's)
  double median_ms = 0;          // on the study's typical node (as the accuracy study's median_ms)
  double measured_median_ms = 0; // as measured: over the loaded frames (liver), over every step (the others)
  double yardstick_ms = 0;       // the yardstick's median step, measured in the same task
  double error = 0;              // the case's measure (above), relative
  double force_error = -1;       // punch and liver_probe: the force's, relative; -1: not measured
  double volume_rel_error = 0;   // max over frames of |V - V0| / V0
  std::string detail;            // the signed errors per point ("A/B/C +8.3/-1.4/-4.8 %")
  bool failed = false;
  std::string note;
};

// Fills row's measures of `trajectory` against `reference` (the same case's frames).
void measure_ladder_row(const Trajectory& reference, const Trajectory& trajectory, LadderRow& row);

}  // namespace vdmsim
