#pragma once
// DIR/video.mp4 from the PNG sequences by ffmpeg (the shaded view; the stress view too, as
// stress.mp4 beside it, or as video.mp4 when it is the only view).
#include <ostream>
#include <string>

#include "app/run/frame_loop.hpp"

namespace vdmsim {

// Encodes the run's videos. Returns run.json's video status ("written" or "failed: why").
// A failure fails a completed run; a signal during the encoding removes the videos and marks
// the run interrupted.
std::string encode_run_videos(const RenderDef& render, const std::filesystem::path& dir, const StopSignals& signals,
                              RunOutcome& outcome, std::ostream& err);

}  // namespace vdmsim
