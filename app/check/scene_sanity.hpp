#pragma once
// `vdmsim check`'s sanity report on a prepared scene: how much of the organ is fixed, when each
// instrument first touches the organ and how deep it goes, and the warnings (and the error) for
// scenes that load but cannot do what was meant: every node fixed, an instrument that never
// touches the organ or starts inside it, a script longer than the frames, a default material.
#include <ostream>
#include <vector>

#include "app/check/fixed_nodes.hpp"
#include "app/check/instrument_reach.hpp"
#include "app/simulation/prepared_scene.hpp"

namespace vdmsim {

struct SanityReport {
  std::vector<FixedCount> fixed;       // per organ, in the scene's order
  std::vector<InstrumentReach> reach;  // per instrument, in the scene's order
  double end_time = 0;                 // the last frame's time (s)
  std::vector<SceneProblem> problems;  // warnings; an error when every node is fixed
};

SanityReport scene_sanity(const PreparedScene& ps);

// The report's lines (stdout; the problems are printed with the scene's).
void print_sanity(const PreparedScene& ps, const SanityReport& report, std::ostream& out);

}  // namespace vdmsim
