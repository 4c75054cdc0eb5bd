#include "app/run/run_video.hpp"

#include "render/video.hpp"

namespace vdmsim {

std::string encode_run_videos(const RenderDef& rd, const std::filesystem::path& dir, const StopSignals& signals,
                              RunOutcome& outcome, std::ostream& err) {
  namespace fs = std::filesystem;
  std::string error;
  bool ok = true;
  if (rd.shaded)
    ok = render::encode_video((dir / "frames" / "frame_%05d.png").string(), rd.fps, (dir / "video.mp4").string(),
                              (dir / "ffmpeg.log").string(), error);
  if (ok && rd.stress)
    ok = render::encode_video((dir / "stress" / "stress_%05d.png").string(), rd.fps,
                              (dir / (rd.shaded ? "stress.mp4" : "video.mp4")).string(), (dir / "ffmpeg.log").string(),
                              error);
  if (signals.received()) {  // Ctrl-C reached ffmpeg too: no half video
    std::error_code ec;
    fs::remove(dir / "video.mp4", ec);
    fs::remove(dir / "stress.mp4", ec);
    ok = false;
    outcome.status = "interrupted";
    outcome.reason = "interrupted while encoding the video; every frame is complete, the video is not written";
    error = outcome.reason;
  }
  if (!ok && outcome.status != "interrupted") {
    err << "vdmsim: error: " << error << "\n";
    if (outcome.status == "completed") outcome.fail(error);
  }
  return ok ? "written" : "failed: " + error;
}

}  // namespace vdmsim
