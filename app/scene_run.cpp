#include "app/scene_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <memory>
#include <sstream>

#include "app/commands.hpp"
#include "app/mesh_io.hpp"
#include "engine/contact.hpp"
#include "engine/sim_state.hpp"
#include "tools_scripted/grasp.hpp"

namespace vdmsim {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

double ramp(double t, double t0, double t1) {
  if (t1 <= t0) return t >= t0 ? 1.0 : 0.0;
  return std::clamp((t - t0) / (t1 - t0), 0.0, 1.0);
}

Eigen::Matrix3d rotation_deg(const vdm::Vec3& deg) {
  const double k = 3.14159265358979323846 / 180.0;
  return (Eigen::AngleAxisd(deg.z() * k, vdm::Vec3::UnitZ()) * Eigen::AngleAxisd(deg.y() * k, vdm::Vec3::UnitY()) *
          Eigen::AngleAxisd(deg.x() * k, vdm::Vec3::UnitX()))
      .toRotationMatrix();
}

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

std::vector<int> select_nodes(const Region& region, const vdm::NodeMat& rest, const std::string& field,
                              std::vector<SceneProblem>& problems) {
  std::vector<int> out;
  const int n = static_cast<int>(rest.rows());
  switch (region.kind) {
    case Region::Kind::all:
      for (int i = 0; i < n; ++i) out.push_back(i);
      break;
    case Region::Kind::nodes:
      for (int i : region.nodes) {
        if (i >= n) {
          problems.push_back({region.where, field + ".nodes",
                              "node " + std::to_string(i) + " does not exist (the mesh has " + std::to_string(n) + " nodes)",
                              false});
          continue;
        }
        out.push_back(i);
      }
      break;
    case Region::Kind::box:
      for (int i = 0; i < n; ++i) {
        const vdm::Vec3 x = rest.row(i);
        if ((x - region.min).minCoeff() >= 0 && (region.max - x).minCoeff() >= 0) out.push_back(i);
      }
      break;
    case Region::Kind::sphere:
      for (int i = 0; i < n; ++i)
        if ((rest.row(i).transpose() - region.center).norm() <= region.radius) out.push_back(i);
      break;
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  if (out.empty() && region.kind != Region::Kind::nodes) {
    const vdm::Vec3 lo = rest.colwise().minCoeff(), hi = rest.colwise().maxCoeff();
    std::ostringstream m;
    m << "the region selects no node of the organ (the organ spans [" << lo.x() << ", " << lo.y() << ", " << lo.z()
      << "] to [" << hi.x() << ", " << hi.y() << ", " << hi.z() << "] m after scale)";
    problems.push_back({region.where, field, m.str(), false});
  }
  return out;
}

bool prepare_scene(const std::string& path, PreparedScene& out, std::vector<SceneProblem>& problems) {
  SceneLoadResult loaded = load_scene(path);
  problems = loaded.problems;
  if (!loaded.ok()) return false;
  out.scene = loaded.scene;
  const SceneDef& s = out.scene;

  MeshLoadOptions mopt;
  mopt.scale = s.scale;
  const MeshLoadResult mesh = load_surface_mesh(s.mesh_path, mopt);
  if (!mesh.ok) {
    problems.push_back({s.file, "organ.mesh", mesh.error, false});
    return false;
  }
  vdm::TissueDef def = vdm::default_tissue(mesh.mesh);
  const int n = def.mesh.node_count();
  def.bulk_modulus = vdm::NodeMat(n, 3);
  for (int d = 0; d < 3; ++d) def.bulk_modulus.col(d).setConstant(s.bulk_modulus[d]);
  def.connectivity_modulus = s.connectivity_modulus;
  def.density = s.density;
  def.dt = s.dt;
  def.gravity = s.gravity;
  def.use_gravity = s.has(Effect::gravity);
  def.use_inertia = s.has(Effect::inertia);
  def.compute_stress = s.has(Effect::stress);
  def.damping = s.damping;
  def.volume_constraint = s.volume_constraint;
  if (s.model != "vdm") def.compute_stress = false;  // fem and mass_spring report no VDM stress
  def.solver = s.solver;
  def.fixed = vdm::FlagMat::Zero(n, 3);
  for (size_t k = 0; k < s.fixed.size(); ++k)
    for (int i : select_nodes(s.fixed[k].region, def.mesh.positions, "organ.fixed[" + std::to_string(k) + "]", problems))
      for (int d = 0; d < 3; ++d)
        if (s.fixed[k].axes[d]) def.fixed(i, d) = 1;
  for (size_t k = 0; k < s.loads.size(); ++k)
    out.load_nodes.push_back(select_nodes(s.loads[k].region, def.mesh.positions, "organ.loads[" + std::to_string(k) + "]", problems));
  for (size_t k = 0; k < s.prescribed.size(); ++k) {
    const auto nodes =
        select_nodes(s.prescribed[k].region, def.mesh.positions, "organ.prescribed[" + std::to_string(k) + "]", problems);
    vdm::Vec3 c = vdm::Vec3::Zero();
    for (int i : nodes) c += def.mesh.positions.row(i).transpose() / double(nodes.size());
    out.prescribed_about.push_back(s.prescribed[k].about.value_or(c));
    out.prescribed_nodes.push_back(nodes);
  }
  if (std::any_of(problems.begin(), problems.end(), [](const SceneProblem& p) { return !p.warning; })) return false;
  std::string error;
  if (!vdm::build_tissue_model(def, out.model, error)) {
    problems.push_back({s.file, "organ", error, false});
    return false;
  }
  if (!make_organ_solver(s, out.model, out.organ, error)) {
    problems.push_back({s.file, "organ.model", error, false});
    return false;
  }
  return true;
}

int run_scene(PreparedScene& ps, const RunOptions& opt, std::ostream& out, std::ostream& err, bool terminal) {
  namespace fs = std::filesystem;
  const SceneDef& s = ps.scene;
  const vdm::TissueModel& m = ps.model;
  const int frames = opt.frames > 0 ? opt.frames : s.frames;
  const fs::path dir = opt.out_dir.empty() ? fs::path("out") / s.name : fs::path(opt.out_dir);
  std::string error;
  if (!prepare_output_dir(dir.string(), error)) {
    err << "vdmsim: error: " << error << "\n";
    return 2;
  }
  // Contact runs only when listed, against probes; grasping only when listed, by graspers.
  std::vector<const InstrumentDef*> probes, graspers;
  for (const InstrumentDef& in : s.instruments)
    (in.type == InstrumentDef::Type::probe ? probes : graspers).push_back(&in);
  if (!probes.empty() && !s.has(Effect::contact))
    err << "vdmsim: note: the scene has probes but does not list the contact effect: they pass through the organ\n";
  if (!graspers.empty() && !s.has(Effect::grasp))
    err << "vdmsim: note: the scene has graspers but does not list the grasp effect: they hold nothing\n";
  std::vector<tools::Grasp> grasps(s.has(Effect::grasp) ? graspers.size() : 0);
  double grasp_ms = 0;
  std::unique_ptr<vdm::ContactSolver> contact;
  if (s.has(Effect::contact) && !probes.empty()) contact = std::make_unique<vdm::ContactSolver>(m);
  if (contact) contact->set_solver(ps.organ.get());
  std::vector<vdm::Capsule> capsules(probes.size());
  vdm::ContactReport report;
  double collision_ms = 0;
  long queries = 0;
  if (opt.render && s.has_render)
    err << "vdmsim: warning: the renderer is not built yet: no frames are written (metrics only)\n";

  std::ofstream metrics(dir / "metrics.csv");
  if (!metrics) {
    err << "vdmsim: error: " << (dir / "metrics.csv").string() << ": cannot open for writing\n";
    return 2;
  }
  metrics << "frame,time_s,step_ms,iterations,residual,volume,volume_rel_error,pressure_pa,contact_nodes,"
             "contact_force_n,max_penetration_m,max_displacement_m,max_stress_pa\n";
  metrics << std::setprecision(9);

  vdm::SimState state = vdm::make_sim_state(m);
  vdm::StepInput input = vdm::make_step_input(m);
  const auto t_run = Clock::now();
  double loads_ms = 0, assemble_ms = 0, solve_ms = 0, stress_ms = 0, io_ms = 0;
  double sum_step = 0, max_step = 0, max_vol = 0;
  std::vector<double> step_times;
  step_times.reserve(static_cast<size_t>(frames));
  std::string status = "completed", reason;
  int done = 0;
  int last_pct = -1;
  for (int f = 0; f < frames; ++f) {
    const double t = (f + 1) * s.dt;
    // Scripted loads and motions for this frame.
    const auto t_loads = Clock::now();
    input.force.setZero();
    input.prescribed.setZero();
    for (size_t k = 0; k < s.loads.size(); ++k) {
      const auto& nodes = ps.load_nodes[k];
      const vdm::Vec3 per_node = ramp(t, s.loads[k].t0, s.loads[k].t1) * s.loads[k].force / double(nodes.size());
      for (int i : nodes) input.force.row(i) += per_node.transpose();
    }
    for (size_t k = 0; k < s.prescribed.size(); ++k) {
      const PrescribedDef& p = s.prescribed[k];
      const double a = ramp(t, p.t0, p.t1);
      const Eigen::Matrix3d R = rotation_deg(a * p.rotate_deg);
      const vdm::Vec3 c = ps.prescribed_about[k];
      for (int i : ps.prescribed_nodes[k]) {
        const vdm::Vec3 X = m.rest.positions.row(i);
        input.prescribed.row(i).setOnes();
        input.prescribed_u.row(i) = (R * (X - c) + c + a * p.translate - X).transpose();
      }
    }
    loads_ms += ms_since(t_loads);
    const auto t_grasp = Clock::now();
    for (size_t k = 0; k < grasps.size(); ++k) {
      const tools::InstrumentPose pose = tools::pose_at(*graspers[k], t);
      grasps[k].update(*graspers[k], pose, state.x);
      grasps[k].apply(pose, m.rest.positions, input);
    }
    if (!grasps.empty()) grasp_ms += ms_since(t_grasp);

    double frame_step_ms = 0;
    int frame_iterations = 0;
    if (contact) {
      // Sub-step when a probe moves more than its radius in a frame, so it cannot tunnel.
      double substeps = 1;
      for (const InstrumentDef* p : probes) {
        const double move = (tools::pose_at(*p, t).tip - tools::pose_at(*p, t - s.dt).tip).norm();
        substeps = std::max(substeps, std::ceil(move / p->radius));
      }
      const int n_sub = static_cast<int>(std::min(substeps, 1000.0));
      for (int j = 1; j <= n_sub; ++j) {
        const double tj = t - s.dt + s.dt * j / n_sub, tprev = t - s.dt + s.dt * (j - 1) / n_sub;
        for (size_t k = 0; k < probes.size(); ++k) {
          capsules[k] = tools::probe_capsule(*probes[k], tools::pose_at(*probes[k], tj));
          capsules[k].motion = tools::pose_at(*probes[k], tj).tip - tools::pose_at(*probes[k], tprev).tip;
        }
        const auto t_contact = Clock::now();
        contact->step(m, input, capsules, state, report);
        frame_step_ms += ms_since(t_contact);
        frame_iterations += state.stats.iterations;
        collision_ms += report.collision_ms;
        queries += report.queries;
      }
    } else {
      if (ps.organ) ps.organ->step(input, state);  // organ.model fem or mass_spring
      else vdm::step(m, input, state);
      frame_step_ms = state.stats.step_ms;
      frame_iterations = state.stats.iterations;
    }
    const vdm::StepStats& st = state.stats;
    assemble_ms += st.assemble_ms;
    solve_ms += st.solve_ms;
    stress_ms += st.stress_ms;
    if (!state.u.allFinite()) {
      status = "failed";
      reason = "non-finite displacement at frame " + std::to_string(f);
      break;
    }
    const auto t_io = Clock::now();
    sum_step += frame_step_ms;
    max_step = std::max(max_step, frame_step_ms);
    step_times.push_back(frame_step_ms);
    max_vol = std::max(max_vol, std::abs(state.volume_rel_error));
    metrics << f << ',' << t << ',' << frame_step_ms << ',' << frame_iterations << ',' << st.residual << ','
            << state.volume << ',' << state.volume_rel_error << ',' << state.pressure << ',';
    if (contact)
      metrics << report.nodes << ',' << report.force.norm() << ',' << report.max_penetration << ',';
    else
      metrics << ",,,";  // the contact effect is not simulated: its columns stay empty
    metrics << state.u.rowwise().norm().maxCoeff() << ',';
    if (m.compute_stress) metrics << state.stress.rowwise().norm().maxCoeff();
    metrics << '\n';
    if (!metrics) {
      status = "failed";
      reason = "writing metrics.csv failed (disk full?)";
      break;
    }
    io_ms += ms_since(t_io);
    done = f + 1;
    const int pct = 100 * done / frames;
    if (terminal) {
      if (pct != last_pct) {
        const int w = 30, fill = w * done / frames;
        err << "\r[" << std::string(fill, '#') << std::string(w - fill, '.') << "] " << std::setw(3) << pct << "%  frame "
            << done << "/" << frames << std::flush;
      }
    } else if (pct / 10 != last_pct / 10 || done == frames) {
      err << "frame " << done << "/" << frames << " (" << pct << "%)\n";
    }
    last_pct = pct;
  }
  if (terminal) err << "\n";
  metrics.flush();
  const double wall = ms_since(t_run) / 1000.0;

  std::vector<double> sorted = step_times;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted.empty() ? 0.0 : sorted[sorted.size() / 2];
  std::ostringstream js;
  js << std::setprecision(9);
  js << "{\n  \"scene\": \"" << json_escape(s.name) << "\",\n  \"scene_file\": \"" << json_escape(s.file)
     << "\",\n  \"status\": \"" << status << "\",\n";
  if (!reason.empty()) js << "  \"reason\": \"" << json_escape(reason) << "\",\n";
  js << "  \"frames\": " << done << ",\n  \"frames_requested\": " << frames << ",\n  \"nodes\": " << m.n
     << ",\n  \"model\": \"" << s.model << "\",\n  \"solver\": \"" << vdm::to_string(m.solver.method)
     << "\",\n  \"effects\": [";
  for (size_t i = 0; i < s.effects.size(); ++i) js << (i ? ", " : "") << '"' << to_string(s.effects[i]) << '"';
  js << "],\n  \"wall_time_s\": " << wall << ",\n  \"mean_step_ms\": " << (done ? sum_step / done : 0.0)
     << ",\n  \"median_step_ms\": " << median << ",\n  \"max_step_ms\": " << max_step
     << ",\n  \"max_volume_rel_error\": " << max_vol << ",\n  \"stage_ms\": {\"loads\": " << loads_ms
     << ", \"assemble\": " << assemble_ms << ", \"solve\": " << solve_ms << ", \"stress\": " << stress_ms
     << ", \"grasp\": " << grasp_ms << ", \"collision\": " << collision_ms << ", \"metrics_io\": " << io_ms << "},\n  \"collision_queries\": "
     << queries << ",\n  \"warnings\": [";
  for (size_t i = 0; i < state.warnings.size(); ++i) js << (i ? ", " : "") << '"' << json_escape(state.warnings[i]) << '"';
  js << "]\n}\n";
  if (!write_run_json(dir / "run.json", js.str(), error)) {
    err << "vdmsim: error: " << error << "\n";
    return 1;
  }
  out << s.name << ": " << done << " frames, " << m.n << " nodes, median step " << median << " ms, max |volume error| "
      << max_vol << ", status " << status << " -> " << dir.string() << "\n";
  return status == "completed" ? 0 : 1;
}

}  // namespace vdmsim
