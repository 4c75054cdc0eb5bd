#include "app/run/frame_output.hpp"

#include <malloc.h>
#include <pthread.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "app/run/camera_json.hpp"
#include "app/run/instrument_focus.hpp"
#include "app/run/output_dir.hpp"
#include "app/run/scene_field.hpp"
#include "engine/stopwatch.hpp"
#include "render/png_io.hpp"

namespace vdmsim {
namespace {
using vdm::Clock;
using vdm::ms_since;

// Removes prefix_*<extension> (and unfinished <extension>.tmp) left in `folder` by an earlier
// run.
void remove_old_frames(const std::filesystem::path& folder, const std::string& prefix, const std::string& extension) {
  auto ends_with = [](const std::string& name, const std::string& tail) {
    return name.size() > tail.size() && name.compare(name.size() - tail.size(), tail.size(), tail) == 0;
  };
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    const bool frame = ends_with(name, extension) || ends_with(name, extension + ".tmp");
    if (frame && name.rfind(prefix + "_", 0) == 0) std::filesystem::remove(entry.path(), ec);
  }
}

// The first picture view of the scene's (its frames make the contact sheet), or null.
const render::ViewRow* first_picture_view(const RenderDef& rd) {
  for (render::View v : rd.views)
    if (render::view_row(v).pass == render::ViewPass::picture) return &render::view_row(v);
  return nullptr;
}
}  // namespace

std::string frame_file_name(const std::string& prefix, int f, const char* extension) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "_%05d", f);
  return prefix + buf + extension;
}

int FrameOutput::open(const PreparedScene& ps, const std::filesystem::path& dir, int frames, std::string& error,
                      int resume_from, int fail_frame) {
  ps_ = &ps;
  fail_frame_ = fail_frame;
  dir_ = dir;
  const RenderDef& rd = ps.scene.render;
  view_ = rd.stress_view;
  for (render::View v : rd.views) {
    const render::ViewRow& row = render::view_row(v);
    std::error_code ec;
    std::filesystem::create_directories(dir / row.folder, ec);
    if (ec) {
      error = (dir / row.folder).string() + ": cannot create the folder (" + ec.message() + ")";
      return 1;
    }
    if (resume_from == 0) remove_old_frames(dir / row.folder, row.prefix, render::file_extension(row.file));
  }
  queue_ = std::make_unique<render::ImageQueue>(rd.png_compression);
  sheet_frames_ = render::contact_sheet_frames(frames, 12);
  // Thumbnails of the frames an interrupted run already wrote.
  if (const render::ViewRow* sheet_view = first_picture_view(rd))
    for (int f : sheet_frames_) {
      if (f >= resume_from) break;
      render::Image im;
      if (!render::read_png((dir / sheet_view->folder / render::view_file_name(*sheet_view, f)).string(), im, error))
        return 1;
      thumbnails_.push_back({f, render::downscale(im, std::max(1, im.width / 320)), ""});
    }
  // The render thread owns the GL context: it creates the renderer and says whether it could.
  bool started = false;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    starting_ = true;
    thread_ = std::thread([this, &error, &started] { render_loop(&error, &started); });
    changed_.wait(lock, [&] { return !starting_; });
  }
  if (!started) {
    thread_.join();
    error = "the renderer could not start: " + error;
    return 1;
  }
  if (rd.has_ground_truth()) {
    if (!write_file_atomically(dir / "camera.json", camera_json(camera_), error)) return 1;
    const int objects = 1 + int(ps.scene.instruments.size());
    if (const int code = poses_.open(dir, resume_from, objects, error); code >= 0) return code;
  }
  return -1;
}

FrameOutput::~FrameOutput() { stop(); }

void FrameOutput::stop() {
  if (!thread_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void FrameOutput::render_loop(std::string* start_error, bool* started) {
  pthread_setname_np(pthread_self(), "vdmsim-render");  // for profilers (perf, top -H)
  {
    std::string error;
    auto renderer = render::Renderer::create(framed_settings(*ps_), ps_->surface, error);
    std::lock_guard<std::mutex> lock(mutex_);
    renderer_ = std::move(renderer);
    *started = renderer_ != nullptr;
    if (renderer_) camera_ = renderer_->camera_model();
    else *start_error = error;
    starting_ = false;
  }
  changed_.notify_all();
  if (!renderer_) return;
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    changed_.wait(lock, [&] { return !jobs_.empty() || stopping_; });
    if (jobs_.empty()) break;  // stopping, nothing left
    Job job = std::move(jobs_.front());
    jobs_.pop_front();
    busy_ = true;
    lock.unlock();
    changed_.notify_all();
    const auto t0 = Clock::now();
    draw(job);
    const double ms = ms_since(t0);
    lock.lock();
    render_ms_ += ms;
    busy_ = false;
    changed_.notify_all();
  }
  const bool sheet = sheet_wanted_;
  lock.unlock();
  renderer_.reset();  // GL objects go with the context, on this thread
  // The contact sheet (finish()), once every PNG is written, made here rather than by the
  // thread that calls finish(), and after the freed memory went back to the system
  // (malloc_trim: malloc keeps what a thread frees for that thread's arena): its own GL
  // context, framebuffer and shaders came on top of the renderer's memory otherwise, the
  // run's peak (+60 MB at 40k nodes without MSAA).
  malloc_trim(0);
  if (sheet && queue_->finish() && !thumbnails_.empty()) {
    const std::string title = ps_->scene.name + " (" + first_picture_view(ps_->scene.render)->name + ")";
    std::string error;
    if (!render::write_contact_sheet(thumbnails_, title, (dir_ / "contact_sheet.png").string(),
                                     ps_->scene.render.png_compression, error))
      sheet_error_ = error;
  }
}

void FrameOutput::draw(Job& job) {
  const RenderDef& rd = ps_->scene.render;
  job.scene.positions = &job.x;
  bool thumb_taken = false;
  // Each view's image to its file; the first picture view's to the contact sheet too.
  auto queue = [&](render::View v, render::ViewImage& image) {
    const render::ViewRow& row = render::view_row(v);
    if (job.keep_thumbnail && !thumb_taken && row.pass == render::ViewPass::picture) {
      render::Thumbnail t{job.frame, render::downscale(image.image, std::max(1, image.image.width / 320)), ""};
      std::lock_guard<std::mutex> lock(mutex_);
      thumbnails_.push_back(std::move(t));
      thumb_taken = true;
    }
    return queue_->push(image, (dir_ / row.folder / render::view_file_name(row, job.frame)).string());
  };
  // A frame the renderer cannot draw stops the output there: no image of it is written, nor
  // of the frames after it (the run stops on write()'s false).
  auto failed = [&] {
    std::lock_guard<std::mutex> lock(mutex_);
    if (render_error_.empty())
      render_error_ = "rendering frame " + std::to_string(job.frame) + " failed: " + renderer_->error();
  };
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!render_error_.empty()) return;
  }
  if (job.frame == fail_frame_) renderer_->fail_next_map_for_testing();
  render::ViewOptions options;
  options.hud = rd.hud;
  options.stress = view_;
  if (!renderer_->draw_views(job.scene, rd.views, options, queue)) failed();
}

std::string FrameOutput::render_error() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return render_error_;
}

void FrameOutput::set_stress_range(double lo, double hi) {
  view_.lo = lo;
  view_.hi = hi;
}

namespace {
// The largest of the scene's moduli (Pa): the order of the pressures it can have.
double stiffness_scale(const SceneDef& s) {
  double scale = 0;
  for (const OrganDef& o : s.organs) {
    scale = std::max({scale, o.connectivity_modulus, o.young_modulus});
    for (int d = 0; d < 3; ++d)
      if (std::isfinite(o.bulk_modulus[d])) scale = std::max(scale, o.bulk_modulus[d]);
  }
  return scale;
}
}  // namespace

bool FrameOutput::write(int f, int frames, const SceneSimulation& sim) {
  const RenderDef& rd = ps_->scene.render;
  const vdm::SimState& st = sim.state();
  Job job;
  job.frame = f;
  job.x = sim.positions();
  render::RenderScene& scene = job.scene;
  const std::vector<tools::InstrumentPose> poses = sim.poses(sim.time());
  for (size_t k = 0; k < poses.size(); ++k) {
    render::InstrumentView v = render::instrument_view(ps_->scene.instruments[k], poses[k]);
    if (k < ps_->skins.size()) {
      v.skin = ps_->skins[k].body.get();
      v.jaw_skins[0] = ps_->skins[k].jaws[0].get();
      v.jaw_skins[1] = ps_->skins[k].jaws[1].get();
    }
    scene.instruments.push_back(v);
  }
  if (rd.settings.camera_type == render::CameraType::endoscope) {
    const tools::EndoscopePose scope = tools::endoscope_at(rd.settings.endoscope, sim.time());
    scene.camera_pose = scope.camera;
    scene.light_distance = (scope.look_at - scope.tip).norm();
  }
  render::HudInfo& hud = scene.hud;
  hud.scene_name = ps_->scene.name;
  hud.show_step_time = rd.hud_step_time;
  hud.frame = f;          // the file's number, as in metrics.csv
  hud.frames = frames;
  hud.time_s = sim.time();
  hud.has_contact = sim.contact_simulated();
  hud.contact_force_n = sim.contact_simulated() ? sim.total_force().norm() : 0.0;  // with the grasped nodes
  hud.pressure_pa = st.pressure;
  hud.pressure_scale_pa = stiffness_scale(ps_->scene);
  hud.force_scale_n = hud.pressure_scale_pa * ps_->organ().model.size * ps_->organ().model.size;
  hud.volume_rel_error = st.volume_rel_error;  // the worst organ's
  for (size_t i = 1; i < sim.organ_count(); ++i)
    if (std::abs(sim.state(i).volume_rel_error) > std::abs(hud.volume_rel_error))
      hud.volume_rel_error = sim.state(i).volume_rel_error;
  hud.step_ms = sim.frame_step_ms();
  if (rd.has(render::View::stress)) scene_scalar_field(view_.quantity, sim, scene.scalar);
  if (poses_.is_open() && !write_poses(f, scene)) return false;
  job.keep_thumbnail = std::find(sheet_frames_.begin(), sheet_frames_.end(), f) != sheet_frames_.end();
  {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return jobs_.size() < 2; });
    jobs_.push_back(std::move(job));
  }
  changed_.notify_all();
  return error().empty();
}

bool FrameOutput::write_poses(int f, const render::RenderScene& scene) {
  std::vector<ObjectPose> poses;
  const bool endoscope = ps_->scene.render.settings.camera_type == render::CameraType::endoscope;
  poses.push_back({"camera", endoscope ? scene.camera_pose : camera_.pose, 0.0});
  for (size_t k = 0; k < scene.instruments.size(); ++k) {
    const render::InstrumentView& v = scene.instruments[k];
    const bool grasper = v.type == tools::InstrumentDef::Type::grasper;
    const double jaw_deg = grasper ? tools::kMaxJawAngleDeg * std::clamp(v.jaw_opening, 0.0, 1.0) : 0.0;
    poses.push_back({"instruments[" + std::to_string(k) + "]", v.frame, jaw_deg});
  }
  std::string error;
  if (poses_.write(f, poses, error)) return true;
  std::lock_guard<std::mutex> lock(mutex_);
  if (poses_error_.empty()) poses_error_ = error;
  return false;
}

void FrameOutput::keep_frames(int frames) { poses_.keep_frames(frames); }

bool FrameOutput::flush() {
  poses_.flush();
  if (!queue_) return true;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return (jobs_.empty() && !busy_) || !thread_.joinable(); });
  }
  return queue_->finish() && error().empty();
}

bool FrameOutput::finish(std::string& error) {
  if (!queue_) return true;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    sheet_wanted_ = true;
  }
  stop();  // draws what is pending, then ends the render thread, which writes the contact sheet
  if (!render_error_.empty()) {  // the thread has ended
    error = render_error_;
    return false;
  }
  if (!queue_->finish()) {
    error = "writing images failed: " + queue_->error();
    return false;
  }
  if (!sheet_error_.empty()) {
    error = "writing images failed: " + sheet_error_;
    return false;
  }
  error = this->error();  // poses.csv's
  return error.empty();
}

std::string FrameOutput::error() const {
  const std::string rendering = render_error();
  if (!rendering.empty()) return rendering;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!poses_error_.empty()) return "writing poses failed: " + poses_error_;
  }
  const std::string writing = queue_ ? queue_->error() : std::string();
  return writing.empty() ? writing : "writing images failed: " + writing;
}
double FrameOutput::render_ms() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return render_ms_;
}
double FrameOutput::encode_ms() const { return queue_ ? queue_->encode_ms() : 0.0; }
long FrameOutput::images_written() const { return queue_ ? queue_->written() : 0; }

}  // namespace vdmsim
