#include "app/run/scene_run.hpp"

#include <malloc.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <memory>
#include <optional>
#include <sstream>

#include "app/run/checkpoint.hpp"
#include "app/run/frame_output.hpp"
#include "app/run/output_dir.hpp"
#include "app/simulation/scene_simulation.hpp"
#include "engine/stopwatch.hpp"
#include "render/video.hpp"
#include "engine/contact.hpp"
#include "engine/sim_state.hpp"
#include "tools_scripted/grasp.hpp"

namespace vdmsim {
namespace {

// Ctrl-C (SIGINT) and SIGTERM during a run: the loop stops after the current frame, writes
// everything so far and says "interrupted" in run.json.
// A lock-free atomic: set in the handler on whichever thread gets the signal, read by the loop.
std::atomic<int> g_stop_signal{0};
static_assert(std::atomic<int>::is_always_lock_free, "the stop flag must be usable in a signal handler");
void on_stop_signal(int sig) {
  g_stop_signal = sig;
  std::signal(sig, SIG_DFL);  // a second Ctrl-C stops at once
}

// Installs the handlers for the lifetime of a run and restores the previous ones.
class StopSignals {
 public:
  StopSignals() {
    g_stop_signal = 0;
    old_int_ = std::signal(SIGINT, on_stop_signal);
    old_term_ = std::signal(SIGTERM, on_stop_signal);
  }
  ~StopSignals() {
    std::signal(SIGINT, old_int_);
    std::signal(SIGTERM, old_term_);
  }
  int received() const { return g_stop_signal.load(); }

 private:
  void (*old_int_)(int) = SIG_DFL;
  void (*old_term_)(int) = SIG_DFL;
};

using vdm::Clock;
using vdm::ms_since;

std::string json_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (static_cast<unsigned char>(c) < 0x20) {
      o += ' ';
      continue;
    }
    o += c;
  }
  return o;
}

// Writes run.json atomically (temporary file, then rename), so a reader never sees half.
bool write_run_json(const std::filesystem::path& path, const std::string& body, std::string& error) {
  const std::filesystem::path tmp = path.string() + ".tmp";
  {
    std::ofstream f(tmp);
    f << body;
    f.flush();
    if (!f) {
      error = tmp.string() + ": write failed";
      return false;
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    error = path.string() + ": " + ec.message();
    return false;
  }
  return true;
}

}  // namespace

int run_scene(PreparedScene& ps, const RunOptions& opt, std::ostream& out, std::ostream& err, bool terminal) {
  namespace fs = std::filesystem;
  const SceneDef& s = ps.scene;
  const vdm::TissueModel& m = ps.model;
  const int frames = opt.frames > 0 ? opt.frames : s.frames;
  const fs::path dir = opt.out_dir.empty() ? fs::path("out") / s.name : fs::path(opt.out_dir);
  std::string error;
  const bool rendering = opt.render && s.has_render && (s.render.shaded || s.render.stress);
  if (opt.video && !rendering) {
    err << "vdmsim: error: --video needs rendered frames: " << (opt.render ? s.file + " has no render: section" : "drop --no-render")
        << "\n";
    return 2;
  }
  if (opt.video && render::find_program("ffmpeg").empty()) {
    err << "vdmsim: error: --video needs the ffmpeg program, which is not installed (apt-get install ffmpeg)\n";
    return 1;
  }
  if (!prepare_output_dir(dir.string(), error)) {
    err << "vdmsim: error: " << error << "\n";
    return 2;
  }
  bool has_probe = false, has_grasper = false;
  for (const InstrumentDef& in : s.instruments) (in.type == InstrumentDef::Type::probe ? has_probe : has_grasper) = true;
  if (has_probe && !s.has(Effect::contact))
    err << "vdmsim: note: the scene has probes but does not list the contact effect: they pass through the organ\n";
  if (has_grasper && !s.has(Effect::grasp))
    err << "vdmsim: note: the scene has graspers but does not list the grasp effect: they hold nothing\n";

  // Resuming: the checkpoint must belong to this scene and these options.
  std::ostringstream options;
  options << "frames=" << frames << ";render=" << rendering;
  const std::string this_run = run_hash(s.file, options.str());
  const fs::path checkpoint_path = dir / "checkpoint.json";
  Checkpoint resume_cp;
  int start = 0;  // first frame to write
  if (opt.resume) {
    if (!read_checkpoint(checkpoint_path.string(), resume_cp, error)) {
      err << "vdmsim: error: " << error << "\n";
      return 2;
    }
    if (resume_cp.run_hash != this_run) {
      err << "vdmsim: error: " << checkpoint_path.string()
          << ": the checkpoint belongs to another scene or other options (frames, --no-render): cannot resume\n";
      return 2;
    }
    start = resume_cp.frame + 1;
    if (start >= frames) {
      err << "vdmsim: note: " << dir.string() << ": the run was already complete (" << frames
          << " frames): nothing to do\n";
      return 0;
    }
  } else {
    // A fresh run: outputs of an earlier run in this folder would be stale.
    std::error_code ec;
    for (const char* old : {"checkpoint.json", "state.bin", "video.mp4", "stress.mp4", "contact_sheet.png", "ffmpeg.log"})
      fs::remove(dir / old, ec);
  }
  const StopSignals signals;
  FrameOutput output;
  if (rendering && !output.open(ps, dir, frames, error, start, opt.fail_render_at_frame)) {
    err << "vdmsim: error: " << error << "\n";
    return 1;
  }
  const auto t_run = Clock::now();
  auto progress = [&](const std::string& what, int done, int total, int& last_pct) {
    const int pct = 100 * done / total;
    if (terminal) {
      if (pct != last_pct) {
        const int w = 30, fill = w * done / total;
        err << "\r" << what << " [" << std::string(fill, '#') << std::string(w - fill, '.') << "] " << std::setw(3) << pct
            << "%  frame " << done << "/" << total << std::flush;
      }
    } else if (pct / 10 != last_pct / 10 || done == total) {
      err << what << " frame " << done << "/" << total << " (" << pct << "%)\n";
    }
    last_pct = pct;
  };

  // The stress view's colour range, when not given: a first pass over the whole sequence
  // (the simulation is deterministic, so the second pass sees the same values).
  double first_pass_ms = 0;
  if (rendering && s.render.stress && s.render.range_auto && opt.resume && resume_cp.range_lo < resume_cp.range_hi) {
    output.set_stress_range(resume_cp.range_lo, resume_cp.range_hi);  // the interrupted run's range
  } else if (rendering && s.render.stress && s.render.range_auto) {
    const auto t0 = Clock::now();
    SceneSimulation pass(ps);
    std::vector<float> field;
    double lo = 0, hi = 0;
    int last_pct = -1;
    for (int f = 0; f < frames && !signals.received(); ++f) {
      pass.advance(f);
      if (pass.state().failed || !pass.state().u.allFinite()) break;
      // The 0.5 % and 99.5 % quantiles of each frame (a handful of nodes under an
      // instrument would otherwise set the range and leave the rest of the organ one colour);
      // values beyond the range saturate.
      render::scalar_field(output.stress_view().quantity, pass.state(), field);
      if (output.stress_view().quantity == render::Quantity::contact_pressure) {
        // Contact pressure: the instruments' contact patches only. The fixed nodes' reactions
        // (the organ resting on its support) are many and small and would set the range.
        size_t kept = 0;
        for (size_t i = 0; i < field.size(); ++i)
          if (field[i] > 0.0f && ps.model.held.row(static_cast<Eigen::Index>(i)).minCoeff() == 0) field[kept++] = field[i];
        field.resize(kept);
        if (field.empty()) {
          progress("colour range", f + 1, frames, last_pct);
          continue;
        }
      }
      const size_t k_lo = field.size() / 200, k_hi = field.size() - 1 - field.size() / 200;
      std::nth_element(field.begin(), field.begin() + k_hi, field.end());
      hi = std::max(hi, double(field[k_hi]));
      std::nth_element(field.begin(), field.begin() + k_lo, field.end());
      lo = std::min(lo, double(field[k_lo]));
      progress("colour range", f + 1, frames, last_pct);
    }
    if (terminal) err << "\n";
    if (render::quantity_is_signed(output.stress_view().quantity)) {
      const double a = std::max(std::abs(lo), std::abs(hi));
      lo = -a;
      hi = a;
    } else {
      lo = 0;
    }
    if (!(hi > lo)) hi = lo + 1e-12 + std::abs(lo) * 1e-6;
    output.set_stress_range(lo, hi);
    first_pass_ms = ms_since(t0);
  }

  // metrics.csv: a resumed run keeps the rows of the frames before `start`.
  std::vector<std::string> kept_rows;
  std::string last_hash;  // state hash after the last complete frame
  if (opt.resume) {
    std::ifstream old(dir / "metrics.csv");
    std::string line;
    std::getline(old, line);  // header
    while (static_cast<int>(kept_rows.size()) < start && std::getline(old, line)) kept_rows.push_back(line);
    if (static_cast<int>(kept_rows.size()) < start) {
      err << "vdmsim: error: " << (dir / "metrics.csv").string() << ": has fewer rows than the checkpoint's "
          << start << " frames: cannot resume\n";
      return 2;
    }
  }
  std::ofstream metrics(dir / "metrics.csv");
  if (!metrics) {
    err << "vdmsim: error: " << (dir / "metrics.csv").string() << ": cannot open for writing\n";
    return 1;
  }
  metrics << "frame,time_s,step_ms,iterations,residual,volume,volume_rel_error,pressure_pa,contact_nodes,"
             "contact_force_n,max_penetration_m,max_displacement_m,max_stress_pa,fallbacks\n";
  for (const std::string& row : kept_rows) metrics << row << '\n';
  metrics << std::setprecision(9);
  metrics.flush();
  if (!metrics) {
    err << "vdmsim: error: " << (dir / "metrics.csv").string() << ": write failed (disk full?)\n";
    return 1;
  }
  std::uintmax_t metrics_good_size = static_cast<std::uintmax_t>(metrics.tellp());
  // File size after each row written by this run (frame start + k), to cut metrics.csv back
  // to the frames whose images are on disk if an image write fails.
  std::vector<std::uintmax_t> row_end;
  const std::uintmax_t rows_base = metrics_good_size;
  std::optional<SceneSimulation> simulation(std::in_place, ps);  // (freed before the contact sheet)
  SceneSimulation& sim = *simulation;
  // What setting up the scene, the renderer and the simulation freed (the mesh as read,
  // the model's and the solver's temporaries, FCL's tree once copied) goes back to the
  // system now: malloc keeps freed pages inside its heaps otherwise.
  malloc_trim(0);
  double io_ms = 0, sum_step = 0, max_step = 0, max_vol = 0;
  // The state snapshot (state.bin) goes with each checkpoint, written first: a resume loads
  // it when it is of the checkpoint's frame, and re-simulates otherwise. It only saves time:
  // when it cannot be written (disk full) the run goes on without it.
  const fs::path state_path = dir / "state.bin";
  bool snapshots = true;
  auto save_snapshot = [&](int frame) {
    StateFile sf{this_run, frame, max_vol, {}};
    std::string why;
    if (!snapshots || !sim.save(sf.snapshot)) return;  // a reference model: resumed by re-simulating
    if (!write_state_file(state_path.string(), sf, why)) {
      err << "vdmsim: warning: " << why << ": a resume will re-simulate instead\n";
      std::error_code ec;
      fs::remove(state_path, ec);
      snapshots = false;
    }
  };
  auto checkpoint = [&](int frame) {
    Checkpoint cp{this_run, frame, frames, last_hash, output.stress_view().lo, output.stress_view().hi};
    if (!(rendering && s.render.stress && s.render.range_auto)) cp.range_lo = cp.range_hi = 0;
    save_snapshot(frame);
    return write_checkpoint(checkpoint_path.string(), cp, error);
  };
  int first = 0;  // the first frame simulated: `start` when the snapshot was loaded
  if (opt.resume) {
    // Checked on a scratch simulation first: a snapshot that does not load leaves `sim` as new.
    StateFile sf;
    std::string why;
    SceneSimulation scratch(ps);
    if (read_state_file(state_path.string(), sf, why) && sf.run_hash == this_run && sf.frame == resume_cp.frame &&
        scratch.load(sf.snapshot, why) && state_hash(scratch.state()) == resume_cp.state_hash && sim.load(sf.snapshot, why)) {
      first = start;
      max_vol = sf.max_volume_error;
    }
  }
  std::vector<double> step_times;
  step_times.reserve(static_cast<size_t>(frames));
  std::string status = "completed", reason;
  int done = first, last_pct = -1;
  int state_frame = first - 1;  // the last complete frame, whose state `sim` holds
  for (int f = first; f < frames; ++f) {
    if (signals.received()) {
      status = "interrupted";
      reason = std::string(signals.received() == SIGINT ? "SIGINT (Ctrl-C)" : "SIGTERM") + " before frame " +
               std::to_string(f) + "; every frame before it is complete";
      break;
    }
    sim.advance(f);
    const vdm::SimState& state = sim.state();
    const vdm::StepStats& st = state.stats;
    if (state.failed) {  // the engine could not do this frame: stop, keeping every frame so far
      status = "failed";
      reason = "frame " + std::to_string(f) + ": " + state.failure;
      break;
    }
    if (!state.u.allFinite()) {
      status = "failed";
      reason = "non-finite displacement at frame " + std::to_string(f);
      break;
    }
    const double step_ms = sim.frame_step_ms();
    sum_step += step_ms;
    max_step = std::max(max_step, step_ms);
    step_times.push_back(step_ms);
    max_vol = std::max(max_vol, std::abs(state.volume_rel_error));
    if (f < start) {  // resuming: re-simulated only, already written
      if (f == resume_cp.frame && state_hash(state) != resume_cp.state_hash) {
        status = "failed";
        reason = "resuming: re-simulating up to frame " + std::to_string(f) +
                 " did not reproduce the checkpoint's state (was the program or a mesh changed?)";
        break;
      }
      done = f + 1;
      progress("replay", done, start, last_pct);
      if (done == start) last_pct = -1;
      continue;
    }
    const auto t_io = Clock::now();
    metrics << f << ',' << sim.time() << ',' << step_ms << ',' << sim.frame_iterations() << ',' << st.residual << ','
            << state.volume << ',' << state.volume_rel_error << ',' << state.pressure << ',';
    if (sim.contact_simulated()) {
      const vdm::ContactReport& report = sim.contact_report();
      metrics << report.nodes << ',' << report.force.norm() << ',' << report.max_penetration << ',';
    } else {
      metrics << ",,,";  // the contact effect is not simulated: its columns stay empty
    }
    metrics << state.u.rowwise().norm().maxCoeff() << ',';
    if (m.compute_stress) metrics << state.stress.rowwise().norm().maxCoeff();
    metrics << ',' << sim.frame_fallbacks() << '\n';
    // Each row reaches the file before the frame counts as done; a failed write (disk full) is
    // cut back to the last whole row so that the file stays valid.
    metrics.flush();
    if (!metrics) {
      status = "failed";
      reason = (dir / "metrics.csv").string() + ": write failed at frame " + std::to_string(f) + " (disk full?)";
      metrics.close();
      std::error_code ec;
      fs::resize_file(dir / "metrics.csv", metrics_good_size, ec);
      break;
    }
    metrics_good_size = static_cast<std::uintmax_t>(metrics.tellp());
    row_end.push_back(metrics_good_size);
    io_ms += ms_since(t_io);
    if (rendering && !output.write(f, frames, sim)) {
      status = "failed";
      reason = output.error();
      break;
    }
    done = f + 1;
    state_frame = f;
    last_hash = state_hash(state);
    if (opt.frame_done_ms) opt.frame_done_ms->push_back(ms_since(t_run));
    progress(rendering ? "render" : "simulate", done, frames, last_pct);
    // A checkpoint every K frames, once this frame's images are on disk.
    if (done % std::max(1, opt.checkpoint_every) == 0 && done < frames) {
      metrics.flush();
      if (rendering && !output.flush()) {
        status = "failed";
        reason = output.error();
        break;
      }
      if (!checkpoint(f)) {
        status = "failed";
        reason = error;
        break;
      }
    }
  }
  if (terminal) err << "\n";
  if (metrics.is_open()) metrics.flush();
  // What run.json needs from the simulation. A completed run needs no more of it (no state
  // snapshot): its memory goes before finish() draws the contact sheet, whose GL context and
  // shaders would otherwise come on top of the engine's.
  const StageTimes times = sim.stage_times();
  const std::vector<std::string> warnings = sim.state().warnings;
  if (status == "completed") simulation.reset();
  if (rendering && !output.finish(error) && status == "completed") {
    status = "failed";
    reason = error;
  }
  // After an image write failure, only the frames whose images all reached the disk count:
  // metrics.csv is cut back to them (the writer reports a failure a frame or more late).
  if (rendering && !output.error().empty()) {
    const int views = (s.render.shaded ? 1 : 0) + (s.render.stress ? 1 : 0);
    const int complete = start + static_cast<int>(output.images_written() / std::max(1, views));
    if (complete < done) {
      done = complete;
      if (metrics.is_open()) metrics.close();
      std::error_code ec;
      fs::resize_file(dir / "metrics.csv", done > start ? row_end[static_cast<size_t>(done - start - 1)] : rows_base, ec);
    }
  }
  // The final checkpoint: the last frame whose row and images are complete.
  if (done > start && (!rendering || output.error().empty())) {
    std::string cp_error;
    Checkpoint cp{this_run, done - 1, frames, last_hash, output.stress_view().lo, output.stress_view().hi};
    if (!(rendering && s.render.stress && s.render.range_auto)) cp.range_lo = cp.range_hi = 0;
    // A snapshot only of a state that is that frame's (not after a failed or cut-back frame,
    // whose grasps or state moved on); without one a resume re-simulates.
    const bool snapshot = simulation && done < frames && done - 1 == state_frame &&
                          (status == "completed" || status == "interrupted");
    std::error_code ec;
    if (snapshot) save_snapshot(done - 1);
    else fs::remove(state_path, ec);
    if (!write_checkpoint(checkpoint_path.string(), cp, cp_error)) err << "vdmsim: warning: " << cp_error << "\n";
  }
  // Video from the PNG sequences.
  std::string video_status = opt.video ? "" : "not requested";
  if (opt.video && done > 0 && status == "completed") {
    const double t0_ms = ms_since(t_run);
    bool ok = true;
    if (s.render.shaded)
      ok = render::encode_video((dir / "frames" / "frame_%05d.png").string(), s.render.fps, (dir / "video.mp4").string(),
                                (dir / "ffmpeg.log").string(), error);
    if (ok && s.render.stress)
      ok = render::encode_video((dir / "stress" / "stress_%05d.png").string(), s.render.fps,
                                (dir / (s.render.shaded ? "stress.mp4" : "video.mp4")).string(),
                                (dir / "ffmpeg.log").string(), error);
    if (signals.received()) {  // Ctrl-C reached ffmpeg too: no half video
      std::error_code ec;
      fs::remove(dir / "video.mp4", ec);
      fs::remove(dir / "stress.mp4", ec);
      ok = false;
      status = "interrupted";
      reason = "interrupted while encoding the video; every frame is complete, the video is not written";
      error = reason;
    }
    video_status = ok ? "written" : "failed: " + error;
    if (!ok && status != "interrupted") {
      err << "vdmsim: error: " << error << "\n";
      if (status == "completed") {
        status = "failed";
        reason = error;
      }
    }
    io_ms += ms_since(t_run) - t0_ms;
  }
  const double wall = ms_since(t_run) / 1000.0;

  std::vector<double> sorted = step_times;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted.empty() ? 0.0 : sorted[sorted.size() / 2];
  std::ostringstream js;
  js << std::setprecision(9);
  js << "{\n  \"scene\": \"" << json_escape(s.name) << "\",\n  \"scene_file\": \"" << json_escape(s.file)
     << "\",\n  \"status\": \"" << status << "\",\n";
  if (!reason.empty()) js << "  \"reason\": \"" << json_escape(reason) << "\",\n";
  if (opt.resume)
    js << "  \"resumed_from_frame\": " << start << ",\n  \"resumed_by\": \""
       << (first > 0 ? "state snapshot" : "re-simulation") << "\",\n";
  js << "  \"frames\": " << done << ",\n  \"frames_requested\": " << frames << ",\n  \"nodes\": " << m.n
     << ",\n  \"model\": \"" << vdm::to_string(s.model) << "\",\n  \"solver\": \"" << vdm::to_string(m.solver.method)
     << "\",\n  \"effects\": [";
  for (size_t i = 0; i < s.effects.size(); ++i) js << (i ? ", " : "") << '"' << to_string(s.effects[i]) << '"';
  js << "],\n";
  if (s.has(Effect::contact)) {
    const bool penalty = s.contact.method == vdm::ContactSettings::Method::penalty;
    js << "  \"contact\": {\"method\": \"" << (penalty ? "penalty" : "kinematic") << '"';
    if (penalty) js << ", \"stiffness_pa_per_m\": " << s.contact.penalty_stiffness;
    js << "},\n";
  }
  js << "  \"wall_time_s\": " << wall << ",\n  \"mean_step_ms\": "
     << (step_times.empty() ? 0.0 : sum_step / double(step_times.size()))
     << ",\n  \"median_step_ms\": " << median << ",\n  \"max_step_ms\": " << max_step
     << ",\n  \"max_volume_rel_error\": " << max_vol << ",\n  \"stage_ms\": {\"loads\": " << times.loads
     << ", \"assemble\": " << times.assemble << ", \"solve\": " << times.solve << ", \"stress\": " << times.stress
     << ", \"grasp\": " << times.grasp << ", \"collision\": " << times.collision << ", \"metrics_io\": " << io_ms;
  if (rendering)
    js << ", \"colour_range_pass\": " << first_pass_ms << ", \"render\": " << output.render_ms()
       << ", \"png_encode\": " << output.encode_ms();
  js << "},\n  \"collision_queries\": " << times.collision_queries << ",\n";
  if (rendering) {
    const RenderDef& rd = s.render;
    js << "  \"render\": {\"width\": " << rd.settings.width << ", \"height\": " << rd.settings.height
       << ", \"antialias\": \"" << render::to_string(rd.settings.antialias) << "\", \"samples\": "
       << rd.settings.msaa_samples() << ", \"views\": [" << (rd.shaded ? "\"shaded\"" : "")
       << (rd.shaded && rd.stress ? ", " : "") << (rd.stress ? "\"stress\"" : "") << "], \"images_written\": "
       << output.images_written();
    if (rd.stress)
      js << ", \"stress_quantity\": \"" << render::to_string(output.stress_view().quantity) << "\", \"stress_range\": ["
         << output.stress_view().lo << ", " << output.stress_view().hi << "], \"stress_range_source\": \""
         << (rd.range_auto ? "first pass" : "scene") << "\"";
    js << ", \"video\": \"" << json_escape(video_status) << "\"},\n";
  } else {
    js << "  \"render\": null,\n";
  }
  js << "  \"warnings\": [";
  for (size_t i = 0; i < warnings.size(); ++i) js << (i ? ", " : "") << '"' << json_escape(warnings[i]) << '"';
  js << "]\n}\n";
  if (!write_run_json(dir / "run.json", js.str(), error)) {
    err << "vdmsim: error: " << error << "\n";
    return 1;
  }
  out << s.name << ": " << done << " frames, " << m.n << " nodes, median step " << median << " ms, max |volume error| "
      << max_vol << (rendering ? ", " + std::to_string(output.images_written()) + " images" : std::string())
      << ", status " << status << " -> " << dir.string() << "\n";
  if (status == "interrupted") {
    err << "vdmsim: interrupted: " << reason << "\n";
    return 130;
  }
  if (status != "completed") err << "vdmsim: error: " << reason << "\n";
  return status == "completed" ? 0 : 1;
}

}  // namespace vdmsim
