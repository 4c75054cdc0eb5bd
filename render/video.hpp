#pragma once
// Video through the ffmpeg program (H.264 in MP4): the PNG sequence is encoded after the run.
#include <string>

namespace render {

// The full path of `program` on PATH, or "" when it is not installed.
std::string find_program(const std::string& program);

// Encodes `pattern` (e.g. DIR/frames/frame_%05d.png) at `fps` into `output` with libx264
// (yuv420p, padded to even sizes). ffmpeg's messages go to `log_path`. False + error (with
// the log's last line) on failure.
bool encode_video(const std::string& pattern, double fps, const std::string& output, const std::string& log_path,
                  std::string& error);

}  // namespace render
