#pragma once
// The endoscope's frame against the framing camera's, side by side: assets' lap_liver_retraction
// scene simulated into its grasp and press, then one 1280x720 frame of it drawn (with the HUD)
// and encoded to PNG by a renderer with the scene's endoscope and by one with the automatic
// framing camera and its floor (the frame every other scene draws), in turn, frame after frame;
// and each ground-truth view drawn and read back through the endoscope (no encoding).
#include <filesystem>

namespace vdmsim {

struct EndoscopeFrameCost {
  long nodes = 0;
  int frames = 0;
  double framing_ms = 0, endoscope_ms = 0;  // medians, draw + encode
  double ratio = 0;                         // endoscope over framing, of the medians
  double pair_ratio_max = 0;                // the highest frame-by-frame ratio
  double depth_ms = 0, segmentation_ms = 0, normals_ms = 0;  // medians, draw + read
};

EndoscopeFrameCost bench_endoscope_frame(const std::filesystem::path& dir, int frames, int simulated_frames);

}  // namespace vdmsim
