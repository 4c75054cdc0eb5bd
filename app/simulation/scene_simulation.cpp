#include "app/simulation/scene_simulation.hpp"

#include "app/simulation/organ_models.hpp"
#include "app/simulation/tool_depth.hpp"
#include "engine/state_snapshot.hpp"
#include "engine/stopwatch.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>

namespace vdmsim {
namespace {

using vdm::Clock;
using vdm::ms_since;

double ramp(double t, double t0, double t1) {
  if (t1 <= t0) return t >= t0 ? 1.0 : 0.0;
  return std::clamp((t - t0) / (t1 - t0), 0.0, 1.0);
}

}  // namespace

SceneSimulation::SceneSimulation(const PreparedScene& ps)
    : ps_(ps), state_(vdm::make_sim_state(ps.model)), input_(vdm::make_step_input(ps.model)) {
  const SceneDef& s = ps.scene;
  // Contact runs only when listed, against probes and graspers' jaws; grasping only when
  // listed, by graspers.
  for (size_t k = 0; k < s.instruments.size(); ++k) {
    const bool probe = s.instruments[k].type == tools::InstrumentDef::Type::probe;
    (probe ? probes_ : graspers_).push_back(&s.instruments[k]);
    (probe ? probe_index_ : grasper_index_).push_back(k);
  }
  instrument_force_.assign(s.instruments.size(), vdm::Vec3::Zero());
  const vdm::NodeMat& X = ps.model.rest.positions;
  organ_size_ = (X.colwise().maxCoeff() - X.colwise().minCoeff()).norm();
  holder_.assign(static_cast<size_t>(ps.model.n), -1);
  peak_force_.assign(s.instruments.size(), 0.0);
  if (s.has(Effect::grasp)) grasps_.resize(graspers_.size());
  // External forces only when the scene has loads: an empty force is none (1 MB at 40k nodes).
  if (s.loads.empty()) input_.force.resize(0, 3);
  // A reference model keeps its own state: every simulation (a colour-range pass, the run, a
  // benchmark repeat) builds its own, so that none starts where another ended.
  organ_ = make_organ_solver(ps.reference);
  if (s.has(Effect::contact) && !s.instruments.empty()) contact_ = std::make_unique<vdm::ContactSolver>(ps.model, s.contact);
  if (contact_) contact_->set_solver(organ_.get());  // organ.model's solver (null: vdm)
  tools_.resize(probes_.size() + 3 * graspers_.size());  // probes, then each grasper's two jaws and shaft
}

std::string SceneSimulation::unsound() const {
  const vdm::SimState& st = state_;
  if (!st.u.allFinite()) return "non-finite displacement";
  if (!std::isfinite(st.volume) || !std::isfinite(st.volume_rel_error)) return "non-finite volume";
  if (!std::isfinite(st.pressure)) return "non-finite pressure";
  if (!std::isfinite(st.stats.residual)) return "non-finite solver residual";
  if (ps_.scene.has(Effect::stress) && !st.stress.allFinite()) return "non-finite stress";
  if (st.reaction.size() > 0 && !st.reaction.allFinite()) return "non-finite reaction forces";
  if (!total_force().allFinite()) return "non-finite instrument force";
  const double size = organ_size_;
  const double moved = st.u.rowwise().norm().maxCoeff();
  if (moved > 2 * size) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "a node moved %.3g m, more than twice the organ's size (%.3g m): the material or the loads are out of "
                  "range",
                  moved, size);
    return text;
  }
  if (!conflict_.empty()) return conflict_;
  return deep_probe();
}

void SceneSimulation::note_hold(int node, int holder, const vdm::Vec3& before, const vdm::Vec3& after) {
  const int earlier = holder_[static_cast<size_t>(node)];
  holder_[static_cast<size_t>(node)] = holder;
  if (earlier == -1) return;
  // Apart by more than 5 % of the organ's size: not two holds of one piece of tissue moving
  // together, but the tissue torn between them.
  const double gap = (after - before).norm();
  if (!(gap > 0.05 * organ_size_) || gap <= conflict_gap_) return;
  conflict_gap_ = gap;
  const auto name = [](int h) {
    return h >= 0 ? "instruments[" + std::to_string(h) + "]" : "organ.prescribed[" + std::to_string(-2 - h) + "]";
  };
  char gap_text[32];
  std::snprintf(gap_text, sizeof gap_text, "%.3g", gap);
  conflict_ = "node " + std::to_string(node) + " is held by both " + name(earlier) + " and " + name(holder) +
              ", which move it to places " + gap_text +
              " m apart: they pull the same tissue against each other (the model cannot tear tissue)";
}

// Why contact could not push the organ away from instruments[k], in the terms of the scene: a
// probe far thinner than the organ's triangles slips between its nodes; a material far softer
// than any tissue gives no force; else the organ is rigid or held where the probe presses.
std::string SceneSimulation::deep_probe_cause(size_t probe) const {
  const SceneDef& s = ps_.scene;
  const vdm::SurfaceMesh& rest = ps_.model.rest;
  double edges = 0;
  for (Eigen::Index f = 0; f < rest.triangles.rows(); ++f)
    edges += (rest.positions.row(rest.triangles(f, 0)) - rest.positions.row(rest.triangles(f, 1))).norm();
  const double mean_edge = rest.triangles.rows() ? edges / double(rest.triangles.rows()) : 0;
  const double width = 2 * tools::instrument_size(*probes_[probe]);
  char text[400];
  if (width < 0.1 * mean_edge) {
    std::snprintf(text, sizeof text,
                  "it is %.3g m across, far thinner than the organ's triangles (edges of %.3g m on average): it slips "
                  "between the nodes; give it a radius of at least %.3g m, or a finer organ mesh",
                  width, mean_edge, 0.05 * mean_edge);
    return text;
  }
  // The stiffness contact pushes against (Pa): VDM's moduli for a model given by them, else E.
  const bool vdm_moduli = organ_model(s.model).vdm_moduli;
  const double stiffness = vdm_moduli ? std::min(s.bulk_modulus.minCoeff(), s.connectivity_modulus) : s.young_modulus;
  if (stiffness < 1.0) {
    std::snprintf(text, sizeof text,
                  "the organ's material (%s %.3g Pa) is far softer than any tissue (100 Pa to 100 kPa): nothing "
                  "pushes back",
                  vdm_moduli ? "modulus" : "young_modulus", stiffness);
    return text;
  }
  return "contact could not push the organ away (is it rigid, bulk_modulus inf, or held in place where the probe "
         "presses?)";
}

// A probe's tip deeper inside the organ than 1 cm and twice the probe's size: the force it
// reports is not the tissue's (deep_probe_cause says why it got there).
std::string SceneSimulation::deep_probe() const {
  if (!contact_simulated()) return "";
  for (size_t k = 0; k < probes_.size(); ++k) {
    const vdm::Vec3 tip = tools::pose_at(*probes_[k], time_).tip;
    const double limit = std::max(0.01, 2 * tools::instrument_size(*probes_[k]));
    if (deeper_inside(state_.x, ps_.model.rest.triangles, tip, limit)) {
      const double depth = depth_inside(state_.x, ps_.model.rest.triangles, tip);
      char text[120];
      std::snprintf(text, sizeof text, "instruments[%zu]'s tip is %.3g m inside the organ (more than %.3g m): ",
                    probe_index_[k], depth, limit);
      return text + deep_probe_cause(k) + ", and its force would be wrong";
    }
  }
  return "";
}

vdm::Vec3 SceneSimulation::total_force() const {
  vdm::Vec3 sum = vdm::Vec3::Zero();
  for (const vdm::Vec3& f : instrument_force_) sum += f;
  return sum;
}

void SceneSimulation::measure_forces() {
  if (!forces_simulated()) return;
  const std::vector<vdm::Vec3>* contact = contact_ ? &contact_->tool_forces() : nullptr;
  auto tool = [&](size_t k) { return contact && k < contact->size() ? (*contact)[k] : vdm::Vec3::Zero(); };
  for (size_t k = 0; k < probes_.size(); ++k) instrument_force_[probe_index_[k]] = tool(k);
  for (size_t k = 0; k < graspers_.size(); ++k) {
    const size_t jaws = probes_.size() + 3 * k;
    vdm::Vec3 f = tool(jaws) + tool(jaws + 1) + tool(jaws + 2);
    // The grasped nodes follow the jaws as prescribed motion: the organ pulls the jaws with
    // minus their reactions.
    if (k < grasps_.size())
      for (int i : grasps_[k].held()) f -= state_.reaction.row(i).transpose();
    instrument_force_[grasper_index_[k]] = f;
  }
  for (size_t k = 0; k < instrument_force_.size(); ++k)
    peak_force_[k] = std::max(peak_force_[k], instrument_force_[k].norm());
}

std::vector<tools::InstrumentPose> SceneSimulation::poses(double t) const {
  std::vector<tools::InstrumentPose> out;
  for (const tools::InstrumentDef& in : ps_.scene.instruments) out.push_back(tools::pose_at(in, t));
  return out;
}

bool SceneSimulation::save(std::string& out) const {
  // The organ model's own state first (vdm_core's; a reference model saves none: false).
  if (organ_ && !organ_->save_state(out)) return false;
  vdm::save_state(ps_.model, state_, out);
  const std::int64_t grasps = static_cast<std::int64_t>(grasps_.size());
  out.append(reinterpret_cast<const char*>(&grasps), sizeof grasps);
  for (const tools::Grasp& g : grasps_) g.save(out);
  // The run's force and contact tallies, so that a resumed run reports the whole run's.
  out.append(reinterpret_cast<const char*>(peak_force_.data()), sizeof(double) * peak_force_.size());
  const std::int64_t counts[2] = {unconverged_steps_, contact_iterations_};
  out.append(reinterpret_cast<const char*>(counts), sizeof counts);
  if (contact_) contact_->save_state(out);
  return true;
}

bool SceneSimulation::load(std::string_view in, std::string& error) {
  size_t pos = 0;
  if (organ_ && !organ_->load_state(in, pos, error)) return false;
  if (!vdm::load_state(ps_.model, in, pos, state_, error)) return false;
  std::int64_t grasps = -1;
  if (in.size() - pos >= sizeof grasps) std::memcpy(&grasps, in.data() + pos, sizeof grasps);
  pos += sizeof grasps;
  if (grasps != static_cast<std::int64_t>(grasps_.size())) {
    error = "state snapshot: of a scene with other graspers";
    return false;
  }
  for (tools::Grasp& g : grasps_)
    if (!g.load(in, pos, ps_.model.n)) {
      error = "state snapshot: a grasp is truncated";
      return false;
    }
  std::int64_t counts[2] = {0, 0};
  const size_t tallies = sizeof(double) * peak_force_.size() + sizeof counts;
  if (in.size() - pos < tallies) {
    error = "state snapshot: the force tallies are truncated";
    return false;
  }
  std::memcpy(peak_force_.data(), in.data() + pos, sizeof(double) * peak_force_.size());
  pos += sizeof(double) * peak_force_.size();
  std::memcpy(counts, in.data() + pos, sizeof counts);
  pos += sizeof counts;
  unconverged_steps_ = counts[0];
  contact_iterations_ = counts[1];
  if (contact_ && !contact_->load_state(in, pos, ps_.model.n, ps_.model.rest.triangle_count(), error)) return false;
  if (pos != in.size()) {
    error = "state snapshot: bytes after the end";
    return false;
  }
  return true;
}

void SceneSimulation::advance(int f) {
  const SceneDef& s = ps_.scene;
  const vdm::TissueModel& m = ps_.model;
  const double t = frame_time(f, s.dt);
  // Where the instruments were at the start of this frame's step: frame 0's step (a settle at
  // t = 0) does not move them.
  const double t_start = f == 0 ? t : frame_time(f - 1, s.dt);
  time_ = t;
  // With inertia the state at t = 0 is the initial condition, the organ at rest: a step here
  // would integrate the motion over a whole dt and label it t = 0.
  frame_stepped_ = !(f == 0 && m.use_inertia);
  // Scripted loads and motions for this frame.
  const auto t_loads = Clock::now();
  input_.force.setZero();
  input_.prescribed.setZero();
  for (size_t k = 0; k < s.loads.size(); ++k) {
    const auto& nodes = ps_.load_nodes[k];
    const vdm::Vec3 per_node = ramp(t, s.loads[k].t0, s.loads[k].t1) * s.loads[k].force / double(nodes.size());
    for (int i : nodes) input_.force.row(i) += per_node.transpose();
  }
  // Every hold of a node (organ.prescribed, a grasp) is noted: two that move one node to
  // places far apart pull the tissue against each other (unsound()).
  std::fill(holder_.begin(), holder_.end(), -1);
  conflict_.clear();
  conflict_gap_ = 0;
  for (size_t k = 0; k < s.prescribed.size(); ++k) {
    const PrescribedDef& p = s.prescribed[k];
    const double a = ramp(t, p.t0, p.t1);
    const Eigen::Matrix3d R = rotation_from_degrees(a * p.rotate_deg);
    const vdm::Vec3 c = ps_.prescribed_about[k];
    for (int i : ps_.prescribed_nodes[k]) {
      const vdm::Vec3 X = m.rest.positions.row(i);
      const vdm::Vec3 before = input_.prescribed_u.row(i);
      input_.prescribed.row(i).setOnes();
      input_.prescribed_u.row(i) = (R * (X - c) + c + a * p.translate - X).transpose();
      note_hold(i, -2 - static_cast<int>(k), before, input_.prescribed_u.row(i).transpose());
    }
  }
  times_.loads += ms_since(t_loads);
  const auto t_grasp = Clock::now();
  for (size_t k = 0; frame_stepped_ && k < grasps_.size(); ++k) {
    const tools::InstrumentPose pose = tools::pose_at(*graspers_[k], t);
    grasps_[k].update(*graspers_[k], pose, state_.x);
    earlier_hold_.clear();
    for (int i : grasps_[k].held()) earlier_hold_.emplace_back(i, input_.prescribed_u.row(i).transpose());
    grasps_[k].apply(pose, m.rest.positions, input_);
    for (const auto& [i, before] : earlier_hold_)
      note_hold(i, static_cast<int>(grasper_index_[k]), before, input_.prescribed_u.row(i).transpose());
  }
  if (!grasps_.empty()) times_.grasp += ms_since(t_grasp);

  frame_step_ms_ = 0;
  frame_iterations_ = 0;
  frame_fallbacks_ = 0;
  if (!frame_stepped_) {  // frame 0 with inertia: the organ at rest, nothing held yet
    measure_forces();
    return;
  }
  if (contact_) {
    // Sub-step when an instrument moves more than its size in a frame, so it cannot tunnel.
    double substeps = 1;
    for (const tools::InstrumentDef& in : s.instruments) {
      const double move = tools::instrument_motion(in, tools::pose_at(in, t), tools::pose_at(in, t_start));
      substeps = std::max(substeps, std::ceil(move / tools::instrument_size(in)));
    }
    const int n_sub = static_cast<int>(std::min(substeps, 1000.0));
    for (int j = 1; j <= n_sub; ++j) {
      const double tj = j == n_sub ? t : t_start + (t - t_start) * j / n_sub;
      const double tprev = t_start + (t - t_start) * (j - 1) / n_sub;
      for (size_t k = 0; k < probes_.size(); ++k)
        tools_[k] = tools::probe_shape(*probes_[k], tools::pose_at(*probes_[k], tj), tools::pose_at(*probes_[k], tprev));
      for (size_t k = 0; k < graspers_.size(); ++k) {
        const tools::InstrumentPose now = tools::pose_at(*graspers_[k], tj), before = tools::pose_at(*graspers_[k], tprev);
        for (int side = 0; side < 2; ++side)
          tools_[probes_.size() + 3 * k + side] = tools::jaw_shape(*graspers_[k], now, before, side ? -1 : +1);
        tools_[probes_.size() + 3 * k + 2] = tools::shaft_shape(*graspers_[k], now, before);
      }
      const auto t_contact = Clock::now();
      contact_->step(m, input_, tools_, state_, report_);
      frame_step_ms_ += ms_since(t_contact);
      frame_iterations_ += report_.iterations;  // every active-set solve, not only the last
      contact_iterations_ += report_.iterations;
      if (!report_.converged) ++unconverged_steps_;
      frame_fallbacks_ += state_.stats.fallbacks;
      times_.collision += report_.collision_ms;
      times_.collision_queries += report_.queries;
      if (state_.failed) break;  // the caller stops the run
    }
  } else {
    if (organ_) organ_->step(input_, state_);  // organ.model fem or mass_spring
    else vdm::step(m, input_, state_);
    frame_step_ms_ = state_.stats.step_ms;
    frame_iterations_ = state_.stats.iterations;
    frame_fallbacks_ = state_.stats.fallbacks;
  }
  measure_forces();
  times_.assemble += state_.stats.assemble_ms;
  times_.solve += state_.stats.solve_ms;
  times_.stress += state_.stats.stress_ms;
}

}  // namespace vdmsim
