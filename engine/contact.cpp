#include "engine/contact.hpp"
#include "engine/organ_solver.hpp"

#include <algorithm>

namespace vdm {

ContactSolver::ContactSolver(const TissueModel& m, ContactSettings settings)
    : settings_(settings), broad_(m, settings_), triangles_(&m.rest.triangles), own_solver_(make_vdm_solver(m)) {
  solver_ = own_solver_.get();
  // input_: the penalty method's copy of the scene's input, and the kinematic one's when it
  // does not borrow the caller's (step_kinematic() makes it then, on its first step).
  // SceneSimulation lends its input: none is made.
  if (settings_.method == ContactSettings::Method::penalty) input_ = make_step_input(m);
  active_.assign(m.n, 0);
  mark_.assign(m.n, 0);
  held_target_.reserve(static_cast<size_t>(m.n));  // (reserved, not touched: no memory until used)
  held_normal_.reserve(static_cast<size_t>(m.n));
  candidates_.reserve(static_cast<size_t>(m.n));
  held_.reserve(static_cast<size_t>(m.n));
  holder_.assign(static_cast<size_t>(m.n), 0);
  saved_flags_.reserve(static_cast<size_t>(m.n));
  saved_u_.reserve(static_cast<size_t>(m.n));
  if (settings_.method == ContactSettings::Method::penalty) {
    triangle_mark_.assign(static_cast<size_t>(m.rest.triangle_count()), 0);
    candidates_.reserve(static_cast<size_t>(std::max(m.n, m.rest.triangle_count())));
    penalty_force_ = NodeMat::Zero(m.n, 3);
    penalty_spring_ = NodeMat::Zero(m.n, 3);
    iterate_ = NodeMat::Zero(m.n, 3);
    for (int k = 0; k < kAnderson; ++k) {
      anderson_dg_[k] = NodeMat::Zero(m.n, 3);
      anderson_df_[k] = NodeMat::Zero(m.n, 3);
    }
    last_g_ = last_f_ = residual_ = x_iterate_ = NodeMat::Zero(m.n, 3);
    input_.spring_k = NodeMat::Zero(m.n, 3);
    input_.spring_u = NodeMat::Zero(m.n, 3);
  }
}

ContactSolver::~ContactSolver() = default;

void ContactSolver::set_solver(OrganSolver* solver) { solver_ = solver ? solver : own_solver_.get(); }

void ContactSolver::broad_phase(const ToolShape& t, size_t k, double pad, std::vector<int>& found, ContactReport& rep,
                                bool triangles) {
  ++rep.queries;
  broad_.query(t, k, pad, triangles, triangles ? triangle_mark_ : mark_, found);
}

void ContactSolver::step(const TissueModel& m, const StepInput& base, const std::vector<Capsule>& capsules, SimState& s,
                         ContactReport& rep) {
  capsule_tools_.resize(capsules.size());
  for (size_t k = 0; k < capsules.size(); ++k) capsule_tools_[k] = to_tool(capsules[k]);
  step(m, base, capsule_tools_, s, rep);
}

void ContactSolver::step(const TissueModel& m, const StepInput& base, const std::vector<ToolShape>& tools, SimState& s,
                         ContactReport& rep) {
  step_any(m, base, tools, s, rep, nullptr);
}

void ContactSolver::step(const TissueModel& m, StepInput& base, const std::vector<ToolShape>& tools, SimState& s,
                         ContactReport& rep) {
  const bool rows = base.prescribed.rows() == m.n && base.prescribed_u.rows() == m.n;
  step_any(m, base, tools, s, rep, rows ? &base : nullptr);
}

void ContactSolver::step_any(const TissueModel& m, const StepInput& base, const std::vector<ToolShape>& tools,
                             SimState& s, ContactReport& rep, StepInput* borrowed) {
  rep = ContactReport();
  const long boxes = broad_.box_updates();
  if (settings_.method == ContactSettings::Method::penalty) step_penalty(m, base, tools, s, rep);
  else if (settings_.method == ContactSettings::Method::kinematic) step_kinematic(m, base, tools, s, rep, borrowed);
  else if (solver_->solves_force_laws()) step_constraint_within(m, base, tools, s, rep);
  else step_constraint(m, base, tools, s, rep);
  rep.refit_boxes = broad_.box_updates() - boxes;
}

void ContactSolver::copy_scene_constraints(const TissueModel& m, const StepInput& base) {
  if (base.prescribed.rows() == m.n) {
    input_.prescribed = base.prescribed;
    input_.prescribed_u = base.prescribed_u;
  } else {
    input_.prescribed.setZero();
    input_.prescribed_u.setZero();
  }
}

}  // namespace vdm
