#include "app/frame_output.hpp"

#include <algorithm>
#include <chrono>

#include "render/png_io.hpp"
#include <cstdio>

namespace vdmsim {
namespace {
using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

// Removes prefix_*.png (and unfinished .png.tmp) left in `folder` by an earlier run.
void remove_old_frames(const std::filesystem::path& folder, const std::string& prefix) {
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    const bool png = name.size() > 4 && (name.compare(name.size() - 4, 4, ".png") == 0 ||
                                         (name.size() > 8 && name.compare(name.size() - 8, 8, ".png.tmp") == 0));
    if (png && name.rfind(prefix + "_", 0) == 0) std::filesystem::remove(entry.path(), ec);
  }
}
}  // namespace

std::string frame_file_name(const std::string& prefix, int f) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%s_%05d.png", prefix.c_str(), f);
  return buf;
}

bool FrameOutput::open(const PreparedScene& ps, const std::filesystem::path& dir, int frames, std::string& error,
                       int resume_from) {
  ps_ = &ps;
  dir_ = dir;
  const RenderDef& rd = ps.scene.render;
  view_ = rd.stress_view;
  for (const char* sub : {"frames", "stress"}) {
    const bool wanted = std::string(sub) == "frames" ? rd.shaded : rd.stress;
    if (!wanted) continue;
    std::error_code ec;
    std::filesystem::create_directories(dir / sub, ec);
    if (ec) {
      error = (dir / sub).string() + ": cannot create the folder (" + ec.message() + ")";
      return false;
    }
    if (resume_from == 0) remove_old_frames(dir / sub, std::string(sub) == "frames" ? "frame" : "stress");
  }
  renderer_ = render::Renderer::create(rd.settings, ps.model.rest, error);
  if (!renderer_) {
    error = "the renderer could not start: " + error;
    return false;
  }
  queue_ = std::make_unique<render::PngQueue>(rd.png_compression);
  sheet_frames_ = render::contact_sheet_frames(frames, 12);
  // Thumbnails of the frames an interrupted run already wrote.
  const std::string prefix = rd.shaded ? "frame" : "stress", sub = rd.shaded ? "frames" : "stress";
  for (int f : sheet_frames_) {
    if (f >= resume_from) break;
    render::Image im;
    if (!render::read_png((dir / sub / frame_file_name(prefix, f)).string(), im, error)) return false;
    thumbnails_.push_back({f, render::downscale(im, std::max(1, im.width / 320))});
  }
  scene_.hud.scene_name = ps.scene.name;
  scene_.hud.show_step_time = rd.hud_step_time;
  return true;
}

void FrameOutput::set_stress_range(double lo, double hi) {
  view_.lo = lo;
  view_.hi = hi;
}

bool FrameOutput::write(int f, int frames, const SceneSimulation& sim) {
  const auto t0 = Clock::now();
  const RenderDef& rd = ps_->scene.render;
  const vdm::SimState& st = sim.state();
  scene_.positions = &st.x;
  scene_.instruments.clear();
  const std::vector<tools::InstrumentPose> poses = sim.poses(sim.time());
  for (size_t k = 0; k < poses.size(); ++k) {
    render::InstrumentView v = render::instrument_view(ps_->scene.instruments[k], poses[k]);
    if (k < ps_->skins.size()) {
      v.skin = ps_->skins[k].body.get();
      v.jaw_skins[0] = ps_->skins[k].jaws[0].get();
      v.jaw_skins[1] = ps_->skins[k].jaws[1].get();
    }
    scene_.instruments.push_back(v);
  }
  render::HudInfo& hud = scene_.hud;
  hud.frame = f;          // the file's number, as in metrics.csv
  hud.frames = frames;
  hud.time_s = sim.time();
  hud.has_contact = sim.contact_simulated();
  hud.contact_force_n = sim.contact_simulated() ? sim.contact_report().force.norm() : 0.0;
  hud.pressure_pa = st.pressure;
  hud.volume_rel_error = st.volume_rel_error;
  hud.step_ms = sim.frame_step_ms();
  const bool keep_thumbnail = std::find(sheet_frames_.begin(), sheet_frames_.end(), f) != sheet_frames_.end();
  bool thumb_taken = false;
  auto queue = [&](const std::string& sub, const std::string& prefix) {
    if (keep_thumbnail && !thumb_taken) {
      const int factor = std::max(1, image_.width / 320);
      thumbnails_.push_back({f, render::downscale(image_, factor)});
      thumb_taken = true;
    }
    return queue_->push(image_, (dir_ / sub / frame_file_name(prefix, f)).string());
  };
  bool ok = true;
  if (rd.shaded) {
    renderer_->draw_shaded(scene_, rd.hud, image_);
    ok = queue("frames", "frame") && ok;
  }
  if (rd.stress && ok) {
    render::scalar_field(view_.quantity, st, scene_.scalar);
    renderer_->draw_stress(scene_, view_, rd.hud, image_);
    ok = queue("stress", "stress") && ok;
  }
  render_ms_ += ms_since(t0);
  return ok;
}

bool FrameOutput::flush() { return !queue_ || queue_->finish(); }

bool FrameOutput::finish(std::string& error) {
  if (!queue_) return true;
  if (!queue_->finish()) {
    error = queue_->error();
    return false;
  }
  if (!thumbnails_.empty()) {
    const std::string title = ps_->scene.name + " (" + std::string(ps_->scene.render.shaded ? "shaded" : "stress") + ")";
    if (!render::write_contact_sheet(thumbnails_, title, (dir_ / "contact_sheet.png").string(),
                                     ps_->scene.render.png_compression, error))
      return false;
  }
  return true;
}

std::string FrameOutput::error() const { return queue_ ? queue_->error() : std::string(); }
double FrameOutput::encode_ms() const { return queue_ ? queue_->encode_ms() : 0.0; }
long FrameOutput::images_written() const { return queue_ ? queue_->written() : 0; }

}  // namespace vdmsim
