#pragma once
// The picture side of a scene run: renders each frame's views (the scene's render.views, rows
// of render/views.hpp) on a render thread of its own (so that the next frame is simulated
// meanwhile), queues their files to the writer thread, keeps thumbnails of the first picture
// view for the contact sheet. With a ground-truth view it also writes DIR/camera.json and
// DIR/poses.csv. write() hands over a copy of what the frame shows; the images depend on
// nothing else.
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <memory>
#include <mutex>
#include <thread>
#include <string>
#include <vector>

#include "app/run/poses_csv.hpp"
#include "app/simulation/prepared_scene.hpp"
#include "app/simulation/scene_simulation.hpp"
#include "render/contact_sheet.hpp"
#include "render/image_queue.hpp"
#include "render/renderer.hpp"

namespace vdmsim {

class FrameOutput {
 public:
  FrameOutput() = default;
  ~FrameOutput();  // stops the render thread (pending frames are drawn and queued first)
  FrameOutput(const FrameOutput&) = delete;
  FrameOutput& operator=(const FrameOutput&) = delete;
  // Creates the renderer and each view's folder (removing frames of an earlier run there),
  // and with a ground-truth view camera.json and poses.csv. -1 when ready, otherwise the exit
  // code (1 when rendering cannot start, 2 for an earlier run's damaged poses.csv), with
  // `error`. With `resume_from` > 0 the frames before it are kept, and their contact-sheet
  // thumbnails are read back from disk.
  // `fail_frame` (testing): the renderer is made to fail on that frame (Renderer::
  // fail_next_map_for_testing), as if OpenGL had refused it.
  int open(const PreparedScene& prepared, const std::filesystem::path& dir, int frames, std::string& error,
           int resume_from = 0, int fail_frame = -1);
  void set_stress_range(double lo, double hi);
  const render::StressView& stress_view() const { return view_; }
  // Writes frame f's poses.csv rows and hands frame f of `sim` to the render thread (waits
  // while two frames are pending). False once a frame could not be drawn or a write has
  // failed (error()); the frames after it are not drawn.
  bool write(int f, int frames, const SceneSimulation& sim);
  // Waits until every frame handed over is drawn and its files are on disk. False once a
  // frame could not be drawn or a write has failed.
  bool flush();
  // Keeps poses.csv's rows of the frames before `frames` (after an image write failure, the
  // frames whose images all reached the disk).
  void keep_frames(int frames);
  // Waits for every file, then writes the contact sheet. False + error on a failure.
  bool finish(std::string& error);
  // The first failure, as a sentence: a frame the renderer could not draw, else a file write.
  std::string error() const;
  double render_ms() const;                         // drawing and reading back, on the render thread
  double encode_ms() const;                        // image encoding and writing, on the writer thread
  long images_written() const;

 private:
  struct Job {
    int frame = 0;
    vdm::NodeMat x;  // a copy of the positions
    render::RenderScene scene;
    bool keep_thumbnail = false;
  };
  void render_loop(std::string* start_error, bool* started);
  bool write_poses(int f, const render::RenderScene& scene);
  std::string render_error() const;
  void draw(Job& job);
  void stop();

  const PreparedScene* ps_ = nullptr;
  std::filesystem::path dir_;
  std::unique_ptr<render::ImageQueue> queue_;
  render::StressView view_;
  render::CameraModel camera_;  // the renderer's, once it has started
  PosesCsv poses_;              // with a ground-truth view
  std::string poses_error_;
  std::vector<int> sheet_frames_;
  // Shared with the render thread, under mutex_.
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Job> jobs_;
  bool busy_ = false, stopping_ = false, starting_ = false;
  bool sheet_wanted_ = false;  // finish(): the render thread writes the contact sheet as it ends
  std::string sheet_error_;    // set by the render thread before it ends, read after the join
  std::string render_error_;   // the first frame the renderer could not draw, and why
  int fail_frame_ = -1;        // testing: the frame made to fail (open())
  std::vector<render::Thumbnail> thumbnails_;
  double render_ms_ = 0;
  std::thread thread_;
  // Owned by the render thread.
  std::unique_ptr<render::Renderer> renderer_;
};

// Name of frame f's file in a sequence: frame_00012.png, stress_00012.png (or another
// extension: the mesh export's frame_00012.vtu; a view's: render::view_file_name).
std::string frame_file_name(const std::string& prefix, int f, const char* extension = ".png");

}  // namespace vdmsim
