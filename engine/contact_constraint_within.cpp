// Constraint contact solved inside the organ model's own iteration (a model with
// OrganSolver::solves_force_laws(): vdm_core).
//
// The laws and the Gauss-Seidel are those of engine/contact_constraint.cpp; what differs is
// where the forces are found. There, each whole solve of the organ is followed by a
// correction of the forces on a model of its compliance, and the organ solved again: three
// to six nonlinear solves a step. Here the model calls update() after every linear solve of its
// own nonlinear iteration with the surface it found and its exact compliance at that
// linearisation; the forces that keep the laws on that linear response are found and the
// model's answer moved by them. When the model's iteration has converged, the laws hold on
// its exact equilibrium: one nonlinear solve a step, a second only when the solved surface
// meets a tool where no contact point was (each solve also adds the points it pushes into a
// tool as it goes).
#include <algorithm>

#include "engine/contact.hpp"
#include "engine/headroom.hpp"
#include "engine/organ_solver.hpp"
#include "engine/stopwatch.hpp"

namespace vdm {

void ContactSolver::step_constraint_within(const TissueModel& m, const StepInput& base,
                                           const std::vector<ToolShape>& tools, SimState& s, ContactReport& rep) {
  begin_within(m, base, tools, s, rep);
  const int max_it = std::max(1, settings_.max_constraint_iterations);
  auto solve = [&] {
    solver_->trial_step_with(within_input(m, base), s, *this);
    ++rep.solves;
    rep.iterations += s.stats.iterations;
  };
  for (int it = 0; it < max_it; ++it) {
    if (it > 0) solver_->rewind(s);
    solve();
    if (s.failed) break;  // the caller stops; the state is the step's start
    if (!s.stats.converged && rounds_ > 1) {
      // Solved again with one round, the laws on the points' tangent planes: with friction
      // 0.2, a probe pressed into a ball to half its depth (CoreHard.ProbePressedToHalfTheBallsDepth)
      // had a step where 24 of its 25 points slip and the core's iteration crept at 0.999 an
      // iteration (every Anderson mix refused by the safeguard) until it stalled; with one round
      // it converges. (Three radii by three step sizes of that press: with one round throughout,
      // 2 of the 9 runs end a step unconverged, 6 with four rounds and no second solve, 4 with it.)
      rounds_ = 1;
      solver_->rewind(s);
      solve();
      if (s.failed) break;
    }
    // A solve that did not converge is not judged or repeated: the next would meet the same.
    if (!s.stats.converged) break;

    // The laws at the solved state, with the compliance there: converged when they hold and
    // the forces would move no point by more than the tolerance.
    const auto t0 = Clock::now();
    measure_contacts(tools, s.x);
    const bool added = find_contact_points(m, base, tools, s.x, solver_->start_u(s), -settings_.constraint_tolerance,
                                           false, rep) > 0;
    if (added) sort_contacts();
    if (contacts_.empty()) {
      rep.converged = true;
      rep.collision_ms += ms_since(t0);
      break;
    }
    collect_contact_nodes();
    solver_->surface_compliance(contact_nodes_, exact_compliance_);
    double violation = 0.0, change = 0.0;
    project_forces(tools, true, 1.0, violation, change, rounds_);
    rep.collision_ms += ms_since(t0);
    if (!added && violation <= contact_tolerance_ && change <= contact_tolerance_) {
      rep.converged = true;
      break;
    }
    if (it + 1 == max_it) break;  // the state stays that of the forces it was solved with
    store_forces();
  }
  within_ = WithinStep{};
  if (!s.failed) end_constraint_step(m, base, tools, s, rep);
}

void ContactSolver::begin_within(const TissueModel& m, const StepInput& base, const std::vector<ToolShape>& tools,
                                 SimState& s, ContactReport& rep) {
  begin_constraint_step(m, base, tools, s, rep, true);
  within_ = WithinStep{&m, &base, &tools, &s, &rep};
  rounds_ = kGeometryRounds;
  rep.converged = false;
  input_.tolerance = 0.0;
}

const StepInput& ContactSolver::within_input(const TissueModel& m, const StepInput& base) {
  // The solve starts from the contact points' forces (the last step's, or the last solve's;
  // the points only grow within a step, so these nodes cover every force set before).
  for (const ContactPoint& c : contacts_)
    for (int v = 0; v < c.count; ++v) contact_force_.row(c.node[v]).setZero();
  for (const ContactPoint& c : contacts_)
    for (int v = 0; v < c.count; ++v) contact_force_.row(c.node[v]) += c.weight[v] * c.force.transpose();
  collect_contact_nodes();
  if (base.force.rows() == m.n) input_.force = base.force + contact_force_;
  else input_.force = contact_force_;
  return input_;
}

const StepInput& ContactSolver::begin_joint(const TissueModel& m, const StepInput& base, const std::vector<ToolShape>& tools,
                                            SimState& s, ContactReport& rep) {
  begin_within(m, base, tools, s, rep);
  within_.joint = true;
  return within_input(m, base);
}

void ContactSolver::end_joint(const TissueModel& m, const StepInput& base, const std::vector<ToolShape>& tools,
                              SimState& s, ContactReport& rep) {
  ++rep.solves;
  rep.iterations += s.stats.iterations;
  rep.converged = !s.failed && s.stats.converged;
  within_ = WithinStep{};
  if (!s.failed) end_constraint_step(m, base, tools, s, rep);
}

bool ContactSolver::update(const NodeMat& x, ComplianceSource& source, NodeMat& force) {
  const auto t0 = Clock::now();
  const WithinStep& w = within_;
  measure_contacts(*w.tools, x);
  // Points this solve has pushed into a tool join the step (with no force yet).
  if (find_contact_points(*w.model, *w.base, *w.tools, x, solver_->start_u(*w.state), -settings_.constraint_tolerance,
                          false, *w.report) > 0)
    sort_contacts();
  if (contacts_.empty()) {
    w.report->collision_ms += ms_since(t0);
    return false;
  }
  collect_contact_nodes();
  source.compliance(contact_nodes_, exact_compliance_);
  double violation = 0.0, change = 0.0;
  project_forces(*w.tools, true, 1.0, violation, change, rounds_);
  store_forces();
  // The law's share of the forces: out with the old, in with the new.
  resize_with_headroom(old_force_, contact_nodes_.size());
  for (size_t k = 0; k < contact_nodes_.size(); ++k) {
    const int i = contact_nodes_[k];
    old_force_[k] = contact_force_.row(i);
    force.row(i) -= contact_force_.row(i);
    contact_force_.row(i).setZero();
  }
  for (const ContactPoint& c : contacts_)
    for (int v = 0; v < c.count; ++v) contact_force_.row(c.node[v]) += c.weight[v] * c.force.transpose();
  bool changed = false;
  for (size_t k = 0; k < contact_nodes_.size(); ++k) {
    const int i = contact_nodes_[k];
    force.row(i) += contact_force_.row(i);
    changed = changed || contact_force_.row(i) != old_force_[k];
  }
  w.report->collision_ms += ms_since(t0);
  return changed;
}

}  // namespace vdm
