#include "app/run/run_video.hpp"

#include "render/video.hpp"

namespace vdmsim {

std::string encode_run_videos(const RenderDef& rd, const std::filesystem::path& dir, const StopSignals& signals,
                              RunOutcome& outcome, std::ostream& err) {
  namespace fs = std::filesystem;
  std::string error;
  bool ok = true;
  for (render::View v : rd.views) {
    const std::string video = render::video_file_name(rd.views, v);
    if (!ok || video.empty()) continue;
    const render::ViewRow& row = render::view_row(v);
    const std::string pattern = std::string(row.prefix) + "_%05d" + render::file_extension(row.file);
    ok = render::encode_video((dir / row.folder / pattern).string(), rd.fps, (dir / video).string(),
                              (dir / "ffmpeg.log").string(), error);
  }
  if (signals.received()) {  // Ctrl-C reached ffmpeg too: no half video
    std::error_code ec;
    for (render::View v : rd.views)
      if (const std::string video = render::video_file_name(rd.views, v); !video.empty()) fs::remove(dir / video, ec);
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
