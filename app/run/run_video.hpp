#pragma once
// The videos of a run's picture views from their PNG sequences, by ffmpeg: DIR/video.mp4 of the
// first picture view (render::video_file_name), DIR/<view>.mp4 of the others (stress.mp4 beside
// the shaded view's).
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
