#pragma once
// The stress view's colour range when the scene does not give one: a first pass over the
// whole sequence (the simulation is deterministic, so the run sees the same values), or, when
// resuming, the interrupted run's range.
#include "app/run/frame_output.hpp"
#include "app/run/progress.hpp"
#include "app/run/run_setup.hpp"
#include "app/run/stop_signals.hpp"

namespace vdmsim {

// Sets `output`'s stress range when the scene asks for an automatic one. Returns the first
// pass's time (ms), 0 without a pass.
double set_auto_colour_range(const PreparedScene& prepared, const RunSetup& setup, FrameOutput& output,
                             const StopSignals& signals, Progress& progress);

}  // namespace vdmsim
