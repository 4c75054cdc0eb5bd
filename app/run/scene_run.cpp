#include "app/run/scene_run.hpp"

#include <malloc.h>

#include <algorithm>
#include <optional>

#include "app/run/colour_range.hpp"
#include "app/run/frame_loop.hpp"
#include "app/run/frame_output.hpp"
#include "app/run/mesh_export.hpp"
#include "app/run/metrics_csv.hpp"
#include "app/run/output_dir.hpp"
#include "app/run/progress.hpp"
#include "app/run/run_checkpoints.hpp"
#include "app/run/run_json.hpp"
#include "app/run/run_setup.hpp"
#include "app/run/run_video.hpp"
#include "app/run/stop_signals.hpp"
#include "app/simulation/scene_simulation.hpp"
#include "engine/stopwatch.hpp"

namespace vdmsim {
namespace {

// After an image or poses write failure only the frames whose images all reached the disk
// count (the writer reports a failure a frame or more late), and not the frame whose output
// failed: metrics.csv and poses.csv are cut back to them.
void keep_frames_with_images(const RenderDef& rd, const RunSetup& setup, FrameOutput& output, MetricsCsv& metrics,
                             RunOutcome& outcome) {
  const int views = static_cast<int>(rd.views.size());
  const int complete = setup.start + static_cast<int>(output.images_written() / std::max(1, views));
  outcome.done = std::min(outcome.done, complete);
  metrics.cut_back(outcome.done - setup.start);
  output.keep_frames(outcome.done);
}

// The run's last line on stdout, and its exit code: 0 completed, 130 interrupted, 1 failed.
int report(const RunRecord& r, std::ostream& out, std::ostream& err) {
  const SceneDef& s = r.prepared.scene;
  const RunOutcome& o = r.outcome;
  out << s.name << ": " << o.done << " frames, " << r.prepared.surface.node_count() << " nodes, median step " << r.tally.median_step()
      << " ms, max |volume error| " << r.tally.max_volume_error
      << (r.setup.rendering ? ", " + std::to_string(r.output.images_written()) + " images" : std::string())
      << ", status " << o.status << " -> " << r.setup.dir.string() << "\n";
  if (o.status == "interrupted") {
    err << "vdmsim: interrupted: " << o.reason << "\n";
    return 130;
  }
  if (o.status != "completed") err << "vdmsim: error: " << o.reason << "\n";
  return o.status == "completed" ? 0 : 1;
}

}  // namespace

int run_scene(PreparedScene& ps, const RunOptions& opt, std::ostream& out, std::ostream& err, bool terminal) {
  const SceneDef& s = ps.scene;
  RunSetup setup;
  if (const int code = set_up_run(ps, opt, setup, err); code >= 0) return code;
  const StopSignals signals;
  FrameOutput output;
  std::string error;
  if (setup.rendering) {
    if (const int code = output.open(ps, setup.dir, setup.frames, error, setup.start, opt.fail_render_at_frame);
        code >= 0) {
      err << "vdmsim: error: " << error << "\n";
      return code;
    }
  }
  const auto t_run = vdm::Clock::now();
  Progress progress(err, terminal);
  const double colour_range_ms = set_auto_colour_range(ps, setup, output, signals, progress);
  MeshExport mesh;
  if (opt.export_mesh && !mesh.open(ps, setup.dir, setup.start, error)) {
    err << "vdmsim: error: " << error << "\n";
    return 1;
  }
  MetricsCsv metrics;
  std::vector<std::string> organ_names;
  bool stress = false;
  for (size_t i = 0; i < ps.organs.size(); ++i) {
    organ_names.push_back(ps.scene.organs[i].name);
    stress = stress || ps.organs[i].model.compute_stress;
  }
  if (const int code = metrics.open(setup.dir, setup.start, setup.resume, stress, err, organ_names); code >= 0)
    return code;

  std::optional<SceneSimulation> simulation(std::in_place, ps);  // (freed before the contact sheet)
  // What setting up the scene, the renderer and the simulation freed (the mesh as read,
  // the model's and the solver's temporaries, FCL's tree once copied) goes back to the
  // system now: malloc keeps freed pages inside its heaps otherwise.
  malloc_trim(0);
  RunTally tally;
  RunCheckpoints checkpoints(ps, setup, output, err);
  // The first frame simulated: `start` when the state snapshot was loaded.
  SnapshotLoad snapshot = SnapshotLoad::absent;
  if (setup.resume) {
    snapshot = checkpoints.load_snapshot(*simulation, tally.max_volume_error, error);
    if (snapshot == SnapshotLoad::damaged) {
      err << "vdmsim: error: " << error << ": cannot resume (run it afresh without --resume)\n";
      return 2;
    }
  }
  const bool from_snapshot = snapshot == SnapshotLoad::loaded;
  RunOutcome outcome;
  FrameLoop{setup, opt, *simulation, metrics, output, mesh, checkpoints, signals, progress, t_run}.run(
      from_snapshot ? setup.start : 0, tally, outcome);
  metrics.flush();

  // What run.json needs from the simulation. A completed run needs no more of it (no state
  // snapshot): its memory goes before finish() draws the contact sheet, whose GL context and
  // shaders would otherwise come on top of the engine's.
  RunRecord record{ps, setup, outcome, tally, output};
  record.mesh = &mesh;
  record.resumed_by_snapshot = from_snapshot;
  record.colour_range_ms = colour_range_ms;
  record.stage_times = simulation->stage_times();
  record.warnings = simulation->warnings();
  for (size_t i = 0; i < simulation->organ_count(); ++i)
    record.organ_max_volume_errors.push_back(simulation->max_volume_error(i));
  record.forces = simulation->forces_simulated();
  record.peak_forces = simulation->peak_forces();
  record.contact_iterations = simulation->contact_iterations();
  record.unconverged_contact_steps = simulation->unconverged_contact_steps();
  if (record.unconverged_contact_steps > 0) {
    const std::string w = "contact: " + std::to_string(record.unconverged_contact_steps) +
                          " steps stopped with the instruments' contact set still changing (run.json contact.unconverged_steps)";
    record.warnings.push_back(w);
    err << "vdmsim: warning: " << w << "\n";
  }
  if (outcome.status == "completed") simulation.reset();
  if (setup.rendering && !output.finish(error) && outcome.status == "completed") outcome.fail(error);
  if (setup.rendering && !output.error().empty()) {
    keep_frames_with_images(s.render, setup, output, metrics, outcome);
    if (!mesh.keep_frames(outcome.done, error)) err << "vdmsim: warning: " << error << "\n";
  }
  // The last checkpoint: the last frame whose row and images are complete, with a snapshot
  // only of a state that is that frame's (not after a failed or cut-back frame, whose grasps
  // or state moved on); without one a resume re-simulates.
  if (outcome.done > setup.start && (!setup.rendering || output.error().empty())) {
    const bool snapshot = simulation && outcome.done < setup.frames && outcome.done - 1 == outcome.state_frame &&
                          (outcome.status == "completed" || outcome.status == "interrupted");
    checkpoints.write_last(outcome.done - 1, outcome.last_hash, snapshot ? &*simulation : nullptr,
                           tally.max_volume_error);
  }
  record.video_status = opt.video ? "" : "not requested";
  if (opt.video && outcome.done > 0 && outcome.status == "completed") {
    const double t0_ms = vdm::ms_since(t_run);
    record.video_status = encode_run_videos(s.render, setup.dir, signals, outcome, err);
    tally.io_ms += vdm::ms_since(t_run) - t0_ms;
  }
  record.wall_s = vdm::ms_since(t_run) / 1000.0;
  if (!write_file_atomically(setup.dir / "run.json", run_json(record), error)) {
    err << "vdmsim: error: " << error << "\n";
    report(record, out, err);  // what stopped the run, too (often the same full disk)
    return 1;
  }
  return report(record, out, err);
}

}  // namespace vdmsim
