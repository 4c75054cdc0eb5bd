#pragma once
// The model ladder's FEM cases as load cases (docs/model.md, "Against the FEM"; E 3 kPa,
// nu 0.45): the flat punch (a 10 x 10 x 5 cm block, bottom held, a bonded flat punch of
// radius 5 mm pressed 1 mm in 4 steps into the top's centre; gmsh tets graded from the rim)
// and the 2 x 10 x 2 cm beam, one end clamped, the other end's face stretched 20 %, bent
// sideways by one width or twisted 30 deg in 5 steps. A rung runs its model through the case
// and returns the case's measure points, frame by frame, as a Trajectory:
//   punch: the top's displacement at 1.5, 2, 3 and 4 punch radii from the centre, 8 azimuths
//          each (rows radius-major), and the punch force (0, 0, F);
//   beams: the displacement at A, B, C, the top face's centre line at L/4, L/2, 3L/4.
// Points are interpolated on the model's surface, so that every mesh is measured at the same
// material points.
#include "app/simulation/tet_mesher.hpp"
#include "app/studies/accuracy_trajectory.hpp"
#include "app/studies/ladder.hpp"

namespace vdmsim {

constexpr int kLadderPunchRadii = 4, kLadderPunchAzimuths = 8;
constexpr double kLadderPunchRadius = 0.005;  // m
extern const double kLadderPunchDistances[kLadderPunchRadii];  // in punch radii: 1.5, 2, 3, 4

// The punch's FEM block at `level` (0: 0.5 mm at the rim, 1: 0.35 mm, 2: 0.25 mm).
BoxWithDisk punch_level(int level);

// Runs a punch or beams rung (not liver_probe: a scene). Throws std::runtime_error when its
// mesh or model cannot be built.
Trajectory run_ladder_case(const LadderConfig& c);

}  // namespace vdmsim
