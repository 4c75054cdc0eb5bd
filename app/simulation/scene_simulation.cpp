#include "app/simulation/scene_simulation.hpp"

#include "app/mesh_prep/mesh_quality.hpp"
#include "app/simulation/organ_models.hpp"
#include "app/simulation/organ_overlap.hpp"
#include "app/simulation/organ_ties.hpp"
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

// An organ's box at its state, grown by `margin` and twice the most any of its nodes moves in
// a frame of dt at its last speed.
void grown_box(const vdm::SimState& st, double dt, double margin, vdm::Vec3& lo, vdm::Vec3& hi) {
  const vdm::NodeMat& x = st.x;
  const vdm::NodeMat& v = st.velocity;
  const double moved = v.rows() == x.rows() && v.rows() > 0 ? v.rowwise().norm().maxCoeff() * dt : 0.0;
  lo = x.colwise().minCoeff().transpose().array() - (margin + 2 * moved);
  hi = x.colwise().maxCoeff().transpose().array() + (margin + 2 * moved);
}

}  // namespace

SceneSimulation::SceneSimulation(const PreparedScene& ps) : ps_(ps) {
  const SceneDef& s = ps.scene;
  // Contact runs only when listed, against probes and graspers' jaws; grasping only when
  // listed, by graspers.
  for (size_t k = 0; k < s.instruments.size(); ++k) {
    const bool probe = s.instruments[k].type == tools::InstrumentDef::Type::probe;
    (probe ? probes_ : graspers_).push_back(&s.instruments[k]);
    (probe ? probe_index_ : grasper_index_).push_back(k);
  }
  contact_ = s.has(Effect::contact) && !s.instruments.empty();
  grasp_ = s.has(Effect::grasp) && !graspers_.empty();
  instrument_force_.assign(s.instruments.size(), vdm::Vec3::Zero());
  peak_force_.assign(s.instruments.size(), 0.0);
  organs_.resize(ps.organs.size());
  for (size_t i = 0; i < organs_.size(); ++i) {
    OrganRun& o = organs_[i];
    const PreparedOrgan& po = ps.organs[i];
    o.prepared = &po;
    o.def = &s.organs[i];
    o.state = vdm::make_sim_state(po.model);
    o.input = vdm::make_step_input(po.model);
    const vdm::NodeMat& X = po.model.rest.positions;
    o.size = (X.colwise().maxCoeff() - X.colwise().minCoeff()).norm();
    o.holder.assign(static_cast<size_t>(po.model.n), -1);
    o.force.assign(s.instruments.size(), vdm::Vec3::Zero());
    if (grasp_) o.grasps.resize(graspers_.size());
    // External forces only when the organ has loads: an empty force is none (1 MB at 40k nodes).
    if (o.def->loads.empty()) o.input.force.resize(0, 3);
    // A reference model keeps its own state: every simulation (a colour-range pass, the run, a
    // benchmark repeat) builds its own, so that none starts where another ended.
    o.solver = make_organ_solver(po.reference);
    if (contact_) {
      o.contact = std::make_unique<vdm::ContactSolver>(po.model, s.contact);
      o.contact->set_solver(o.solver.get());  // the organ model's solver (null: vdm)
    }
  }
  if (organs_.size() > 1) positions_ = ps.surface.positions;
  // Contact between organs: with the contact effect, constraint contact, and every organ on
  // the core (its iteration can be driven from here and gives its exact compliance).
  bool joint = organs_.size() > 1 && s.has(Effect::contact) && s.contact.method == vdm::ContactSettings::Method::constraint;
  for (const OrganRun& o : organs_) joint = joint && o.solver && o.solver->kind() == vdm::ModelKind::vdm_core;
  if (joint) {
    std::vector<int> nodes;
    std::vector<double> edges;
    for (const OrganRun& o : organs_) {
      nodes.push_back(o.prepared->model.n);
      edges.push_back(measure_mesh(o.prepared->model.rest).mean_edge);
    }
    pair_ = std::make_unique<vdm::OrganPairContact>(nodes, edges, s.contact.friction, vdmsim::organ_ties(ps));
    organ_force_.assign(organs_.size(), vdm::Vec3::Zero());
    joint_x_.resize(organs_.size());
    joint_triangles_.resize(organs_.size());
    joint_solvers_.resize(organs_.size());
    joint_active_.resize(organs_.size());
    joint_member_.resize(organs_.size());
    joint_waiting_.resize(organs_.size());
    joint_converged_.resize(organs_.size());
    joint_ready_.resize(organs_.size());
    joint_linear_.resize(organs_.size());
    joint_fixed_.resize(organs_.size());
    joint_solved_x_.resize(organs_.size());
    // The organs from the fewest nodes to the most (by the list where equal).
    for (size_t i = 0; i < organs_.size(); ++i) joint_order_.push_back(i);
    std::stable_sort(joint_order_.begin(), joint_order_.end(),
                     [&](size_t a, size_t b) { return organs_[a].prepared->model.n < organs_[b].prepared->model.n; });
    joint_lo_.resize(organs_.size());
    joint_hi_.resize(organs_.size());
    for (size_t i = 0; i < organs_.size(); ++i) {
      joint_triangles_[i] = &organs_[i].prepared->model.rest.triangles;
      joint_solvers_[i] = organs_[i].solver.get();
    }
  }
  tools_.resize(probes_.size() + 3 * graspers_.size());  // probes, then each grasper's two jaws and shaft
}

bool SceneSimulation::failed() const {
  return std::any_of(organs_.begin(), organs_.end(), [](const OrganRun& o) { return o.state.failed; });
}

std::string SceneSimulation::failure() const {
  for (const OrganRun& o : organs_)
    if (o.state.failed) return organ_prefix(o) + o.state.failure;
  return "";
}

std::vector<std::string> SceneSimulation::warnings() const {
  std::vector<std::string> out;
  for (const OrganRun& o : organs_)
    for (const std::string& w : o.state.warnings) out.push_back(organ_prefix(o) + w);
  return out;
}

std::string SceneSimulation::organ_prefix(const OrganRun& o) const {
  return organs_.size() > 1 ? o.def->name + ": " : "";
}

vdm::Vec3 SceneSimulation::total_force(size_t organ) const {
  vdm::Vec3 sum = vdm::Vec3::Zero();
  for (const vdm::Vec3& f : organs_[organ].force) sum += f;
  return sum;
}

std::string SceneSimulation::unsound() const {
  for (const OrganRun& o : organs_)
    if (std::string why = unsound(o); !why.empty()) return organ_prefix(o) + why;
  if (!total_force().allFinite()) return "non-finite instrument force";
  if (!conflict_.empty()) return conflict_;
  if (!rest_overlap_.empty()) return rest_overlap_;
  if (std::string why = organs_overlap(); !why.empty()) return why;
  return deep_probe();
}

// Organs passed into each other by more than kOrganOverlap: where contact between organs is not
// simulated nothing would push them apart, and where it is, it failed; their pictures and
// forces would be wrong. `placed`: the organs as placed, before the first step.
std::string SceneSimulation::organs_overlap(bool placed) const {
  for (size_t i = 0; i < organs_.size(); ++i)
    for (size_t j = i + 1; j < organs_.size(); ++j) {
      const OrganRun &a = organs_[i], &b = organs_[j];
      const OrganOverlap o = find_overlap(a.state.x, a.prepared->model.rest.triangles, b.state.x,
                                          b.prepared->model.rest.triangles);
      if (!(o.depth > kOrganOverlap)) continue;
      const OrganRun& in = o.in_b ? a : b;
      const OrganRun& into = o.in_b ? b : a;
      char text[160];
      std::snprintf(text, sizeof text, "node %d of %s is %.3g mm inside %s at [%.4g, %.4g, %.4g] m", o.node,
                    in.def->name.c_str(), 1e3 * o.depth, into.def->name.c_str(), o.where.x(), o.where.y(), o.where.z());
      if (pair_)
        return "organs " + a.def->name + " and " + b.def->name + " pass into each other (" + text +
               (placed ? "): contact between organs cannot push apart organs placed inside each other; place them apart"
                                          : "): contact between organs did not keep them apart (docs/several-organs.md)");
      return "organs " + a.def->name + " and " + b.def->name + " pass into each other (" + text +
             "): contact between organs is not simulated, so nothing keeps them apart; place them apart or keep the "
             "instruments from pushing one into the other (docs/several-organs.md)";
    }
  return "";
}

std::string SceneSimulation::unsound(const OrganRun& o) const {
  const vdm::SimState& st = o.state;
  if (!st.u.allFinite()) return "non-finite displacement";
  if (!std::isfinite(st.volume) || !std::isfinite(st.volume_rel_error)) return "non-finite volume";
  if (!std::isfinite(st.pressure)) return "non-finite pressure";
  if (!std::isfinite(st.stats.residual)) return "non-finite solver residual";
  if (ps_.scene.has(Effect::stress) && !st.stress.allFinite()) return "non-finite stress";
  if (st.reaction.size() > 0 && !st.reaction.allFinite()) return "non-finite reaction forces";
  const double size = o.size;
  const double moved = st.u.rowwise().norm().maxCoeff();
  if (moved > 2 * size) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "a node moved %.3g m, more than twice the organ's size (%.3g m): the material or the loads are out of "
                  "range",
                  moved, size);
    return text;
  }
  return "";
}

void SceneSimulation::note_hold(OrganRun& o, int node, int holder, const vdm::Vec3& before, const vdm::Vec3& after) {
  const int earlier = o.holder[static_cast<size_t>(node)];
  o.holder[static_cast<size_t>(node)] = holder;
  if (earlier == -1) return;
  // Apart by more than 5 % of the organ's size: not two holds of one piece of tissue moving
  // together, but the tissue torn between them.
  const double gap = (after - before).norm();
  if (!(gap > 0.05 * o.size) || gap <= conflict_gap_) return;
  conflict_gap_ = gap;
  const auto name = [&](int h) {
    return h >= 0 ? "instruments[" + std::to_string(h) + "]" : o.def->field + ".prescribed[" + std::to_string(-2 - h) + "]";
  };
  char gap_text[32];
  std::snprintf(gap_text, sizeof gap_text, "%.3g", gap);
  conflict_ = organ_prefix(o) + "node " + std::to_string(node) + " is held by both " + name(earlier) + " and " + name(holder) +
              ", which move it to places " + gap_text +
              " m apart: they pull the same tissue against each other (the model cannot tear tissue)";
}

// Why contact could not push the organ away from instruments[k], in the terms of the scene: a
// probe far thinner than the organ's triangles slips between its nodes; a material far softer
// than any tissue gives no force; else the organ is rigid or held where the probe presses.
std::string SceneSimulation::deep_probe_cause(const OrganRun& o, size_t probe) const {
  const OrganDef& s = *o.def;
  const vdm::SurfaceMesh& rest = o.prepared->model.rest;
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
    for (const OrganRun& o : organs_) {
      const vdm::TriMat& triangles = o.prepared->model.rest.triangles;
      if (!deeper_inside(o.state.x, triangles, tip, limit)) continue;
      const double depth = depth_inside(o.state.x, triangles, tip);
      char text[120];
      std::snprintf(text, sizeof text, "instruments[%zu]'s tip is %.3g m inside the organ (more than %.3g m): ",
                    probe_index_[k], depth, limit);
      return organ_prefix(o) + text + deep_probe_cause(o, k) + ", and its force would be wrong";
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
  for (OrganRun& o : organs_) {
    const std::vector<vdm::Vec3>* contact = o.contact ? &o.contact->tool_forces() : nullptr;
    auto tool = [&](size_t k) { return contact && k < contact->size() ? (*contact)[k] : vdm::Vec3::Zero(); };
    for (size_t k = 0; k < probes_.size(); ++k) o.force[probe_index_[k]] = tool(k);
    for (size_t k = 0; k < graspers_.size(); ++k) {
      const size_t jaws = probes_.size() + 3 * k;
      vdm::Vec3 f = tool(jaws) + tool(jaws + 1) + tool(jaws + 2);
      // The grasped nodes follow the jaws as prescribed motion: the organ pulls the jaws with
      // minus their reactions.
      if (k < o.grasps.size())
        for (int i : o.grasps[k].held()) f -= o.state.reaction.row(i).transpose();
      o.force[grasper_index_[k]] = f;
    }
    for (size_t k = 0; k < instrument_force_.size(); ++k)
      instrument_force_[k] = &o == &organs_.front() ? o.force[k] : vdm::Vec3(instrument_force_[k] + o.force[k]);
  }
  for (size_t k = 0; k < instrument_force_.size(); ++k)
    peak_force_[k] = std::max(peak_force_[k], instrument_force_[k].norm());
}

std::vector<tools::InstrumentPose> SceneSimulation::poses(double t) const {
  std::vector<tools::InstrumentPose> out;
  for (const tools::InstrumentDef& in : ps_.scene.instruments) out.push_back(tools::pose_at(in, t));
  return out;
}

// A snapshot is, for each organ in turn, its model's own state (vdm_core's; a reference model
// saves none: false), its engine state and its grasps; then the run's tallies; then each organ's
// contact carry; then the contact between organs and the attachments' ties.
bool SceneSimulation::save(std::string& out) const {
  for (const OrganRun& o : organs_) {
    if (o.solver && !o.solver->save_state(out)) return false;
    vdm::save_state(o.prepared->model, o.state, out);
    const std::int64_t grasps = static_cast<std::int64_t>(o.grasps.size());
    out.append(reinterpret_cast<const char*>(&grasps), sizeof grasps);
    for (const tools::Grasp& g : o.grasps) g.save(out);
  }
  // The run's force and contact tallies, so that a resumed run reports the whole run's.
  out.append(reinterpret_cast<const char*>(peak_force_.data()), sizeof(double) * peak_force_.size());
  for (const OrganRun& o : organs_)
    out.append(reinterpret_cast<const char*>(&o.max_volume_error), sizeof o.max_volume_error);
  const std::int64_t counts[2] = {unconverged_steps_, contact_iterations_};
  out.append(reinterpret_cast<const char*>(counts), sizeof counts);
  for (const OrganRun& o : organs_)
    if (o.contact) o.contact->save_state(out);
  if (pair_) pair_->save_state(out);
  return true;
}

bool SceneSimulation::load(std::string_view in, std::string& error) {
  size_t pos = 0;
  for (OrganRun& o : organs_) {
    const vdm::TissueModel& m = o.prepared->model;
    if (o.solver && !o.solver->load_state(in, pos, error)) return false;
    if (!vdm::load_state(m, in, pos, o.state, error)) return false;
    std::int64_t grasps = -1;
    if (in.size() - pos >= sizeof grasps) std::memcpy(&grasps, in.data() + pos, sizeof grasps);
    pos += sizeof grasps;
    if (grasps != static_cast<std::int64_t>(o.grasps.size())) {
      error = "state snapshot: of a scene with other graspers";
      return false;
    }
    for (tools::Grasp& g : o.grasps)
      if (!g.load(in, pos, m.n)) {
        error = "state snapshot: a grasp is truncated";
        return false;
      }
  }
  std::int64_t counts[2] = {0, 0};
  const size_t tallies = sizeof(double) * (peak_force_.size() + organs_.size()) + sizeof counts;
  if (in.size() - pos < tallies) {
    error = "state snapshot: the force tallies are truncated";
    return false;
  }
  if (!peak_force_.empty())  // (a scene without instruments: data() may be null)
    std::memcpy(peak_force_.data(), in.data() + pos, sizeof(double) * peak_force_.size());
  pos += sizeof(double) * peak_force_.size();
  for (OrganRun& o : organs_) {
    std::memcpy(&o.max_volume_error, in.data() + pos, sizeof o.max_volume_error);
    pos += sizeof o.max_volume_error;
  }
  std::memcpy(counts, in.data() + pos, sizeof counts);
  pos += sizeof counts;
  unconverged_steps_ = counts[0];
  contact_iterations_ = counts[1];
  for (OrganRun& o : organs_) {
    const vdm::TissueModel& m = o.prepared->model;
    if (o.contact && !o.contact->load_state(in, pos, m.n, m.rest.triangle_count(), error)) return false;
  }
  if (pair_ && !pair_->load_state(in, pos, error)) return false;
  if (pos != in.size()) {
    error = "state snapshot: bytes after the end";
    return false;
  }
  gather_positions();
  return true;
}

vdm::NodeMat SceneSimulation::organ_contact_forces(size_t organ) const {
  vdm::NodeMat force = vdm::NodeMat::Zero(organs_[organ].state.x.rows(), 3);
  if (pair_) pair_->add_forces(static_cast<int>(organ), force);
  return force;
}

void SceneSimulation::record_organ_surface(size_t organ, SubstepSurfaces* out) { organs_[organ].recorded = out; }

void SceneSimulation::follow_recorded_surface(size_t organ, const SubstepSurfaces* recorded) {
  organs_[organ].followed = recorded;
  organs_[organ].followed_x = organs_[organ].state.x;
  // (a followed organ does not yield: the contact between organs sees no compliance of it)
  if (organ < joint_solvers_.size()) joint_solvers_[organ] = recorded ? nullptr : organs_[organ].solver.get();
}

void SceneSimulation::set_followed_surface(OrganRun& o, int f, int j, int n) {
  if (!o.followed || static_cast<size_t>(f) >= o.followed->size()) return;
  const std::vector<vdm::NodeMat>& frame = (*o.followed)[static_cast<size_t>(f)];
  if (frame.empty()) return;
  // Sub-step j of n (1-based) takes the recorded sub-step k of m with k / m the first at or
  // past j / n.
  const size_t m = frame.size();
  const size_t k = std::min(m, (static_cast<size_t>(j) * m + static_cast<size_t>(n) - 1) / static_cast<size_t>(n));
  o.followed_x = frame[std::max<size_t>(k, 1) - 1];
}

void SceneSimulation::end_substep() {
  for (OrganRun& o : organs_) {
    if (o.followed) {
      o.state.x = o.followed_x;
      o.state.u = o.state.x - o.prepared->model.rest.positions;
    }
    if (o.recorded) o.recorded->back().push_back(o.state.x);
  }
}

void SceneSimulation::gather_positions() {
  if (organs_.size() == 1) return;
  for (size_t i = 0; i < organs_.size(); ++i)
    positions_.middleRows(ps_.node_offset[i], organs_[i].state.x.rows()) = organs_[i].state.x;
}

void SceneSimulation::apply_script(OrganRun& o, double t) {
  const OrganDef& s = *o.def;
  const PreparedOrgan& po = *o.prepared;
  const vdm::TissueModel& m = po.model;
  vdm::StepInput& input = o.input;
  input.force.setZero();
  input.prescribed.setZero();
  for (size_t k = 0; k < s.loads.size(); ++k) {
    const auto& nodes = po.load_nodes[k];
    const vdm::Vec3 per_node = ramp(t, s.loads[k].t0, s.loads[k].t1) * s.loads[k].force / double(nodes.size());
    for (int i : nodes) input.force.row(i) += per_node.transpose();
  }
  // Every hold of a node (prescribed, a grasp) is noted: two that move one node to places far
  // apart pull the tissue against each other (unsound()).
  std::fill(o.holder.begin(), o.holder.end(), -1);
  for (size_t k = 0; k < s.prescribed.size(); ++k) {
    const PrescribedDef& p = s.prescribed[k];
    const double a = ramp(t, p.t0, p.t1);
    const Eigen::Matrix3d R = rotation_from_degrees(a * p.rotate_deg);
    const vdm::Vec3 c = po.prescribed_about[k];
    for (int i : po.prescribed_nodes[k]) {
      const vdm::Vec3 X = m.rest.positions.row(i);
      const vdm::Vec3 before = input.prescribed_u.row(i);
      input.prescribed.row(i).setOnes();
      input.prescribed_u.row(i) = (R * (X - c) + c + a * p.translate - X).transpose();
      note_hold(o, i, -2 - static_cast<int>(k), before, input.prescribed_u.row(i).transpose());
    }
  }
  const auto t_grasp = Clock::now();
  for (size_t k = 0; frame_stepped_ && k < o.grasps.size(); ++k) {
    const tools::InstrumentPose pose = tools::pose_at(*graspers_[k], t);
    o.grasps[k].update(*graspers_[k], pose, o.state.x);
    earlier_hold_.clear();
    for (int i : o.grasps[k].held()) earlier_hold_.emplace_back(i, input.prescribed_u.row(i).transpose());
    o.grasps[k].apply(pose, m.rest.positions, input);
    for (const auto& [i, before] : earlier_hold_)
      note_hold(o, i, static_cast<int>(grasper_index_[k]), before, input.prescribed_u.row(i).transpose());
  }
  if (!o.grasps.empty()) times_.grasp += ms_since(t_grasp);
}

void SceneSimulation::advance(int f) {
  const SceneDef& s = ps_.scene;
  const double t = frame_time(f, s.dt);
  // Where the instruments were at the start of this frame's step: frame 0's step (a settle at
  // t = 0) does not move them.
  const double t_start = f == 0 ? t : frame_time(f - 1, s.dt);
  time_ = t;
  // With inertia the state at t = 0 is the initial condition, the organs at rest: a step here
  // would integrate the motion over a whole dt and label it t = 0.
  frame_stepped_ = !(f == 0 && s.has(Effect::inertia));
  // Organs placed inside each other: contact between them cannot tell which way is out, and the
  // run stops before its first step (unsound() says where).
  if (pair_ && f == 0) rest_overlap_ = organs_overlap(true);
  if (!rest_overlap_.empty()) return;
  // Scripted loads and motions for this frame.
  conflict_.clear();
  conflict_gap_ = 0;
  const auto t_loads = Clock::now();
  for (OrganRun& o : organs_) {
    apply_script(o, t);
    if (o.recorded) o.recorded->emplace_back();
  }
  times_.loads += ms_since(t_loads);

  frame_step_ms_ = 0;
  frame_iterations_ = 0;
  frame_fallbacks_ = 0;
  if (!frame_stepped_) {  // frame 0 with inertia: the organs at rest, nothing held yet
    measure_forces();
    return;
  }
  report_ = vdm::ContactReport{};
  if (contact_) {
    // Sub-step when an instrument moves more than its size in a frame, so it cannot tunnel:
    // counting the part of it that can reach an organ.
    double substeps = 1;
    for (const tools::InstrumentDef& in : s.instruments) {
      const tools::InstrumentPose now = tools::pose_at(in, t), before = tools::pose_at(in, t_start);
      const double move = tools::instrument_motion(in, now, before);
      const double reach = reach_into_organs(in, now, before, move);
      substeps = std::max(substeps, std::ceil(tools::instrument_motion(in, now, before, reach) / tools::instrument_size(in)));
    }
    const int n_sub = static_cast<int>(std::min(substeps, 1000.0));
    bool failed = false;
    for (int j = 1; j <= n_sub && !failed; ++j) {
      const double tj = j == n_sub ? t : t_start + (t - t_start) * j / n_sub;
      // (the stress of the frame's last sub-step only: it is the one drawn and measured)
      for (OrganRun& o : organs_)
        if (o.solver) o.solver->set_surface_stress(j == n_sub);
      const double tprev = t_start + (t - t_start) * (j - 1) / n_sub;
      for (size_t k = 0; k < probes_.size(); ++k)
        tools_[k] = tools::probe_shape(*probes_[k], tools::pose_at(*probes_[k], tj), tools::pose_at(*probes_[k], tprev));
      for (size_t k = 0; k < graspers_.size(); ++k) {
        const tools::InstrumentPose now = tools::pose_at(*graspers_[k], tj), before = tools::pose_at(*graspers_[k], tprev);
        for (int side = 0; side < 2; ++side)
          tools_[probes_.size() + 3 * k + side] = tools::jaw_shape(*graspers_[k], now, before, side ? -1 : +1);
        tools_[probes_.size() + 3 * k + 2] = tools::shaft_shape(*graspers_[k], now, before);
      }
      for (OrganRun& o : organs_) set_followed_surface(o, f, j, n_sub);
      if (pair_) {
        const auto t_contact = Clock::now();
        step_joint();
        frame_step_ms_ += ms_since(t_contact);
      }
      for (size_t i = 0; i < organs_.size(); ++i) {
        OrganRun& o = organs_[i];
        if (o.followed) continue;
        if (!joint(i)) {
          const auto t_contact = Clock::now();
          o.contact->step(o.prepared->model, o.input, tools_, o.state, o.report);
          frame_step_ms_ += ms_since(t_contact);
        }
        frame_iterations_ += o.report.iterations;  // every active-set solve, not only the last
        o.iterations += o.report.iterations;
        contact_iterations_ += o.report.iterations;
        if (!o.report.converged) ++unconverged_steps_;
        frame_fallbacks_ += o.state.stats.fallbacks;
        times_.collision += o.report.collision_ms;
        times_.collision_queries += o.report.queries;
        if (o.state.failed) {  // the caller stops the run
          failed = true;
          break;
        }
      }
      end_substep();
    }
    // The frame's report over every organ (the last sub-step's of each).
    report_ = organs_.front().report;
    for (size_t i = 1; i < organs_.size(); ++i) {
      const vdm::ContactReport& r = organs_[i].report;
      report_.nodes += r.nodes;
      report_.force += r.force;
      report_.max_penetration = std::max(report_.max_penetration, r.max_penetration);
      report_.solves += r.solves;
      report_.iterations += r.iterations;
      report_.converged = report_.converged && r.converged;
      report_.queries += r.queries;
      report_.refit_boxes += r.refit_boxes;
      report_.collision_ms += r.collision_ms;
    }
  } else {
    for (OrganRun& o : organs_) set_followed_surface(o, f, 1, 1);
    if (pair_) step_joint();
    for (size_t i = 0; i < organs_.size(); ++i) {
      OrganRun& o = organs_[i];
      if (o.followed) continue;
      if (joint(i)) {}  // stepped with the organs it touches
      else if (o.solver) o.solver->step(o.input, o.state);  // the organ model's own (fem, mass_spring, vdm_core)
      else vdm::step(o.prepared->model, o.input, o.state);
      frame_step_ms_ += o.state.stats.step_ms;
      frame_iterations_ += o.state.stats.iterations;
      o.iterations += o.state.stats.iterations;
      frame_fallbacks_ += o.state.stats.fallbacks;
      if (o.state.failed) break;
    }
  }
  if (!contact_) end_substep();
  measure_forces();
  for (OrganRun& o : organs_) {
    o.max_volume_error = std::max(o.max_volume_error, std::abs(o.state.volume_rel_error));
    times_.assemble += o.state.stats.assemble_ms;
    times_.solve += o.state.stats.solve_ms;
    times_.stress += o.state.stats.stress_ms;
  }
  gather_positions();
}

double SceneSimulation::reach_into_organs(const tools::InstrumentDef& in, const tools::InstrumentPose& now,
                                          const tools::InstrumentPose& before, double move) const {
  // The farthest point of the axis, at either pose, inside an organ's box grown by the
  // instrument's radius, its whole motion over the frame and the organ's own (twice its last
  // velocity's, and a centimetre): a point of the shaft farther back moves by less than the
  // growth over the frame, so it meets no organ however far it moves.
  double reach = 0;
  for (const OrganRun& o : organs_) {
    if (o.state.x.rows() == 0) continue;
    vdm::Vec3 lo, hi;
    grown_box(o.state, ps_.scene.dt, in.radius + move + 0.01, lo, hi);
    for (const tools::InstrumentPose* p : {&now, &before}) {
      // The axis from the tip back, tip - s axis for s in [0, length], clipped to the box.
      const vdm::Vec3 d = -p->axis.normalized();
      double s0 = 0, s1 = in.length;
      for (int k = 0; k < 3 && s0 <= s1; ++k) {
        if (std::abs(d[k]) < 1e-12) {
          if (p->tip[k] < lo[k] || p->tip[k] > hi[k]) s1 = -1;
          continue;
        }
        double a = (lo[k] - p->tip[k]) / d[k], b = (hi[k] - p->tip[k]) / d[k];
        if (a > b) std::swap(a, b);
        s0 = std::max(s0, a);
        s1 = std::min(s1, b);
      }
      if (s0 <= s1) reach = std::max(reach, s1);
    }
  }
  return reach;
}

void SceneSimulation::find_joint_organs() {
  // Each organ's box at the step's start, grown by the contact's reach and twice the most any
  // of its nodes moves in a frame at its last speed (with a millimetre to spare): organs whose
  // boxes meet, or that a tie holds together, step together.
  const size_t n = organs_.size();
  std::vector<vdm::Vec3>& lo = joint_lo_;
  std::vector<vdm::Vec3>& hi = joint_hi_;
  for (size_t i = 0; i < n; ++i) grown_box(organs_[i].state, ps_.scene.dt, kOrganContactReach + 0.001, lo[i], hi[i]);
  std::fill(joint_member_.begin(), joint_member_.end(), 0);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j)
      if (((lo[i].array() <= hi[j].array()).all() && (lo[j].array() <= hi[i].array()).all()) ||
          pair_->tied(static_cast<int>(i), static_cast<int>(j)))
        joint_member_[i] = joint_member_[j] = 1;
}

namespace {
// An organ at its fixed point whose answer the others' forces have since moved, linearly, by
// at most this many times its tolerance has converged: a linear answer's error is about its
// motion times the tissue's strain there.
constexpr double kLinearTrust = 10;
}  // namespace

void SceneSimulation::step_joint() {
  const size_t n = organs_.size();
  find_joint_organs();
  std::fill(organ_force_.begin(), organ_force_.end(), vdm::Vec3::Zero());
  if (std::find(joint_member_.begin(), joint_member_.end(), 1) == joint_member_.end()) return;
  for (size_t i = 0; i < n; ++i) {
    joint_active_[i] = 0;
    if (!joint_member_[i]) continue;
    OrganRun& o = organs_[i];
    o.report = vdm::ContactReport{};
    if (o.followed) continue;
    const vdm::StepInput& in =
        o.contact ? o.contact->begin_joint(o.prepared->model, o.input, tools_, o.state, o.report) : o.input;
    joint_active_[i] = o.solver->joint_begin(in, o.state, o.contact ? &o.contact->joint_law() : nullptr);
  }
  for (size_t i = 0; i < n; ++i) joint_x_[i] = &organs_[i].state.x;
  pair_->begin_step(joint_x_);
  // The organs iterate cheapest first: an organ waits (is not solved) while an organ with
  // fewer nodes has not converged, and when it has converged itself. A large liver then does
  // not iterate for a small gallbladder, pulled by a grasper, that is still finding its way.
  // While it waits for a cheaper organ its answer is not moved by the others' forces (a
  // liver's linear update costs more than a gallbladder's solve): the contact sees it moved by
  // its compliance at the points' nodes (OrganPairContact::predict), and it takes the forces
  // when it is checked again, once every cheaper organ has converged. It has converged when
  // its last solve reached its own iteration's fixed point and the forces since have moved its
  // answer by at most kLinearTrust tolerances; else it is solved again.
  std::fill(joint_waiting_.begin(), joint_waiting_.end(), 0);
  std::fill(joint_linear_.begin(), joint_linear_.end(), 0);
  std::fill(joint_fixed_.begin(), joint_fixed_.end(), 0);
  for (;;) {
    for (size_t i = 0; i < n; ++i) {
      if (joint_active_[i] && !joint_waiting_[i]) {
        organs_[i].solver->joint_solve();
      }
      if (!joint_linear_[i])
        joint_x_[i] = joint_active_[i]         ? &organs_[i].solver->joint_surface()
                      : organs_[i].followed ? &organs_[i].followed_x
                                            : &organs_[i].state.x;
    }
    pair_->find_points(joint_x_, joint_triangles_, kOrganContactReach);
    double violation = 0, change = 0;
    pair_->correct(joint_solvers_, violation, change);
    // Each organ solved in this round, or waiting while every cheaper one has converged,
    // takes the forces and checks its iteration; one waiting for a cheaper organ is predicted.
    bool all = true, cheaper = true;
    for (size_t i : joint_order_) {
      if (!joint_active_[i]) continue;
      vdm::OrganSolver& solver = *organs_[i].solver;
      joint_linear_[i] = joint_waiting_[i] && !cheaper;
      if (joint_linear_[i]) {
        joint_x_[i] = &pair_->predict(static_cast<int>(i), solver.joint_surface());
      } else {
        // Solved in this round: at its fixed point under the forces it was solved with?
        if (!joint_waiting_[i]) {
          joint_fixed_[i] = solver.joint_converged();
          joint_solved_x_[i] = solver.joint_surface();
        }
        pair_->apply(static_cast<int>(i), solver.joint_forces());
        solver.joint_forces_changed();
        // Converged when it was, and the forces' change since its solve has moved its answer
        // (linearly) by no more than a few tolerances.
        joint_converged_[i] = joint_fixed_[i] && (solver.joint_surface() - joint_solved_x_[i]).cwiseAbs().maxCoeff() <=
                                                     kLinearTrust * solver.joint_tolerance();
      }
      joint_ready_[i] = cheaper;
      cheaper = cheaper && joint_converged_[i];
      all = all && joint_converged_[i];
    }
    if (all) {
      for (size_t i = 0; i < n; ++i)
        if (joint_active_[i]) organs_[i].solver->joint_advance(true);
      break;
    }
    bool more = true;
    for (size_t i = 0; i < n; ++i) {
      if (!joint_active_[i]) continue;
      joint_waiting_[i] = joint_converged_[i] || !joint_ready_[i];
      if (!joint_waiting_[i] && !organs_[i].solver->joint_advance(false)) more = false;  // out of iterations: the step ends unconverged
    }
    if (!more) {
      for (size_t i = 0; i < n; ++i) {
        if (!joint_active_[i]) continue;
        if (joint_linear_[i]) {  // the forces the contact found for it, taken
          pair_->apply(static_cast<int>(i), organs_[i].solver->joint_forces());
          organs_[i].solver->joint_forces_changed();
        } else if (joint_converged_[i]) {
          organs_[i].solver->joint_advance(true);  // converged itself: another ran out of iterations
        }
      }
      break;
    }
  }
  pair_->end_step();
  for (size_t i = 0; i < n; ++i) {
    OrganRun& o = organs_[i];
    if (!joint_member_[i]) continue;
    if (o.followed) o.report.converged = true;
    else {
      if (joint_active_[i]) o.solver->joint_end(o.state);
      if (o.contact) o.contact->end_joint(o.prepared->model, o.input, tools_, o.state, o.report);
      else o.report.converged = o.state.stats.converged;
    }
    organ_force_[i] = pair_->contact_force(static_cast<int>(i)) + pair_->tie_force(static_cast<int>(i));
  }
}

}  // namespace vdmsim
