// Kinematic contact (ContactSettings::Method::kinematic): nodes that entered a tool are put
// back on its surface, back along their motion relative to the tool, and held there on all
// three axes for the step (sticking); after the solve, nodes whose reaction would pull the
// tool are released and free nodes pushed into it caught, and the step is solved again
// until the held set stops changing (an active set).
#include <algorithm>
#include <chrono>

#include "engine/contact.hpp"
#include "engine/organ_solver.hpp"
#include "engine/stopwatch.hpp"

namespace vdm {

void ContactSolver::step_kinematic(const TissueModel& m, const StepInput& base, const std::vector<ToolShape>& tools,
                                   SimState& s, ContactReport& rep, StepInput* borrowed) {
  const auto t0 = Clock::now();
  // A node's position at the step's start (its own motion in the step is x minus that), once
  // the step has been solved: the organ solver keeps the start's u, and every model's
  // positions are X + u bit for bit (every pass that moves u writes x so), so no copy of x is
  // made.
  auto start_x = [&](int i) -> Vec3 {
    return Vec3((m.rest.positions.row(i) + solver_->start_u(s).row(i)).transpose());
  };
  const bool has_prescribed = base.prescribed.rows() == m.n;
  // Nodes the scene itself moves (grasped, scripted) on every axis take no part in contact.
  auto driven = [&](int i) { return has_prescribed && base.prescribed.row(i).minCoeff() != 0; };
  // Contacts at the start: nodes inside (or touching) an instrument at its new pose.
  for (int i : held_) active_[i] = 0;
  held_.clear();
  held_target_.clear();
  held_normal_.clear();
  close_d_.resize(tools.size());
  close_p_.resize(tools.size());
  close_n_.resize(tools.size());
  refit(s.x);
  candidates_.clear();
  for (size_t k = 0; k < tools.size(); ++k) broad_phase(tools[k], k, settings_.activation * tools[k].size(), candidates_, rep);
  // A node that was free at the end of the last step (no reaction: a held node keeps
  // sticking until its reaction would pull) and now lies inside or touching the tool, but
  // that its own motion in the last step, carried on through this one, would take clear of
  // it through the face nearest to it (surface point p, outward normal n): the rim of a dent
  // that sinks faster than the instrument. Held, it would pull the tool and be released after
  // the first solve, which would then be redone; left free, it is caught after the solve if
  // it does enter the tool. The set the steps end with passes the same checks either way. A
  // motion that would carry it out through another face (across a thin jaw) does not count:
  // the checks after the solve see where a node ends, not what it crossed.
  auto moves_clear = [&](int i, const ToolShape& t, const Vec3& p, const Vec3& n) {
    const Vec3 v = s.velocity.row(i).transpose();
    if (!(m.dt > 0.0) || v.squaredNorm() == 0.0 || s.reaction.rows() != m.n || (s.reaction.row(i).array() != 0.0).any())
      return false;
    const Vec3 ahead = s.x.row(i).transpose() + m.dt * v;
    if (!((ahead - p).dot(n) > 0.0)) return false;
    Vec3 q, nq;
    return tool_distance(t, ahead, q, nq) > settings_.activation * t.size();
  };
  // `after_solve`: the node may have moved this step (relative motion = its move - the tool's).
  // `known`: close_* hold node i's distances to every tool already.
  auto classify = [&](int i, bool allow_touch, bool after_solve, bool known) {
    const Vec3 x = s.x.row(i).transpose();
    for (size_t k = 0; k < tools.size(); ++k) {
      const ToolShape& t = tools[k];
      if (!known) close_d_[k] = tool_distance(t, x, close_p_[k], close_n_[k]);
      const double dist = close_d_[k];
      const Vec3 &p = close_p_[k], &nrm = close_n_[k];
      const double limit = allow_touch ? settings_.activation * t.size() : -settings_.tolerance * 0.5 * t.size();
      if (dist < limit && !(after_solve == false && moves_clear(i, t, p, nrm))) {
        Vec3 dir;
        const Vec3 node_move = after_solve ? Vec3(s.x.row(i).transpose() - start_x(i)) : Vec3::Zero();
        const Vec3 target = dist < 0.0 ? push_out(t, x, node_move - t.motion_at(x), dir) : p;
        if (dist >= 0.0) dir = nrm;  // touching: held where it is; the tool pushes it along its normal
        active_[i] = 1;  // (classify only sees free nodes)
        holder_[size_t(i)] = int(k);
        held_.push_back(i);
        held_target_.push_back(target.transpose());
        held_normal_.push_back(dir.transpose());
        return true;
      }
    }
    return false;
  };
  for (int i : candidates_) {
    mark_[i] = 0;
    if (!driven(i)) classify(i, true, false, false);
  }
  rep.collision_ms += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();

  // Active set: solve, release adhesive nodes, catch penetrating ones, solve again. When the
  // cap is reached with the set still changing, one last solve makes the state and the set
  // agree (that set is not checked again: rep.converged says so).
  // Each solve sees the scene's loads and constraints with the rows of the held nodes set:
  // in `borrowed` (the caller's input, put back after the solve) or in a copy made once per
  // step (input_: its held rows put back after each solve too).
  const int max_it = std::max(1, settings_.max_active_set_iterations);
  StepInput& in = borrowed ? *borrowed : input_;
  if (!borrowed) {
    if (input_.prescribed.rows() != m.n) input_ = make_step_input(m);  // the first such step: allocates once
    input_.force = base.force;  // (0 rows: none)
    input_.pressure = base.pressure;
    copy_scene_constraints(m, base);
  }
  for (int it = 0; it <= max_it; ++it) {
    saved_flags_.resize(held_.size());
    saved_u_.resize(held_.size());
    for (size_t k = 0; k < held_.size(); ++k) {
      const int i = held_[k];
      saved_flags_[k] = in.prescribed.row(i);
      saved_u_[k] = in.prescribed_u.row(i);
      in.prescribed.row(i).setOnes();
      in.prescribed_u.row(i) = held_target_[k] - m.rest.positions.row(i);
    }
    if (it > 0) solver_->rewind(s);  // solve the same step again from its start
    // The engine's results pass only for the solve kept (finish_step below): the set's
    // checks read the reactions of the held nodes alone.
    solver_->trial_step(in, s, StepResults::reactions);
    for (size_t k = 0; k < held_.size(); ++k) {
      in.prescribed.row(held_[k]) = saved_flags_[k];
      in.prescribed_u.row(held_[k]) = saved_u_[k];
    }
    ++rep.solves;
    rep.iterations += s.stats.iterations;
    if (s.failed) return;  // the caller stops; the state is the step's start

    const auto tc = Clock::now();
    bool changed = false;
    // Release nodes the instrument would have to pull (adhesion).
    if (it < max_it) {
      size_t kept = 0;
      for (size_t k = 0; k < held_.size(); ++k) {
        const int i = held_[k];
        if (s.reaction.row(i).dot(held_normal_[k]) < 0.0) {
          active_[i] = 0;
          changed = true;
        } else {
          held_[kept] = i;
          held_target_[kept] = held_target_[k];
          held_normal_[kept] = held_normal_[k];
          ++kept;
        }
      }
      held_.resize(kept);
      held_target_.resize(kept);
      held_normal_.resize(kept);
    }
    // Catch free nodes that the step pushed into an instrument.
    refit(s.x);
    candidates_.clear();
    for (size_t k = 0; k < tools.size(); ++k) broad_phase(tools[k], k, 0.0, candidates_, rep);
    rep.max_penetration = 0.0;
    for (int i : candidates_) {
      mark_[i] = 0;
      if (active_[i] || driven(i)) continue;
      const Vec3 x = s.x.row(i).transpose();
      for (size_t k = 0; k < tools.size(); ++k) {
        close_d_[k] = tool_distance(tools[k], x, close_p_[k], close_n_[k]);
        rep.max_penetration = std::max(rep.max_penetration, -close_d_[k]);
      }
      if (it < max_it && classify(i, false, true, true)) changed = true;
    }
    rep.collision_ms += std::chrono::duration<double, std::milli>(Clock::now() - tc).count();
    if (!changed) {
      rep.converged = it < max_it;
      break;
    }
  }
  solver_->finish_step(s);
  std::sort(held_.begin(), held_.end());  // the force summed in node order
  tool_force_.assign(tools.size(), Vec3::Zero());
  for (int i : held_) {
    ++rep.nodes;
    rep.force -= s.reaction.row(i).transpose();
    tool_force_[size_t(holder_[size_t(i)])] -= s.reaction.row(i).transpose();
  }
}

}  // namespace vdm
