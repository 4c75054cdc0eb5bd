#include "app/studies/bench.hpp"
#include "app/studies/bench_endoscope.hpp"
#include "app/studies/bench_organs.hpp"
#include "app/studies/bench_scanned_liver.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "app/install/install_paths.hpp"
#include "app/studies/bench_bullet.hpp"
#include "app/run/frame_output.hpp"
#include "app/run/output_dir.hpp"
#include "app/run/scene_run.hpp"
#include "app/scene/mesh_io.hpp"
#include "app/scene/organ_generator.hpp"
#include "app/studies/quantile.hpp"
#include "app/simulation/scene_simulation.hpp"
#include "engine/organ_solver.hpp"
#include "engine/stopwatch.hpp"
#include "render/number_format.hpp"
#include "render/plot.hpp"
#include "render/png_io.hpp"
#include "render/renderer.hpp"

namespace vdmsim {
namespace {

namespace fs = std::filesystem;
using vdm::Clock;
using vdm::ms_since;

struct Row {
  std::string name, model;
  long nodes = 0;
  double median_ms = 0, p95_ms = 0, iterations = 0, volume_rel_error = 0, peak_mb = 0;
};

double peak_mb() {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  return 0;
}

std::string format_row(const Row& r) {
  std::ostringstream s;
  s << std::setprecision(9) << r.name << ',' << r.model << ',' << r.nodes << ',' << r.median_ms << ',' << r.p95_ms << ','
    << r.iterations << ',' << r.volume_rel_error << ',' << r.peak_mb << '\n';
  return s.str();
}

// Runs one case in a new process: this program exec'd again as `bench --only LABEL --case-fd
// N`, which runs the case and writes its CSV row to descriptor N (a pipe). A new program, not
// only a fork: its peak memory counts every page it touches itself, the shared libraries'
// included (a forked child inherits the parent's resident library pages without counting
// them: at 40k nodes with rendering that hid about 65 MB).
bool run_isolated(const std::string& label, const std::string& out_dir, bool quick, Row& row, std::string& error) {
  int fd[2];
  if (pipe(fd) != 0) {
    error = "pipe failed";
    return false;
  }
  const pid_t pid = fork();
  if (pid == 0) {
    close(fd[0]);
    const std::string fd_text = std::to_string(fd[1]);
    std::vector<const char*> args = {"vdmsim", "bench", "--out", out_dir.c_str(), "--only", label.c_str(), "--case-fd",
                                     fd_text.c_str()};
    if (quick) args.push_back("--quick");
    args.push_back(nullptr);
    execv("/proc/self/exe", const_cast<char* const*>(args.data()));
    std::fprintf(stderr, "vdmsim: bench: cannot run /proc/self/exe\n");
    _exit(1);
  }
  close(fd[1]);
  std::string text;
  char buf[512];
  ssize_t n;
  while ((n = read(fd[0], buf, sizeof buf)) > 0) text.append(buf, size_t(n));
  close(fd[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || text.empty()) {
    error = "the benchmark process failed";
    return false;
  }
  std::stringstream s(text);
  std::string field;
  std::vector<std::string> f;
  while (std::getline(s, field, ',')) f.push_back(field);
  if (f.size() != 8) {
    error = "bad benchmark output: " + text;
    return false;
  }
  row = {f[0], f[1], std::stol(f[2]), std::stod(f[3]), std::stod(f[4]), std::stod(f[5]), std::stod(f[6]), std::stod(f[7])};
  return true;
}

}  // namespace

// The bench's vdm rows time the paper's model (organ.model vdm) on the example scenes' paths;
// the scenes give no moduli (they run the default model), so VDM's defaults are used:
// bulk_modulus 20000 Pa, connectivity_modulus 2000 Pa.
namespace {
void on_paper_model(SceneDef& s) {
  s.organ().model = vdm::ModelKind::vdm;
  s.organ().bulk_modulus = OrganDef().bulk_modulus;
  s.organ().connectivity_modulus = OrganDef().connectivity_modulus;
  s.organ().moduli_from_elastic = false;
}
}  // namespace

PreparedScene bench_probe_scene(const std::string& mesh, int frames, bool render, double tolerance,
                                double volume_tolerance, vdm::CapsuleForm capsule) {
  PreparedScene ps;
  std::vector<SceneProblem> problems;
  const std::string path = (fs::path(data_dir()) / "scenes" / "probe_poke.yaml").string();
  SceneLoadResult loaded = load_scene(path);
  if (!loaded.ok()) throw std::runtime_error(path + ": cannot load");
  SceneDef s = loaded.scene;
  s.organ().mesh_path = mesh.find('/') != std::string::npos ? mesh : (fs::path(data_dir()) / "meshes" / mesh).string();
  on_paper_model(s);
  s.frames = frames;
  s.solver.tolerance = tolerance;
  s.solver.volume_tolerance = volume_tolerance;
  s.organ().capsule = capsule;
  // The probe holds the tissue it touches (kinematic contact): the case times the organ's
  // step, one solve per contact set, as Bullet's soft body is timed; what sliding contact
  // with friction costs over it is the liver_slide case.
  s.contact.method = vdm::ContactSettings::Method::kinematic;
  for (auto& in : s.instruments) in.radius = 0.008;
  if (!render) s.has_render = false;
  s.render.remove(render::View::stress);
  if (!prepare_scene_def(s, ps, problems))
    throw std::runtime_error(problems.empty() ? "cannot prepare the probe scene" : problems.back().text());
  return ps;
}

ToleranceError bench_tolerance_error(const std::string& mesh, double tolerance, double reference_tolerance) {
  const PreparedScene loose = bench_probe_scene(mesh, 60, false, tolerance);
  const PreparedScene tight = bench_probe_scene(mesh, 60, false, reference_tolerance, vdm::SolverSettings().volume_tolerance);
  SceneSimulation a(loose), b(tight);
  ToleranceError e;
  e.nodes = loose.organ().model.n;
  double sum2 = 0;
  long count = 0;
  for (int f = 0; f < 60; ++f) {
    a.advance(f);
    b.advance(f);
    for (int i = 0; i < loose.organ().model.n; ++i) {
      const double d2 = (a.state().u.row(i) - b.state().u.row(i)).squaredNorm();
      e.max_m = std::max(e.max_m, std::sqrt(d2));
      sum2 += d2;
      ++count;
    }
  }
  e.rms_m = count ? std::sqrt(sum2 / double(count)) : 0.0;
  return e;
}

namespace {

PreparedScene probe_scene(const std::string& mesh, int frames, bool render) { return bench_probe_scene(mesh, frames, render); }

// Runs `ps` for its frames (60 at most), `repeats` times, timing the steps that `timed(rep, f, sim)`
// accepts, and fills the row's step figures.
template <typename Timed>
void time_steps(const PreparedScene& ps, int repeats, Timed timed, Row& r) {
  std::vector<double> times;
  double iterations = 0, vol = 0;
  for (int rep = 0; rep < repeats; ++rep) {
    SceneSimulation sim(ps);
    for (int f = 0; f < std::min(ps.scene.frames, 60); ++f) {
      sim.advance(f);
      if (!timed(rep, f, sim)) continue;
      times.push_back(sim.frame_step_ms());
      iterations += sim.frame_iterations();
      vol = std::max(vol, std::abs(sim.state().volume_rel_error));
    }
  }
  r.nodes = ps.organ().model.n;
  r.median_ms = quantile(times, 0.5);
  r.p95_ms = quantile(times, 0.95);
  r.iterations = times.empty() ? 0 : iterations / double(times.size());
  r.volume_rel_error = vol;
}

// `capsule`: the model's default form (row "vdm"), or another (row "vdm_<form>", the same
// case side by side: what the form costs).
Row bench_probe(const std::string& mesh, int repeats, vdm::CapsuleForm capsule = vdm::CapsuleForm::membrane) {
  Row r{"liver_probe", capsule == vdm::CapsuleForm::membrane ? "vdm" : std::string("vdm_") + vdm::to_string(capsule)};
  const PreparedScene ps = bench_probe_scene(mesh, 60, false, kBenchTolerance, kBenchVolumeTolerance, capsule);
  // Only steps in contact are timed; the first contact steps warm up.
  time_steps(ps, repeats,
             [](int rep, int f, const SceneSimulation& sim) { return sim.contact_report().nodes > 0 && (rep > 0 || f > 20); },
             r);
  return r;
}

// The FEM reference (corotational tets, static Newton: organ.model fem, E = 5 kPa, nu = 0.45
// as in the accuracy study) on the same probe scene, on the level-3 liver (642 surface
// nodes; FEM is too slow on the bench's larger livers), written to `dir`. The same
// timing as bench_probe; `vdm` at the same level is the row to compare with.
std::string write_level3_liver(const fs::path& dir) {
  const std::string mesh = (dir / "liver_L3.obj").string();
  std::string error;
  if (!save_obj(make_liver_mesh(3), mesh, "vdmsim liver level 3 (app/organ_generator.cpp), for `vdmsim bench`", error))
    throw std::runtime_error(error);
  return mesh;
}

Row bench_fem(const fs::path& dir, int frames) {
  Row r{"liver_probe", "fem"};
  const std::string mesh = write_level3_liver(dir);
  PreparedScene ps;
  std::vector<SceneProblem> problems;
  {
    PreparedScene vdm_scene = probe_scene(mesh, frames, false);
    SceneDef s = vdm_scene.scene;
    s.organ().model = vdm::ModelKind::fem;
    s.organ().young_modulus = 5000;
    s.organ().poisson_ratio = 0.45;
    if (!prepare_scene_def(s, ps, problems))
      throw std::runtime_error(problems.empty() ? "cannot prepare the FEM probe scene" : problems.back().text());
  }
  time_steps(ps, 1, [](int, int f, const SceneSimulation& sim) { return sim.contact_report().nodes > 0 && f > 20; }, r);
  return r;
}

// VDM on the FEM case's level-3 liver (bench_fem), timed the same way.
Row bench_probe_level3(const fs::path& dir, int repeats) { return bench_probe(write_level3_liver(dir), repeats); }

// Bullet's btSoftBody on the same surface, probe motion and frames as bench_probe; timed the
// same way (frames in contact, the first 20 frames of the first run not timed).
Row bench_bullet(const std::string& mesh, int repeats) {
  Row r{"liver_probe", "bullet"};
  const PreparedScene ps = probe_scene(mesh, 60, false);
  std::vector<double> times;
  for (int rep = 0; rep < repeats; ++rep) {
    const BulletRun run = run_bullet_probe(ps, 60, rep > 0 ? -1 : 20, BulletSettings{});
    times.insert(times.end(), run.step_ms.begin(), run.step_ms.end());
    r.iterations = run.iterations;
    r.volume_rel_error = std::max(r.volume_rel_error, run.volume_rel_error);
    r.nodes = run.nodes;
  }
  r.median_ms = quantile(times, 0.5);
  r.p95_ms = quantile(times, 0.95);
  return r;
}

// VDM (the default membrane capsule), VDM with the paper's capsule and Bullet on the same mesh
// and probe script in one process, run after run in turn (`pairs` rounds of three 60-frame
// runs; timed: the frames in contact after the 20th), so that each ratio compares runs made
// within a second of each other rather than processes started minutes apart (the isolated
// rows of bench.csv).
struct SideBySide {
  long nodes = 0;
  int pairs = 0;
  double vdm_ms = 0, bullet_ms = 0, paper_ms = 0;    // medians of all timed frames
  double ratio = 0;                                 // bullet_ms / vdm_ms
  double pair_ratio_median = 0, pair_ratio_min = 0;  // of each round's medians, Bullet's over VDM's
  double paper_ratio = 0;                           // vdm_ms / paper_ms: what the membrane costs
  double paper_pair_ratio_median = 0, paper_pair_ratio_max = 0;  // of each round's, VDM's over the paper's
};

// The medians of the timed frames of one VDM run of `ps` (frames in contact after the 20th).
std::vector<double> vdm_probe_run(const PreparedScene& ps) {
  std::vector<double> ms;
  SceneSimulation sim(ps);
  for (int f = 0; f < 60; ++f) {
    sim.advance(f);
    if (sim.contact_report().nodes > 0 && f > 20) ms.push_back(sim.frame_step_ms());
  }
  return ms;
}

SideBySide bench_side_by_side(const std::string& mesh, int pairs) {
  const PreparedScene ps = probe_scene(mesh, 60, false);
  const PreparedScene paper =
      bench_probe_scene(mesh, 60, false, kBenchTolerance, kBenchVolumeTolerance, vdm::CapsuleForm::paper);
  std::vector<double> vdm_all, bullet_all, paper_all, ratios, paper_ratios;
  for (int k = 0; k < pairs; ++k) {
    const std::vector<double> vdm_ms = vdm_probe_run(ps);
    const std::vector<double> paper_ms = vdm_probe_run(paper);
    std::vector<double> bullet_ms;
    {
      BulletProbe bullet(ps, BulletSettings{});
      for (int f = 0; f < 60; ++f) {
        const double ms = bullet.advance(f);
        if (bullet.touching() && f > 20) bullet_ms.push_back(ms);
      }
    }
    const double v = quantile(vdm_ms, 0.5), b = quantile(bullet_ms, 0.5), p = quantile(paper_ms, 0.5);
    if (v > 0) ratios.push_back(b / v);
    if (p > 0) paper_ratios.push_back(v / p);
    vdm_all.insert(vdm_all.end(), vdm_ms.begin(), vdm_ms.end());
    bullet_all.insert(bullet_all.end(), bullet_ms.begin(), bullet_ms.end());
    paper_all.insert(paper_all.end(), paper_ms.begin(), paper_ms.end());
  }
  SideBySide r;
  r.nodes = ps.organ().model.n;
  r.pairs = int(ratios.size());
  r.vdm_ms = quantile(vdm_all, 0.5);
  r.bullet_ms = quantile(bullet_all, 0.5);
  r.paper_ms = quantile(paper_all, 0.5);
  r.ratio = r.vdm_ms > 0 ? r.bullet_ms / r.vdm_ms : 0;
  r.pair_ratio_median = quantile(ratios, 0.5);
  r.pair_ratio_min = ratios.empty() ? 0 : *std::min_element(ratios.begin(), ratios.end());
  r.paper_ratio = r.paper_ms > 0 ? r.vdm_ms / r.paper_ms : 0;
  r.paper_pair_ratio_median = quantile(paper_ratios, 0.5);
  r.paper_pair_ratio_max = paper_ratios.empty() ? 0 : *std::max_element(paper_ratios.begin(), paper_ratios.end());
  return r;
}

// The sliding probe of palpation_slide.yaml with sticking (kinematic) and with constraint
// contact (its own friction), run after run in turn (`pairs` pairs; `frames` frames each,
// timed: the frames in contact), so that each ratio compares two runs made seconds apart.
struct SlideSideBySide {
  long nodes = 0;
  int pairs = 0;
  double friction = 0;
  double kinematic_ms = 0, constraint_ms = 0;        // medians of all timed frames
  double ratio = 0;                                  // constraint_ms / kinematic_ms
  double pair_ratio_median = 0, pair_ratio_max = 0;  // of each pair's medians
  double solves = 0;                                 // constraint: mean solves per timed frame
  int unconverged = 0;                               // constraint: steps that reached the cap
};

SlideSideBySide bench_slide_side_by_side(int pairs, int frames) {
  const std::string path = (fs::path(data_dir()) / "scenes" / "palpation_slide.yaml").string();
  SceneLoadResult loaded = load_scene(path);
  if (!loaded.ok()) throw std::runtime_error(path + ": cannot load");
  SlideSideBySide r;
  std::vector<double> all[2], ratios;
  PreparedScene ps[2];
  for (int k = 0; k < 2; ++k) {
    SceneDef s = loaded.scene;
    on_paper_model(s);
    s.frames = frames;
    s.has_render = false;
    s.render.remove(render::View::stress);
    if (k == 0) s.contact.method = vdm::ContactSettings::Method::kinematic;
    std::vector<SceneProblem> problems;
    if (!prepare_scene_def(s, ps[k], problems))
      throw std::runtime_error(problems.empty() ? "cannot prepare the slide scene" : problems.back().text());
  }
  r.friction = loaded.scene.contact.friction;
  long solves = 0, timed = 0;
  for (int p = 0; p < pairs; ++p) {
    double median[2] = {0, 0};
    for (int k = 0; k < 2; ++k) {
      std::vector<double> ms;
      SceneSimulation sim(ps[k]);
      for (int f = 0; f < frames; ++f) {
        sim.advance(f);
        if (sim.contact_report().nodes == 0) continue;
        ms.push_back(sim.frame_step_ms());
        if (k == 1) {
          solves += sim.contact_report().solves;
          ++timed;
          if (!sim.contact_report().converged) ++r.unconverged;
        }
      }
      median[k] = quantile(ms, 0.5);
      all[k].insert(all[k].end(), ms.begin(), ms.end());
    }
    if (median[0] > 0) ratios.push_back(median[1] / median[0]);
  }
  r.nodes = ps[0].organ().model.n;
  r.pairs = int(ratios.size());
  r.kinematic_ms = quantile(all[0], 0.5);
  r.constraint_ms = quantile(all[1], 0.5);
  r.ratio = r.kinematic_ms > 0 ? r.constraint_ms / r.kinematic_ms : 0;
  r.pair_ratio_median = quantile(ratios, 0.5);
  r.pair_ratio_max = ratios.empty() ? 0 : *std::max_element(ratios.begin(), ratios.end());
  r.solves = timed ? double(solves) / double(timed) : 0;
  return r;
}

// The slope of log y against log x, least squares.
double loglog_slope(const std::vector<double>& x, const std::vector<double>& y) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = double(x.size());
  for (size_t i = 0; i < x.size(); ++i) {
    const double lx = std::log(x[i]), ly = std::log(y[i]);
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

// VDM's probe step on every mesh in turn, round after round in one process (a round runs the
// 60 frames on each mesh, smallest first), so that the scaling exponent compares runs made
// seconds apart: the isolated rows of bench.csv run minutes apart on a shared machine, and one
// busy minute moves their fit by 0.1. Every run is timed alike: its frames in contact after
// the 20th (an isolated row times those of its first run and every frame in contact of its
// later runs; the 40k row has one run).
struct ScalingInTurn {
  std::vector<double> nodes, median_ms;  // per mesh; medians of all rounds' timed frames
  std::vector<double> round_exponent;    // each round's fit of its own medians
  double exponent = 0;                   // the fit of median_ms
};

ScalingInTurn bench_scaling_in_turn(const std::vector<std::string>& meshes, int rounds) {
  std::vector<PreparedScene> scenes;
  scenes.reserve(meshes.size());  // (SceneSimulation keeps a reference)
  for (const std::string& mesh : meshes) scenes.push_back(probe_scene(mesh, 60, false));
  std::vector<std::vector<double>> all(meshes.size());
  ScalingInTurn r;
  for (const PreparedScene& ps : scenes) r.nodes.push_back(double(ps.organ().model.n));
  for (int round = 0; round < rounds; ++round) {
    std::vector<double> medians;
    for (size_t k = 0; k < scenes.size(); ++k) {
      std::vector<double> ms;
      SceneSimulation sim(scenes[k]);
      for (int f = 0; f < 60; ++f) {
        sim.advance(f);
        if (sim.contact_report().nodes > 0 && f > 20) ms.push_back(sim.frame_step_ms());
      }
      medians.push_back(quantile(ms, 0.5));
      all[k].insert(all[k].end(), ms.begin(), ms.end());
    }
    r.round_exponent.push_back(loglog_slope(r.nodes, medians));
  }
  for (const std::vector<double>& ms : all) r.median_ms.push_back(quantile(ms, 0.5));
  r.exponent = loglog_slope(r.nodes, r.median_ms);
  return r;
}

Row bench_grasp(int repeats) {
  Row r{"grasp_lift", "vdm"};
  PreparedScene ps;
  std::vector<SceneProblem> problems;
  const std::string path = (fs::path(data_dir()) / "scenes" / "grasp_lift.yaml").string();
  SceneLoadResult loaded = load_scene(path);
  if (!loaded.ok()) throw std::runtime_error(path + ": cannot load");
  on_paper_model(loaded.scene);
  if (!prepare_scene_def(loaded.scene, ps, problems)) throw std::runtime_error("cannot prepare grasp_lift.yaml");
  time_steps(ps, repeats, [](int rep, int f, const SceneSimulation&) { return rep > 0 || f >= 5; }, r);
  return r;
}

// The case's name for an anti-aliasing setting: the default (edge) unmarked, _msaa4x, _1x.
std::string aa_case(const std::string& base, render::Antialias aa, int samples) {
  if (aa == render::Antialias::edge) return base;
  if (aa == render::Antialias::none) return base + "_1x";
  return base + "_msaa" + std::to_string(samples) + "x";
}

// Rendering one 1280x720 frame with the HUD plus encoding it to PNG, serially.
Row bench_render(const fs::path& dir, int frames, render::Antialias aa, int samples) {
  Row r{aa_case("render_720p", aa, samples), "pipeline"};
  std::string error;
  PreparedScene ps = probe_scene("liver_L5.obj", frames + 40, true);
  SceneSimulation sim(ps);
  for (int f = 0; f < 40; ++f) sim.advance(f);  // the probe in the tissue
  render::RenderSettings settings = ps.scene.render.settings;
  settings.antialias = aa;
  settings.samples = samples;
  auto renderer = render::Renderer::create(settings, ps.organ().model.rest, error);
  if (!renderer) throw std::runtime_error(error);
  render::RenderScene scene;
  scene.positions = &sim.state().x;
  scene.hud.scene_name = "bench";
  for (size_t k = 0; k < ps.scene.instruments.size(); ++k)
    scene.instruments.push_back(render::instrument_view(ps.scene.instruments[k], sim.poses(sim.time())[k]));
  render::Image image;
  std::vector<double> times;
  for (int f = 0; f < frames + 2; ++f) {
    const auto t0 = Clock::now();
    renderer->draw_shaded(scene, true, image);
    if (!render::write_png((dir / "bench_frame.png").string(), image, ps.scene.render.png_compression, false, error))
      throw std::runtime_error(error);
    if (f >= 2) times.push_back(ms_since(t0));
  }
  fs::remove(dir / "bench_frame.png");
  r.nodes = ps.organ().model.n;
  r.median_ms = quantile(times, 0.5);
  r.p95_ms = quantile(times, 0.95);
  return r;
}

// The whole pipeline as `vdmsim run` does it: simulate, render 1280x720 with the HUD (edge
// anti-aliasing as by default, or `aa`), encode PNGs on the writer thread. The figures are the
// steady frame interval: the wall time between consecutive frames done (the render and PNG
// queues are bounded, so the loop runs at the pace of the slowest stage), the first
// `warm_up` frames (renderer start, shader compilation, queues filling) left out. The wall
// time per frame of the whole run (start and the final drain included) is printed.
Row bench_pipeline(const fs::path& dir, const std::string& mesh, int frames, render::Antialias aa, int samples,
                   std::ostream& out) {
  Row r{aa_case("pipeline_720p", aa, samples), "pipeline"};
  std::string error;
  PreparedScene ps = probe_scene(mesh, frames, true);
  ps.scene.render.settings.antialias = aa;
  ps.scene.render.settings.samples = samples;
  RunOptions opt;
  opt.out_dir = (dir / "pipeline_run").string();
  std::vector<double> done;
  opt.frame_done_ms = &done;
  std::ostringstream o, e;
  const auto t0 = Clock::now();
  if (run_scene(ps, opt, o, e, false) != 0) throw std::runtime_error("the pipeline run failed: " + e.str());
  const double whole = ms_since(t0) / frames;
  const size_t warm_up = std::min<size_t>(10, done.size() / 3);
  std::vector<double> intervals;
  for (size_t f = warm_up + 1; f < done.size(); ++f) intervals.push_back(done[f] - done[f - 1]);
  r.nodes = ps.organ().model.n;
  r.median_ms = quantile(intervals, 0.5);
  r.p95_ms = quantile(intervals, 0.95);
  out << " (whole run " << std::setprecision(4) << whole << " ms per frame)" << std::flush;
  std::error_code ec;
  fs::remove_all(dir / "pipeline_run", ec);
  return r;
}

// The elastic core (organ.model vdm_core, E 5 kPa, its default cell) on one instrument path
// into the 10k liver, run after run in turn: the tissue held on the instrument (kinematic
// contact: sticking), constraint contact with friction 0.2 (the default), 0 and 0.3; the steps
// from frame `first` on that touch the organ timed; and one 1280x720 frame drawn and encoded
// (render_720p's figure) in the same run, the frame the step is measured against. The paths:
// probe_poke's press and hold (frames 16 to 59), palpation_slide's slide across the lobe.
struct CoreSideBySide {
  static constexpr int kVariants = 5;
  static constexpr int kScenes = 4;  // the variants run as scenes; the last prescribes kinematic's held nodes
  const char* name[kVariants] = {"kinematic", "constraint friction 0.2", "constraint friction 0", "constraint friction 0.3",
                                 "prescribed (no contact)"};
  long nodes = 0;
  double cell_m = 0;
  int pairs = 0;
  double median_ms[kVariants] = {}, p95_ms[kVariants] = {}, iterations[kVariants] = {};
  int unconverged[kVariants] = {};
  double frame_ms = 0;
};

CoreSideBySide bench_core_side_by_side(const fs::path& dir, const std::string& scene, int frames, int first, int rounds) {
  // (a scene the bench wrote itself is given by its whole path)
  const std::string path = fs::path(scene).is_absolute() ? scene : (fs::path(data_dir()) / "scenes" / scene).string();
  SceneLoadResult loaded = load_scene(path);
  if (!loaded.ok()) throw std::runtime_error(path + ": cannot load");
  CoreSideBySide r;
  constexpr int kScenes = CoreSideBySide::kScenes;
  PreparedScene ps[kScenes];
  const double friction[kScenes] = {0, 0.2, 0, 0.3};
  for (int k = 0; k < kScenes; ++k) {
    SceneDef s = loaded.scene;
    s.frames = frames;
    s.has_render = false;
    s.render.remove(render::View::stress);
    s.effects.erase(std::remove(s.effects.begin(), s.effects.end(), Effect::stress), s.effects.end());
    s.organ().model = vdm::ModelKind::vdm_core;
    s.organ().young_modulus = 5000;
    s.organ().cell_size = 0;
    s.contact.method = k == 0 ? vdm::ContactSettings::Method::kinematic : vdm::ContactSettings::Method::constraint;
    s.contact.friction = friction[k];
    std::vector<SceneProblem> problems;
    if (!prepare_scene_def(s, ps[k], problems))
      throw std::runtime_error(problems.empty() ? "cannot prepare the core's scene " + scene : problems.back().text());
  }
  std::vector<double> all[CoreSideBySide::kVariants];
  long steps[CoreSideBySide::kVariants] = {};
  // What kinematic contact held at each frame (the entries with a reaction that the organ's
  // own fixed set does not hold) and where: the same press prescribed, with no contact.
  const vdm::core::CoreModel& core = ps[0].organ().reference.core;
  std::vector<vdm::FlagMat> held(static_cast<size_t>(frames));
  std::vector<vdm::NodeMat> held_u(static_cast<size_t>(frames));
  std::vector<char> sampled(static_cast<size_t>(frames), 0);
  for (int round = 0; round < rounds; ++round) {
    for (int k = 0; k < kScenes; ++k) {
      SceneSimulation sim(ps[k]);
      for (int f = 0; f < frames; ++f) {
        sim.advance(f);
        if (k == 0 && round == 0) {
          const vdm::SimState& st = sim.state();
          held[static_cast<size_t>(f)] = vdm::FlagMat::Zero(core.ns, 3);
          for (int i = 0; i < core.ns; ++i)
            for (int d = 0; d < 3; ++d)
              held[static_cast<size_t>(f)](i, d) = st.reaction(i, d) != 0.0 && !core.fixed(i, d);
          held_u[static_cast<size_t>(f)] = st.u;
        }
        if (f < first || sim.contact_report().nodes == 0) continue;
        if (k == 0) sampled[static_cast<size_t>(f)] = 1;
        all[k].push_back(sim.frame_step_ms());
        r.iterations[k] += sim.frame_iterations();
        ++steps[k];
        if (!sim.contact_report().converged) ++r.unconverged[k];
      }
    }
    // The prescribed press, frame by frame from rest as the scenes ran.
    const int k = kScenes;
    const std::unique_ptr<vdm::OrganSolver> solver = vdm::make_core_solver(core, ps[0].scene.dt);
    vdm::SimState st = vdm::make_sim_state(ps[0].organ().model);
    vdm::StepInput in = vdm::make_step_input(ps[0].organ().model);
    for (int f = 0; f < frames; ++f) {
      in.prescribed = held[static_cast<size_t>(f)];
      in.prescribed_u = held_u[static_cast<size_t>(f)];
      solver->step(in, st);
      if (!sampled[static_cast<size_t>(f)]) continue;
      all[k].push_back(st.stats.step_ms);
      r.iterations[k] += st.stats.iterations;
      ++steps[k];
      if (!st.stats.converged) ++r.unconverged[k];
    }
  }
  for (int k = 0; k < CoreSideBySide::kVariants; ++k) {
    r.median_ms[k] = quantile(all[k], 0.5);
    r.p95_ms[k] = quantile(all[k], 0.95);
    if (steps[k] > 0) r.iterations[k] /= double(steps[k]);
  }
  r.nodes = ps[0].organ().model.n;
  r.cell_m = ps[0].organ().reference.core.h;
  r.pairs = rounds;
  r.frame_ms = bench_render(dir, 20, render::Antialias::edge, 1).median_ms;
  return r;
}

}  // namespace

int cmd_bench(const std::string& out_dir, bool quick, std::ostream& out, std::ostream& err, const std::string& only,
              int case_fd, const std::string& shared_assets) {
  std::string error;
  if (!prepare_output_dir(out_dir, error)) {
    err << "vdmsim: error: " << error << "\n";
    return 2;
  }
  const fs::path dir(out_dir);
  const int repeats = quick ? 1 : 3;
  // Bullet right after VDM on the same mesh: the two see about the same machine load.
  std::vector<std::pair<std::string, std::function<Row()>>> cases;
  const bool bullet = bullet_available();
  if (bullet && case_fd < 0) out << "bench: Bullet " << describe(BulletSettings{}) << "\n";
  if (!bullet && case_fd < 0)
    out << "bench: liver_probe bullet: skipped (this build has no Bullet: install libbullet-dev and reconfigure)\n";
  cases.push_back({"liver_probe 2.5k", [&] { return bench_probe("liver_L4.obj", repeats); }});
  if (bullet) cases.push_back({"liver_probe bullet 2.5k", [&] { return bench_bullet("liver_L4.obj", repeats); }});
  cases.push_back({"liver_probe 10k", [&] { return bench_probe("liver_L5.obj", repeats); }});
  cases.push_back({"liver_probe paper capsule 10k",
                   [&] { return bench_probe("liver_L5.obj", repeats, vdm::CapsuleForm::paper); }});
  if (bullet) cases.push_back({"liver_probe bullet 10k", [&] { return bench_bullet("liver_L5.obj", repeats); }});
  if (!quick) cases.push_back({"liver_probe 40k", [&] { return bench_probe("liver_L6.obj", 1); }});
  cases.push_back({"liver_probe 642", [&] { return bench_probe_level3(dir, repeats); }});
  cases.push_back({"liver_probe fem 642", [&] { return bench_fem(dir, quick ? 26 : 60); }});
  cases.push_back({"grasp_lift", [&] { return bench_grasp(repeats); }});
  using render::Antialias;
  const int render_frames = quick ? 6 : 20, pipeline_frames = quick ? 30 : 90;
  cases.push_back({"render_720p", [&] { return bench_render(dir, render_frames, Antialias::edge, 1); }});
  cases.push_back({"render_720p_msaa4x", [&] { return bench_render(dir, render_frames, Antialias::msaa, 4); }});
  cases.push_back({"render_720p_1x", [&] { return bench_render(dir, render_frames, Antialias::none, 1); }});
  cases.push_back({"pipeline_720p 10k", [&] { return bench_pipeline(dir, "liver_L5.obj", pipeline_frames, Antialias::edge, 1, out); }});
  cases.push_back(
      {"pipeline_720p_msaa4x 10k", [&] { return bench_pipeline(dir, "liver_L5.obj", pipeline_frames, Antialias::msaa, 4, out); }});
  cases.push_back({"pipeline_720p_1x 10k", [&] { return bench_pipeline(dir, "liver_L5.obj", pipeline_frames, Antialias::none, 1, out); }});
  // 40k nodes with rendering: its peak memory (a few contact frames).
  cases.push_back({"pipeline_720p 40k", [&] { return bench_pipeline(dir, "liver_L6.obj", 24, Antialias::edge, 1, out); }});
  if (!quick)  // the same with 4x MSAA (the default before edge AA): where the memory case lands with it
    cases.push_back(
        {"pipeline_720p_msaa4x 40k", [&] { return bench_pipeline(dir, "liver_L6.obj", 24, Antialias::msaa, 4, out); }});

  if (case_fd >= 0) {  // the process of one case (run_isolated): its row to the pipe
    for (const auto& [label, body] : cases) {
      if (label != only) continue;
      Row r;
      try {
        r = body();
      } catch (const std::exception& e) {
        err << "vdmsim: bench: " << e.what() << "\n";
        return 1;
      }
      r.peak_mb = peak_mb();
      const std::string text = format_row(r);
      const ssize_t w = write(case_fd, text.data(), text.size());
      close(case_fd);
      return w == ssize_t(text.size()) ? 0 : 1;
    }
    err << "vdmsim: bench: no case " << only << "\n";
    return 1;
  }
  std::vector<Row> rows;
  for (const auto& [label, body] : cases) {
    if (!only.empty() && label.find(only) == std::string::npos) continue;
    Row row;
    out << "bench: " << label << " ..." << std::flush;
    if (!run_isolated(label, out_dir, quick, row, error)) {
      out << " failed\n";
      err << "vdmsim: error: " << label << ": " << error << "\n";
      return 1;
    }
    out << " median " << row.median_ms << " ms, p95 " << row.p95_ms << " ms, " << row.nodes << " nodes, peak "
        << std::lround(row.peak_mb) << " MB\n";
    rows.push_back(row);
  }
  std::ofstream csv(dir / "bench.csv");
  csv << "case,model,nodes,median_ms,p95_ms,iterations,volume_rel_error,peak_mb\n" << std::setprecision(6);
  for (const Row& r : rows)
    csv << r.name << ',' << r.model << ',' << r.nodes << ',' << r.median_ms << ',' << r.p95_ms << ',' << r.iterations
        << ',' << r.volume_rel_error << ',' << r.peak_mb << '\n';
  csv.flush();
  if (!csv) {
    err << "vdmsim: error: " << (dir / "bench.csv").string() << ": write failed\n";
    return 1;
  }
  // Side by side: Bullet's and FEM's time per step over VDM's on the same mesh.
  for (const Row& r : rows)
    for (const Row& v : rows)
      if (r.name == "liver_probe" && v.name == r.name && v.model == "vdm" && r.model != "vdm" && v.nodes == r.nodes &&
          v.median_ms > 0)
        out << "bench: liver_probe " << r.nodes << " nodes: " << r.model << " takes " << std::setprecision(3)
            << r.median_ms / v.median_ms << "x VDM's time per step\n";
  // Bullet and VDM run after run in turn (after the isolated cases: its memory is not theirs).
  if (bullet && (only.empty() || std::string("liver_probe side by side").find(only) != std::string::npos)) {
    std::ofstream sc(dir / "bench_side_by_side.csv");
    sc << "nodes,pairs,vdm_median_ms,bullet_median_ms,ratio,pair_ratio_median,pair_ratio_min,paper_median_ms,"
          "paper_ratio,paper_pair_ratio_median,paper_pair_ratio_max\n";
    for (const char* mesh : {"liver_L4.obj", "liver_L5.obj"}) {
      out << "bench: liver_probe side by side " << mesh << " ..." << std::flush;
      const SideBySide r = bench_side_by_side(mesh, quick ? 2 : 6);
      sc << r.nodes << ',' << r.pairs << ',' << std::setprecision(6) << r.vdm_ms << ',' << r.bullet_ms << ',' << r.ratio
         << ',' << r.pair_ratio_median << ',' << r.pair_ratio_min << ',' << r.paper_ms << ',' << r.paper_ratio << ','
         << r.paper_pair_ratio_median << ',' << r.paper_pair_ratio_max << '\n';
      out << " " << r.nodes << " nodes, runs in turn: bullet " << std::setprecision(3) << r.bullet_ms << " ms, vdm "
          << r.vdm_ms << " ms: bullet takes " << r.ratio << "x VDM's time per step (round by round: median "
          << r.pair_ratio_median << "x, lowest " << r.pair_ratio_min << "x, " << r.pairs << " rounds); the paper's capsule "
          << r.paper_ms << " ms: VDM takes " << r.paper_ratio << "x its time (round by round: median "
          << r.paper_pair_ratio_median << "x, highest " << r.paper_pair_ratio_max << "x)\n";
    }
    sc.flush();
    if (!sc) {
      err << "vdmsim: error: " << (dir / "bench_side_by_side.csv").string() << ": write failed\n";
      return 1;
    }
  }
  // Sliding with friction against sticking, run after run in turn.
  if (only.empty() || std::string("liver_slide side by side").find(only) != std::string::npos) {
    out << "bench: liver_slide side by side ..." << std::flush;
    const SlideSideBySide r = bench_slide_side_by_side(quick ? 1 : 3, quick ? 60 : 120);
    std::ofstream sc(dir / "bench_slide.csv");
    sc << "nodes,pairs,friction,kinematic_median_ms,constraint_median_ms,ratio,pair_ratio_median,pair_ratio_max,"
          "constraint_solves_per_step,constraint_unconverged_steps\n";
    sc << r.nodes << ',' << r.pairs << ',' << r.friction << ',' << std::setprecision(6) << r.kinematic_ms << ','
       << r.constraint_ms << ',' << r.ratio << ',' << r.pair_ratio_median << ',' << r.pair_ratio_max << ',' << r.solves
       << ',' << r.unconverged << '\n';
    sc.flush();
    if (!sc) {
      err << "vdmsim: error: " << (dir / "bench_slide.csv").string() << ": write failed\n";
      return 1;
    }
    out << " " << r.nodes << " nodes, runs in turn: constraint contact (friction " << r.friction << ") "
        << std::setprecision(3) << r.constraint_ms << " ms, kinematic " << r.kinematic_ms << " ms per step in contact: "
        << r.ratio << "x (pair by pair: median " << r.pair_ratio_median << "x, highest " << r.pair_ratio_max << "x, "
        << r.pairs << " pairs); " << r.solves << " solves per step, " << r.unconverged << " steps unconverged\n";
  }
  // The elastic core's press and slide, its contact methods in turn, against one frame drawn
  // and encoded.
  // The CT-like press: on SOFA's scanned liver when the shared assets are there.
  struct CorePath {
    const char* label;
    std::string scene;
    int frames, first;
    const char* file;
  };
  for (CorePath p : {CorePath{"core_probe side by side", "probe_poke.yaml", 60, 16, "bench_core_probe.csv"},
                     CorePath{"core_slide side by side", "palpation_slide.yaml", 121, 0, "bench_core_slide.csv"},
                     CorePath{"core_scanned_probe side by side", "", 40, 6, "bench_core_scanned_probe.csv"}}) {
    if (!only.empty() && std::string(p.label).find(only) == std::string::npos) continue;
    out << "bench: " << p.label << " ..." << std::flush;
    if (p.scene.empty()) {
      std::string why_not;
      p.scene = scanned_liver_press_scene(shared_assets, dir, why_not);
      if (p.scene.empty()) {
        out << " skipped: " << why_not << "\n";
        continue;
      }
    }
    const CoreSideBySide r = bench_core_side_by_side(dir, p.scene, p.frames, p.first, quick ? 1 : 3);
    const std::string file = p.file;
    std::ofstream sc(dir / file);
    sc << "nodes,cell_m,rounds,contact,median_ms,p95_ms,iterations,unconverged_steps,frame_720p_ms,median_over_frame,"
          "median_over_kinematic,p95_over_kinematic,median_over_prescribed,p95_over_prescribed\n";
    out << " " << r.nodes << " nodes, cell " << r.cell_m * 1e3 << " mm, " << r.pairs << " rounds; one 720p frame "
        << std::setprecision(3) << r.frame_ms << " ms\n";
    for (int k = 0; k < CoreSideBySide::kVariants; ++k) {
      const double base = r.median_ms[0] > 0 ? r.median_ms[0] : 1;
      const double prescribed = r.median_ms[CoreSideBySide::kScenes] > 0 ? r.median_ms[CoreSideBySide::kScenes] : 1;
      sc << r.nodes << ',' << r.cell_m << ',' << r.pairs << ',' << r.name[k] << ',' << std::setprecision(6)
         << r.median_ms[k] << ',' << r.p95_ms[k] << ',' << r.iterations[k] << ',' << r.unconverged[k] << ','
         << r.frame_ms << ',' << r.median_ms[k] / r.frame_ms << ',' << r.median_ms[k] / base << ','
         << r.p95_ms[k] / base << ',' << r.median_ms[k] / prescribed << ',' << r.p95_ms[k] / prescribed << '\n';
      out << "bench:   core " << r.name[k] << ": median " << std::setprecision(3) << r.median_ms[k] << " ms (p95 "
          << r.p95_ms[k] << "), " << r.median_ms[k] / r.frame_ms << "x a frame, " << r.median_ms[k] / base
          << "x kinematic (p95 " << r.p95_ms[k] / base << "x), " << r.median_ms[k] / prescribed << "x prescribed (p95 "
          << r.p95_ms[k] / prescribed << "x); " << r.iterations[k] << " iterations a step, " << r.unconverged[k]
          << " unconverged\n";
    }
    sc.flush();
    if (!sc) {
      err << "vdmsim: error: " << (dir / file).string() << ": write failed\n";
      return 1;
    }
  }
  // Two organs against each alone on the same script, in turn (quick: up to the first frames
  // of the grasp, which starts at frame 15).
  if (only.empty() || std::string("organs side by side").find(only) != std::string::npos) {
    out << "bench: organs side by side ..." << std::flush;
    const OrgansSideBySide r = bench_organs_side_by_side(quick ? 24 : 61, quick ? 1 : 3);
    std::ofstream sc(dir / "bench_organs.csv");
    sc << "frames,rounds,nodes_both,nodes_liver,nodes_gallbladder,both_ms,liver_ms,gallbladder_ms,both_iterations,"
          "liver_iterations,gallbladder_iterations,ratio,ratio_min,ratio_max,liver_replayed_ms,gallbladder_replayed_ms,"
          "liver_replayed_iterations,gallbladder_replayed_iterations,replayed_ratio,replayed_ratio_min,replayed_ratio_max,"
          "liver_iterations_together,gallbladder_iterations_together,per_iteration_ratio,per_iteration_ratio_min,"
          "per_iteration_ratio_max,both_unconverged,liver_unconverged,gallbladder_unconverged,liver_replayed_unconverged,"
          "gallbladder_replayed_unconverged,liver_replayed_apart_m,gallbladder_replayed_apart_m\n"
       << r.frames << ',' << r.rounds << ',' << r.nodes[0] << ',' << r.nodes[1] << ',' << r.nodes[2] << ','
       << std::setprecision(6) << r.total_ms[0] << ',' << r.total_ms[1] << ',' << r.total_ms[2] << ',' << r.iterations[0]
       << ',' << r.iterations[1] << ',' << r.iterations[2] << ',' << r.ratio << ',' << r.ratio_min << ',' << r.ratio_max
       << ',' << r.total_ms[3] << ',' << r.total_ms[4] << ',' << r.iterations[3] << ',' << r.iterations[4] << ','
       << r.replayed_ratio << ',' << r.replayed_ratio_min << ',' << r.replayed_ratio_max << ','
       << r.iterations_together[0] << ',' << r.iterations_together[1] << ',' << r.per_iteration_ratio << ','
       << r.per_iteration_ratio_min << ',' << r.per_iteration_ratio_max;
    for (long u : r.unconverged) sc << ',' << u;
    sc << ',' << r.replayed_apart_m[0] << ',' << r.replayed_apart_m[1] << '\n';
    sc.flush();
    if (!sc) {
      err << "vdmsim: error: " << (dir / "bench_organs.csv").string() << ": write failed\n";
      return 1;
    }
    out << " " << r.frames << " frames, " << r.rounds << " rounds in turn: both organs " << std::setprecision(3)
        << r.total_ms[0] / 1000 << " s (" << r.iterations[0] << " iterations), the liver alone " << r.total_ms[1] / 1000
        << " s (" << r.iterations[1] << "), the gallbladder alone " << r.total_ms[2] / 1000 << " s (" << r.iterations[2]
        << "): " << r.ratio << "x the sum of the organs alone (round by round " << r.ratio_min << "x to " << r.ratio_max
        << "x); each alone with the other following its recorded surface: the liver " << r.total_ms[3] / 1000 << " s (" << r.iterations[3]
        << "), the gallbladder " << r.total_ms[4] / 1000 << " s (" << r.iterations[4] << "): " << r.replayed_ratio
        << "x their sum (round by round " << r.replayed_ratio_min << "x to " << r.replayed_ratio_max
        << "x; their last surfaces " << r.replayed_apart_m[0] * 1e3 << " and " << r.replayed_apart_m[1] * 1e3
        << " mm from the two-organ run's); an iteration together over alone (the liver's " << r.iterations_together[0] << " and the gallbladder's "
        << r.iterations_together[1] << " iterations in the two-organ run, each at its cost alone with the other following): "
        << r.per_iteration_ratio << "x (round by round " << r.per_iteration_ratio_min << "x to "
        << r.per_iteration_ratio_max << "x); unconverged contact steps " << r.unconverged[0] << " / " << r.unconverged[1]
        << " / " << r.unconverged[2] << " / " << r.unconverged[3] << " / " << r.unconverged[4] << "\n";
  }
  // The endoscope's frame against the framing camera's, in turn, and its ground-truth views.
  if (only.empty() || std::string("endoscope_720p side by side").find(only) != std::string::npos) {
    out << "bench: endoscope_720p side by side ..." << std::flush;
    const EndoscopeFrameCost r = bench_endoscope_frame(dir, quick ? 6 : 20, quick ? 20 : 60);
    std::ofstream sc(dir / "bench_endoscope.csv");
    sc << "nodes,frames,framing_ms,endoscope_ms,ratio,pair_ratio_max,depth_ms,segmentation_ms,normals_ms\n";
    sc << r.nodes << ',' << r.frames << ',' << std::setprecision(6) << r.framing_ms << ',' << r.endoscope_ms << ','
       << r.ratio << ',' << r.pair_ratio_max << ',' << r.depth_ms << ',' << r.segmentation_ms << ',' << r.normals_ms
       << '\n';
    sc.flush();
    if (!sc) {
      err << "vdmsim: error: " << (dir / "bench_endoscope.csv").string() << ": write failed\n";
      return 1;
    }
    out << " " << r.nodes << " nodes, " << r.frames << " frames in turn: the endoscope's frame " << std::setprecision(3)
        << r.endoscope_ms << " ms, the framing camera's " << r.framing_ms << " ms (draw and encode): " << r.ratio
        << "x (frame by frame at most " << r.pair_ratio_max << "x); ground truth through the endoscope (draw and "
        << "read): depth " << r.depth_ms << " ms, segmentation " << r.segmentation_ms << " ms, normals "
        << r.normals_ms << " ms\n";
  }
  // The scaling exponent from VDM's probe on every size in turn (40k only in the full bench).
  if (only.empty() || std::string("liver_probe sizes in turn").find(only) != std::string::npos) {
    std::vector<std::string> meshes = {"liver_L4.obj", "liver_L5.obj"};
    if (!quick) meshes.push_back("liver_L6.obj");
    out << "bench: liver_probe sizes in turn ..." << std::flush;
    const ScalingInTurn r = bench_scaling_in_turn(meshes, quick ? 2 : 5);
    std::vector<double> sorted = r.round_exponent;
    std::sort(sorted.begin(), sorted.end());
    const double round_median = quantile(sorted, 0.5);
    std::ofstream st(dir / "bench_scaling.csv");
    st << "nodes,rounds,median_ms,exponent,round_exponent_median,round_exponent_min,round_exponent_max\n";
    for (size_t k = 0; k < r.nodes.size(); ++k)
      st << std::lround(r.nodes[k]) << ',' << r.round_exponent.size() << ',' << std::setprecision(6) << r.median_ms[k]
         << ',' << r.exponent << ',' << round_median << ',' << sorted.front() << ',' << sorted.back() << '\n';
    st.flush();
    if (!st) {
      err << "vdmsim: error: " << (dir / "bench_scaling.csv").string() << ": write failed\n";
      return 1;
    }
    out << " " << r.round_exponent.size() << " rounds, median ms";
    for (size_t k = 0; k < r.nodes.size(); ++k)
      out << (k ? " / " : " ") << std::setprecision(3) << r.median_ms[k] << " at " << std::lround(r.nodes[k]);
    out << " nodes: ms per step grows as nodes^" << std::setprecision(3) << r.exponent << " (rounds: median "
        << round_median << ", " << sorted.front() << " to " << sorted.back() << ")\n";
  }
  // The displacement error of the bench's solver tolerance, against a tight one.
  if (only.empty() || std::string("liver_probe tolerance").find(only) != std::string::npos) {
    constexpr double kReference = 1e-10;
    std::ofstream tc(dir / "bench_tolerance.csv");
    const double ref_volume = vdm::SolverSettings().volume_tolerance;
    tc << "nodes,tolerance,volume_tolerance,reference_tolerance,reference_volume_tolerance,max_error_mm,rms_error_mm\n";
    // Every mesh the probe cases time (40k only in the full bench).
    for (const char* mesh : {"liver_L4.obj", "liver_L5.obj", "liver_L6.obj"}) {
      if (quick && std::string(mesh) == "liver_L6.obj") continue;
      const ToleranceError e = bench_tolerance_error(mesh, kBenchTolerance, kReference);
      tc << e.nodes << ',' << kBenchTolerance << ',' << kBenchVolumeTolerance << ',' << kReference << ',' << ref_volume
         << ',' << std::setprecision(6) << e.max_m * 1e3 << ',' << e.rms_m * 1e3 << '\n';
      out << "bench: liver_probe " << e.nodes << " nodes at tolerance " << kBenchTolerance << " (volume "
          << kBenchVolumeTolerance << "): displacements within " << std::setprecision(3) << e.max_m * 1e3
          << " mm (max; RMS " << e.rms_m * 1e3 << " mm) of tolerance " << kReference << " (volume " << ref_volume
          << ")\n";
    }
    tc.flush();
    if (!tc) {
      err << "vdmsim: error: " << (dir / "bench_tolerance.csv").string() << ": write failed\n";
      return 1;
    }
  }
  // Scaling of the probe step with the node count: log-log fit and plot.
  render::Panel p;
  p.title = "Step with a probe in contact";
  p.x_label = "surface nodes";
  p.y_label = "median ms per step";
  p.log_x = p.log_y = true;
  for (const char* model : {"vdm", "bullet", "fem"}) {
    render::Series s;
    s.label = model;
    s.markers = true;
    for (const Row& r : rows)
      if (r.name == "liver_probe" && r.model == model) {
        s.x.push_back(double(r.nodes));
        s.y.push_back(r.median_ms);
      }
    if (s.x.empty()) continue;
    // Points in order of size (the 642-node row comes last in the table).
    std::vector<size_t> order(s.x.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&s](size_t a, size_t b) { return s.x[a] < s.x[b]; });
    const std::vector<double> x = s.x, y = s.y;
    for (size_t i = 0; i < order.size(); ++i) {
      s.x[i] = x[order[i]];
      s.y[i] = y[order[i]];
    }
    // The fit spans 2.5k nodes and up (the range; the 642-node row is FEM's organ).
    std::vector<size_t> fit;
    for (size_t i = 0; i < s.x.size(); ++i)
      if (s.x[i] >= 2000) fit.push_back(i);
    if (fit.size() >= 2) {
      std::vector<double> fx, fy;
      for (size_t i : fit) {
        fx.push_back(s.x[i]);
        fy.push_back(s.y[i]);
      }
      const double slope = loglog_slope(fx, fy);
      out << "scaling: " << model << " ms per step grows as nodes^" << std::setprecision(3) << slope
          << " (log-log fit over " << fit.size() << " sizes, 2.5k nodes and up)\n";
      s.label += " (nodes^" + render::format_number(slope, 3) + ")";
    }
    p.series.push_back(s);
  }
  render::Figure fig;
  fig.panels.push_back(p);
  if (!render::write_figure_png(fig, (dir / "scaling.png").string(), error)) {
    err << "vdmsim: error: " << error << "\n";
    return 1;
  }
  out << "bench: wrote " << (dir / "bench.csv").string() << " and " << (dir / "scaling.png").string() << "\n";
  return 0;
}

}  // namespace vdmsim
