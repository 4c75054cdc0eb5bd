#include "app/studies/bench_endoscope.hpp"

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/install/install_paths.hpp"
#include "app/run/instrument_focus.hpp"
#include "app/simulation/prepared_scene.hpp"
#include "app/simulation/scene_simulation.hpp"
#include "app/studies/quantile.hpp"
#include "engine/stopwatch.hpp"
#include "render/png_io.hpp"
#include "render/renderer.hpp"

namespace vdmsim {

namespace fs = std::filesystem;

EndoscopeFrameCost bench_endoscope_frame(const fs::path& dir, int frames, int simulated_frames) {
  const std::string path = (fs::path(data_dir()) / "scenes" / "lap_liver_retraction.yaml").string();
  PreparedScene ps;
  std::vector<SceneProblem> problems;
  if (!prepare_scene(path, ps, problems)) throw std::runtime_error(path + ": cannot prepare");
  SceneSimulation sim(ps);
  for (int f = 0; f < simulated_frames; ++f) sim.advance(f);

  const render::RenderSettings scope = framed_settings(ps);  // as `vdmsim run` draws it: with the ports
  render::RenderSettings framing = scope;
  framing.camera_type = render::CameraType::framing;
  framing.auto_camera = true;
  framing.floor = framing.shadows = true;
  std::string error;
  std::unique_ptr<render::Renderer> renderers[2] = {render::Renderer::create(framing, ps.organ().model.rest, error),
                                                    render::Renderer::create(scope, ps.organ().model.rest, error)};
  if (!renderers[0] || !renderers[1]) throw std::runtime_error(error);

  render::RenderScene scene;
  scene.positions = &sim.state().x;
  scene.hud.scene_name = ps.scene.name;
  const std::vector<tools::InstrumentPose> poses = sim.poses(sim.time());
  for (size_t k = 0; k < poses.size(); ++k) scene.instruments.push_back(render::instrument_view(ps.scene.instruments[k], poses[k]));
  const tools::EndoscopePose pose = tools::endoscope_at(ps.scene.render.settings.endoscope, sim.time());
  scene.camera_pose = pose.camera;
  scene.light_distance = (pose.look_at - pose.tip).norm();

  render::Image image;
  std::vector<double> times[2], ratios;
  const fs::path png = dir / "bench_endoscope_frame.png";
  for (int f = 0; f < frames + 2; ++f) {
    double ms[2];
    for (int k = 0; k < 2; ++k) {
      const auto t0 = vdm::Clock::now();
      if (!renderers[k]->draw_shaded(scene, true, image)) throw std::runtime_error(renderers[k]->error());
      if (!render::write_png(png.string(), image, ps.scene.render.png_compression, false, error))
        throw std::runtime_error(error);
      ms[k] = vdm::ms_since(t0);
    }
    if (f < 2) continue;  // warming up
    times[0].push_back(ms[0]);
    times[1].push_back(ms[1]);
    ratios.push_back(ms[1] / ms[0]);
  }
  fs::remove(png);

  EndoscopeFrameCost r;
  r.nodes = ps.organ().model.n;
  r.frames = frames;
  r.framing_ms = quantile(times[0], 0.5);
  r.endoscope_ms = quantile(times[1], 0.5);
  r.ratio = r.endoscope_ms / r.framing_ms;
  r.pair_ratio_max = *std::max_element(ratios.begin(), ratios.end());
  // Each ground-truth view alone: its pass drawn and the view read back.
  double* view_ms[3] = {&r.depth_ms, &r.segmentation_ms, &r.normals_ms};
  const render::View views[3] = {render::View::depth, render::View::segmentation, render::View::normals};
  for (int v = 0; v < 3; ++v) {
    std::vector<double> t;
    for (int f = 0; f < frames + 2; ++f) {
      const auto t0 = vdm::Clock::now();
      if (!renderers[1]->draw_views(scene, {views[v]}, render::ViewOptions{},
                                    [](render::View, render::ViewImage&) { return true; }))
        throw std::runtime_error(renderers[1]->error());
      if (f >= 2) t.push_back(vdm::ms_since(t0));
    }
    *view_ms[v] = quantile(t, 0.5);
  }
  return r;
}

}  // namespace vdmsim
