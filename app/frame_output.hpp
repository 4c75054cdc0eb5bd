#pragma once
// The picture side of a scene run: renders each frame's views (shaded, stress) with the HUD,
// queues the PNGs to the writer thread, keeps thumbnails for the contact sheet.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "app/scene_run.hpp"
#include "app/scene_simulation.hpp"
#include "render/contact_sheet.hpp"
#include "render/png_queue.hpp"
#include "render/renderer.hpp"

namespace vdmsim {

class FrameOutput {
 public:
  // Creates the renderer and the frames/ and stress/ folders (removing frames of an earlier
  // run there). False with `error` when rendering cannot start.
  // With `resume_from` > 0 the frames before it are kept, and their contact-sheet thumbnails
  // are read back from disk.
  bool open(const PreparedScene& prepared, const std::filesystem::path& dir, int frames, std::string& error,
            int resume_from = 0);
  void set_stress_range(double lo, double hi);
  const render::StressView& stress_view() const { return view_; }
  // Renders frame f of `sim` and queues its images. False once a write has failed (error()).
  bool write(int f, int frames, const SceneSimulation& sim);
  // Waits until every queued PNG is on disk. False once a write has failed.
  bool flush();
  // Waits for every PNG, then writes the contact sheet. False + error on a write failure.
  bool finish(std::string& error);
  std::string error() const;
  double render_ms() const { return render_ms_; }   // drawing and reading back, on this thread
  double encode_ms() const;                        // PNG encoding and writing, on the writer thread
  long images_written() const;

 private:
  const PreparedScene* ps_ = nullptr;
  std::filesystem::path dir_;
  std::unique_ptr<render::Renderer> renderer_;
  std::unique_ptr<render::PngQueue> queue_;
  render::RenderScene scene_;
  render::StressView view_;
  render::Image image_;
  std::vector<int> sheet_frames_;
  std::vector<render::Thumbnail> thumbnails_;
  double render_ms_ = 0;
};

// Name of frame f's image in a sequence: frame_00012.png, stress_00012.png.
std::string frame_file_name(const std::string& prefix, int f);

}  // namespace vdmsim
