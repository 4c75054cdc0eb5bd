#include "app/run/frame_loop.hpp"

#include <algorithm>
#include <cmath>
#include <csignal>

namespace vdmsim {
namespace {
// The hash of every organ's state (one organ's: its state's own).
std::string scene_state_hash(const SceneSimulation& sim) {
  std::string h = state_hash(sim.state(0));
  for (size_t i = 1; i < sim.organ_count(); ++i) h += "-" + state_hash(sim.state(i));
  return h;
}
}  // namespace

void RunTally::add_step(double ms) {
  sum_step += ms;
  max_step = std::max(max_step, ms);
  step_ms.push_back(ms);
}

double RunTally::median_step() const {
  std::vector<double> sorted = step_ms;
  std::sort(sorted.begin(), sorted.end());
  return sorted.empty() ? 0.0 : sorted[sorted.size() / 2];
}

void FrameLoop::run(int first, RunTally& tally, RunOutcome& outcome) {
  // Grown as frames are done: a run stopped early (or failing at once) holds only what it used.
  tally.step_ms.reserve(static_cast<size_t>(std::min(setup.frames, 1 << 16)));
  outcome.done = first;
  outcome.state_frame = first - 1;
  progress.restart();
  for (int f = first; f < setup.frames; ++f) {
    if (const int sig = signals.received()) {
      outcome.status = "interrupted";
      outcome.reason = std::string(sig == SIGINT ? "SIGINT (Ctrl-C)" : "SIGTERM") + " before frame " + std::to_string(f) +
                       "; every frame before it is complete";
      break;
    }
    sim.advance(f);
    if (sim.failed()) {  // the engine could not do this frame: stop, keeping every frame so far
      outcome.fail("frame " + std::to_string(f) + ": " + sim.failure());
      break;
    }
    // Nothing unsound is written: the run stops as failed, every frame before this one kept.
    if (const std::string why = sim.unsound(); !why.empty()) {
      outcome.fail(why + " at frame " + std::to_string(f));
      break;
    }
    if (sim.frame_stepped()) tally.add_step(sim.frame_step_ms());  // an inertial frame 0 takes none
    for (size_t i = 0; i < sim.organ_count(); ++i)
      tally.max_volume_error = std::max(tally.max_volume_error, std::abs(sim.state(i).volume_rel_error));
    if (!(f < setup.start ? replay(f, outcome) : write(f, tally, outcome))) break;
  }
  progress.end_line();
}

bool FrameLoop::replay(int f, RunOutcome& outcome) {
  const Checkpoint& cp = setup.resume_from;
  if (f == cp.frame && scene_state_hash(sim) != cp.state_hash) {
    outcome.fail("resuming: re-simulating up to frame " + std::to_string(f) +
                 " did not reproduce the checkpoint's state (was the program or a mesh changed?)");
    return false;
  }
  outcome.done = f + 1;
  progress.show("replay", outcome.done, setup.start);
  if (outcome.done == setup.start) progress.restart();
  return true;
}

bool FrameLoop::write(int f, RunTally& tally, RunOutcome& outcome) {
  const auto t_io = vdm::Clock::now();
  std::string reason;
  if (!metrics.write(f, sim, reason)) {
    outcome.fail(reason);
    return false;
  }
  tally.io_ms += vdm::ms_since(t_io);
  if (!mesh.write(f, sim, reason)) {  // the frame is not done: its metrics row goes too
    metrics.cut_back(f - setup.start);
    outcome.fail(reason);
    return false;
  }
  if (setup.rendering && !output.write(f, setup.frames, sim)) {
    outcome.fail(output.error());
    return false;
  }
  outcome.done = f + 1;
  outcome.state_frame = f;
  outcome.last_hash = scene_state_hash(sim);
  if (options.frame_done_ms) options.frame_done_ms->push_back(vdm::ms_since(run_start));
  progress.show(setup.rendering ? "render" : "simulate", outcome.done, setup.frames);
  // A checkpoint after the first frame written (a disk that fills up early still leaves a run
  // to resume) and every K frames, once this frame's images are on disk.
  const bool due = f == setup.start || outcome.done % std::max(1, options.checkpoint_every) == 0;
  if (due && outcome.done < setup.frames) {
    metrics.flush();
    if (setup.rendering && !output.flush()) {
      outcome.fail(output.error());
      return false;
    }
    std::string error;
    if (!checkpoints.write(f, outcome.last_hash, sim, tally.max_volume_error, error)) {
      outcome.fail(error);
      return false;
    }
  }
  return true;
}

}  // namespace vdmsim
