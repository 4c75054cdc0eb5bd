// Penalty contact (ContactSettings::Method::penalty): every surface triangle near a tool is
// sampled, each sample inside a tool is pushed out along the tool's normal by the pressure
// k_c * depth, spread on the triangle's nodes by barycentric weights (so a thin probe between
// nodes still meets the surface). The forces are solved implicitly by a majorised Newton
// iteration: each solve adds, per node and axis, a spring that bounds the penalty's
// stiffness from above (StepInput::spring_k), which makes the iteration converge for any
// k_c; Anderson mixing of the last solves speeds it up.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "engine/contact.hpp"
#include "engine/organ_solver.hpp"
#include "engine/stopwatch.hpp"
#include "engine/warnings.hpp"

namespace vdm {

double ContactSolver::penalty_forces(const std::vector<ToolShape>& tools, const NodeMat& x, ContactReport& rep,
                                     const StepInput* base, std::vector<Vec3>* per_tool) {
  const bool has_prescribed = base && base->prescribed.rows() == x.rows();
  if (per_tool) per_tool->assign(tools.size(), Vec3::Zero());
  penalty_force_.setZero();
  penalty_spring_.setZero();
  refit(x);
  candidates_.clear();
  for (size_t k = 0; k < tools.size(); ++k) broad_phase(tools[k], k, 0.0, candidates_, rep, true);
  double smallest = std::numeric_limits<double>::infinity();
  for (const ToolShape& t : tools) smallest = std::min(smallest, t.size());
  const double kc = settings_.penalty_stiffness;
  double deepest = 0.0;
  for (int tri : candidates_) {
    triangle_mark_[tri] = 0;
    const int node[3] = {(*triangles_)(tri, 0), (*triangles_)(tri, 1), (*triangles_)(tri, 2)};
    const Vec3 a = x.row(node[0]).transpose();
    const Vec3 ab = x.row(node[1]).transpose() - a, ac = x.row(node[2]).transpose() - a;
    const double area = 0.5 * ab.cross(ac).norm();
    const double edge = std::max({ab.norm(), ac.norm(), (ac - ab).norm()});
    // S x S sub-triangles, none wider than a quarter of the smallest tool: their centroids
    // are the samples, each standing for area / S^2 of the surface.
    const int S = std::clamp(static_cast<int>(std::ceil(edge / (0.25 * smallest))), 1, 16);
    const double weight = kc * area / (S * S);
    auto sample = [&](double bu, double bv) {
      const Vec3 y = a + bu * ab + bv * ac;
      const double b[3] = {1.0 - bu - bv, bu, bv};
      for (size_t k = 0; k < tools.size(); ++k) {
        const ToolShape& t = tools[k];
        Vec3 p, n;
        const double dist = tool_distance(t, y, p, n);
        if (dist >= 0.0) continue;
        deepest = std::max(deepest, -dist);
        // Force k_c depth w n; its Jacobian k_c w (b n)(b n)^T is bounded by the diagonal
        // k_c w b_i |n_d| |n|_1 (diagonally dominant difference: positive semi-definite).
        const Vec3 force = weight * (-dist) * n;
        const Vec3 spring = weight * n.lpNorm<1>() * n.cwiseAbs();
        for (int c = 0; c < 3; ++c) {
          penalty_force_.row(node[c]) += b[c] * force.transpose();
          penalty_spring_.row(node[c]) += b[c] * spring.transpose();
          if (per_tool && !(has_prescribed && base->prescribed.row(node[c]).minCoeff() != 0))
            (*per_tool)[k] -= b[c] * force;
        }
      }
    };
    for (int i = 0; i < S; ++i)
      for (int j = 0; i + j < S; ++j) {
        sample((i + 1.0 / 3.0) / S, (j + 1.0 / 3.0) / S);                         // upright sub-triangle
        if (i + j < S - 1) sample((i + 2.0 / 3.0) / S, (j + 2.0 / 3.0) / S);  // inverted one
      }
  }
  return deepest;
}

void ContactSolver::step_penalty(const TissueModel& m, const StepInput& base, const std::vector<ToolShape>& tools,
                                 SimState& s, ContactReport& rep) {
  if (!solver_->takes_springs()) {  // fem and mass_spring: their steps could not be implicit
    s.failed = true;
    s.failure = "penalty contact needs the vdm model (organ.model fem and mass_spring take kinematic or constraint contact)";
    return;
  }
  const bool has_prescribed = base.prescribed.rows() == m.n;
  copy_scene_constraints(m, base);
  input_.pressure = base.pressure;
  double smallest = std::numeric_limits<double>::infinity();
  for (const ToolShape& t : tools) smallest = std::min(smallest, t.size());
  // Majorised Newton: at the iterate u_k, the step sees the penalty force F(u_k) plus springs
  // D (u_k - u), D >= the penalty's Jacobian, so that every solve lowers the energy of the
  // linearised problem: the iteration converges for any k_c, but slowly where D exceeds the
  // Jacobian (sliding along a curved tool). Anderson mixing of the last solves speeds it up;
  // it restarts when the residual grows.
  auto t0 = Clock::now();
  iterate_ = s.u;
  penalty_forces(tools, s.x, rep);
  rep.collision_ms += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  const int max_it = std::max(1, settings_.max_penalty_iterations);
  rep.converged = false;
  int history = 0, next_slot = 0;  // Anderson differences stored, ring position
  double last_norm = std::numeric_limits<double>::infinity();  // residual of the last accepted iterate
  bool mixed = false;                                          // the current iterate is a mixed one
  for (int it = 0; it < max_it; ++it) {
    if (it > 0) solver_->rewind(s);
    if (base.force.rows() == m.n) input_.force = base.force + penalty_force_;
    else input_.force = penalty_force_;
    input_.spring_k = penalty_spring_;
    input_.spring_u = iterate_;
    solver_->trial_step(input_, s, StepResults::none);  // the results of the last one only (below)
    ++rep.solves;
    rep.iterations += s.stats.iterations;
    if (s.failed) return;  // the caller stops; the state is the step's start
    residual_ = s.u - iterate_;  // f_k = G(u_k) - u_k
    const double change = residual_.cwiseAbs().maxCoeff();
    if (change <= settings_.penalty_tolerance * smallest) {
      rep.converged = true;
      break;
    }
    if (it + 1 == max_it) break;
    // Anderson (type II): u_{k+1} = G(u_k) - sum_j gamma_j dG_j, gamma minimising
    // |f_k - sum_j gamma_j dF_j| over the stored differences. Safeguarded: a mixed iterate
    // whose residual grew is dropped for the plain step from the point before it, G(u_{k-1}),
    // and the history starts again.
    const double norm = residual_.norm();
    if (mixed && norm > last_norm) {
      iterate_ = last_g_;
      history = 0;
      next_slot = 0;
      mixed = false;
    } else {
      if (it > 0) {
        anderson_dg_[next_slot] = s.u - last_g_;
        anderson_df_[next_slot] = residual_ - last_f_;
        next_slot = (next_slot + 1) % kAnderson;
        history = std::min(history + 1, static_cast<int>(kAnderson));
      }
      last_g_ = s.u;
      last_f_ = residual_;
      last_norm = norm;
      iterate_ = s.u;
      mixed = false;
      if (settings_.anderson && history > 0) {
        Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kAnderson, kAnderson> gram(history, history);
        Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kAnderson, 1> rhs(history), gamma(history);
        for (int a = 0; a < history; ++a) {
          rhs[a] = (anderson_df_[a].array() * residual_.array()).sum();
          for (int b = 0; b <= a; ++b)
            gram(a, b) = gram(b, a) = (anderson_df_[a].array() * anderson_df_[b].array()).sum();
        }
        gram.diagonal() *= 1.0 + 1e-10;  // nearly parallel differences
        gamma = gram.ldlt().solve(rhs);
        if (gamma.allFinite()) {
          for (int a = 0; a < history; ++a) iterate_ -= gamma[a] * anderson_dg_[a];
          mixed = true;
        }
      }
    }
    t0 = Clock::now();
    x_iterate_ = m.rest.positions + iterate_;
    penalty_forces(tools, x_iterate_, rep);
    rep.collision_ms += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  }
  solver_->finish_step(s);
  t0 = Clock::now();
  const double deepest = penalty_forces(tools, s.x, rep, &base, &tool_force_);
  rep.collision_ms += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  // The contact force at the final positions; the organ pushes the tools with -F.
  rep.max_penetration = deepest;
  // Deeper than half the tool, a penalty this soft lets the surface slip round it.
  static const char* const kTooSoft =
      "penalty contact too soft: an instrument sank more than half its size into the surface";
  if (deepest > 0.5 * smallest && s.warnings.size() < kMaxWarnings &&
      std::find(s.warnings.begin(), s.warnings.end(), kTooSoft) == s.warnings.end())
    s.warnings.emplace_back(kTooSoft);
  for (int i = 0; i < m.n; ++i) {
    if (penalty_force_.row(i).squaredNorm() == 0.0) continue;
    if (has_prescribed && base.prescribed.row(i).minCoeff() != 0) continue;  // driven: the scene holds it
    ++rep.nodes;
    rep.force -= penalty_force_.row(i).transpose();
    s.reaction.row(i) = penalty_force_.row(i);
    const double a = s.area_vectors.row(i).norm();
    s.reaction_pressure[i] = a > 0 ? penalty_force_.row(i).norm() / a : 0.0;
  }
}

}  // namespace vdm
