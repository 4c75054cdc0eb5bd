#include <algorithm>
#include <chrono>
#include <cmath>

#include "engine/geometry.hpp"
#include "engine/loads.hpp"
#include "engine/sim_state.hpp"
#include "engine/step_workspace.hpp"
#include "engine/stiffness.hpp"
#include "engine/stress.hpp"

namespace vdm {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

void add_warning(SimState& s, const char* what) {
  if (s.warnings.size() < 64) s.warnings.emplace_back(what);
}

// Step 1 of section 4: A_i, V_i, V and every K^d at the positions `x`. Returns V. A geometry
// that encloses no positive volume (inverted mid-run) would make K indefinite: then the last
// valid geometry is kept (returns -1 after restoring it) and the caller says so.
double refresh_geometry(const TissueModel& m, const NodeMat& x, SimState& s, StepWorkspace& w) {
  distributed_area_vectors(x, m.rest.triangles, s.area_vectors);
  const double v = enclosed_volume(x, m.rest.triangles, m.origin);
  if (!(v > 0.0) || !std::isfinite(v) || !s.area_vectors.allFinite()) {
    if (w.have_geometry) {  // back to the geometry K was built from
      distributed_area_vectors(w.x_refresh, m.rest.triangles, s.area_vectors);
      distributed_volumes(s.area_vectors, enclosed_volume(w.x_refresh, m.rest.triangles, m.origin),
                          s.node_volumes);
    }
    return -1.0;
  }
  distributed_volumes(s.area_vectors, v, s.node_volumes);
  if (m.use_inertia) {
    const double h = m.dt;
    for (int i = 0; i < m.n; ++i) {
      const double mass = m.density * s.node_volumes[i];
      w.extra_diagonal[i] = mass / (h * h) + m.damping * mass / h;
    }
  }
  assemble_stiffness(m, s.area_vectors, s.node_volumes, w.extra_diagonal, w.K);
  if (&x != &w.x_refresh) w.x_refresh = x;
  w.matrix_dirty = true;
  w.have_geometry = true;
  w.steps_since_refresh = 0;
  return v;
}

// The input's arrays must be sized for the model and finite where used. Returns the reason
// when not (static text), null when the input is fine.
const char* check_input(const TissueModel& m, const StepInput& in) {
  const bool has_prescribed = in.prescribed.rows() != 0;
  if (has_prescribed && in.prescribed.rows() != m.n) return "StepInput.prescribed has the wrong number of rows";
  if (has_prescribed && in.prescribed_u.rows() != m.n)
    return "StepInput.prescribed_u has the wrong number of rows";
  if (in.force.rows() != 0 && in.force.rows() != m.n) return "StepInput.force has the wrong number of rows";
  if (in.pressure.size() != 0 && in.pressure.size() != m.n) return "StepInput.pressure has the wrong size";
  if (in.force.rows() == m.n && !in.force.allFinite()) return "StepInput.force is not finite";
  if (in.pressure.size() == m.n && !in.pressure.allFinite()) return "StepInput.pressure is not finite";
  if (has_prescribed)
    for (int d = 0; d < 3; ++d)
      for (int i = 0; i < m.n; ++i)
        if (in.prescribed(i, d) && !std::isfinite(in.prescribed_u(i, d)))
          return "StepInput.prescribed_u is not finite at a prescribed entry";
  if (in.spring_k.rows() != 0) {
    if (in.spring_k.rows() != m.n || in.spring_u.rows() != m.n)
      return "StepInput.spring_k and spring_u must both have one row per node";
    if (!in.spring_u.allFinite()) return "StepInput.spring_u is not finite";
    for (int d = 0; d < 3; ++d)
      for (int i = 0; i < m.n; ++i)
        if (!(in.spring_k(i, d) >= 0.0) || !std::isfinite(in.spring_k(i, d)))
          return "StepInput.spring_k must be finite and >= 0";
  }
  return nullptr;
}

// Constrained entries this step: held (fixed, infinite B) and prescribed by the input
// (sizes checked by check_input).
void build_constraints(const TissueModel& m, const StepInput& in, StepWorkspace& w) {
  const bool has_prescribed = in.prescribed.rows() == m.n && in.prescribed_u.rows() == m.n;
  for (int d = 0; d < 3; ++d)
    for (int i = 0; i < m.n; ++i) {
      const bool held = m.held(i, d) != 0;
      const bool presc = has_prescribed && in.prescribed(i, d) != 0;
      w.mask(i, d) = (held || presc) ? 1 : 0;
      w.u_fixed(i, d) = (!held && presc) ? in.prescribed_u(i, d) : 0.0;
    }
}

// Loads f (section 3): external forces and pressures, hydrostatic gravity (eq 9), inertia.
void build_loads(const TissueModel& m, const StepInput& in, SimState& s, StepWorkspace& w) {
  const NodeMat& A = s.area_vectors;
  if (in.force.rows() == m.n) w.force = in.force;
  else w.force.setZero();
  if (in.pressure.size() == m.n)
    for (int i = 0; i < m.n; ++i) w.force.row(i) -= in.pressure[i] * A.row(i);
  // Springs: k (u_s - u) with k on the matrix's diagonal (see the K_masked build), k u_s here.
  if (in.spring_k.rows() == m.n) w.force.array() += in.spring_k.array() * in.spring_u.array();
  // Area vectors and depths of the same geometry (the last refresh), so that between
  // refreshes the load is that of one surface: summed, exactly the weight.
  if (m.use_gravity) add_hydrostatic_loads(m, w.x_refresh, A, w.scratch, w.force);
  if (m.use_inertia) {
    const double h = m.dt;
    for (int i = 0; i < m.n; ++i) {
      const double mass = m.density * s.node_volumes[i];
      w.force.row(i) += (mass / (h * h)) * (w.u_start.row(i) + h * s.velocity.row(i)) +
                        (m.damping * mass / h) * w.u_start.row(i);
    }
  }
}

// Newton on the exact volume along the fluid's own response s (K s = a): u += dP' s and
// dP += dP', with dV/d(dP') = A(x) . s. K u - dP a = f still holds exactly, and V -> V_0.
// Returns the change of the volume row's right-hand side, sum dP' (a . s), so the reported
// residual is that of the corrected system.
double correct_volume(const TissueModel& m, SimState& s, StepWorkspace& w, LinearSolver& solver) {
  const int max_corr = m.solver.volume_corrections;
  double c_shift = 0.0;
  if (max_corr <= 0) return c_shift;
  const NodeMat* response = nullptr;
  for (int k = 0; k < max_corr; ++k) {
    const double err = m.rest_volume - enclosed_volume(s.x, m.rest.triangles, m.origin);
    if (std::abs(err) <= m.solver.volume_tolerance * m.rest_volume) return c_shift;
    if (!response) response = &solver.pressure_response(w.K_masked, w.a_free);
    if (!response->allFinite()) return c_shift;
    distributed_area_vectors(s.x, m.rest.triangles, w.area_now);
    double slope = 0.0;
    for (int d = 0; d < 3; ++d) slope += w.area_now.col(d).dot(response->col(d));
    if (!(slope > 0.0) || !std::isfinite(slope)) return c_shift;
    const double dp = err / slope;
    for (int d = 0; d < 3; ++d) c_shift += dp * w.a_free.col(d).dot(response->col(d));
    s.u.noalias() += dp * *response;
    s.x = m.rest.positions + s.u;
    s.pressure += dp;
  }
  return c_shift;
}

}  // namespace

void StepInput::clear() {
  force.setZero();
  pressure.setZero();
  prescribed.setZero();
  prescribed_u.setZero();
  spring_k.setZero();
  spring_u.setZero();
}

StepInput make_step_input(const TissueModel& m) {
  StepInput in;
  in.force = NodeMat::Zero(m.n, 3);
  in.pressure = Vec();
  in.prescribed = FlagMat::Zero(m.n, 3);
  in.prescribed_u = NodeMat::Zero(m.n, 3);
  return in;
}

SimState::SimState() = default;
SimState::~SimState() = default;
SimState::SimState(SimState&&) noexcept = default;
SimState& SimState::operator=(SimState&&) noexcept = default;

SimState make_sim_state(const TissueModel& m) {
  SimState s;
  const int n = m.n;
  s.u = NodeMat::Zero(n, 3);
  s.x = m.rest.positions;
  s.velocity = NodeMat::Zero(n, 3);
  s.area_vectors = NodeMat::Zero(n, 3);
  s.node_volumes = Vec::Zero(n);
  s.volume = m.rest_volume;
  s.reaction = NodeMat::Zero(n, 3);
  s.reaction_pressure = Vec::Zero(n);
  s.strain = NodeMat::Zero(n, 3);
  s.stress = NodeMat::Zero(n, 3);
  s.warnings.reserve(64);
  auto w = std::make_unique<StepWorkspace>();
  for (auto& k : w->K) k = m.pattern.matrix;
  for (auto& k : w->K_masked) k = m.pattern.matrix;
  w->mask = FlagMat::Zero(n, 3);
  w->last_springs = NodeMat::Zero(n, 3);
  w->last_mask = FlagMat::Constant(n, 3, 2);  // never equal: the first step builds K_masked
  w->u_fixed = NodeMat::Zero(n, 3);
  w->a_free = NodeMat::Zero(n, 3);
  w->force = NodeMat::Zero(n, 3);
  w->rhs = NodeMat::Zero(n, 3);
  w->u_start = NodeMat::Zero(n, 3);
  w->u_new = NodeMat::Zero(n, 3);
  w->area_now = NodeMat::Zero(n, 3);
  w->x_refresh = m.rest.positions;
  w->x_refresh_start = m.rest.positions;
  w->residual_prev = NodeMat::Zero(n, 3);
  w->velocity_start = NodeMat::Zero(n, 3);
  if (m.use_inertia) w->extra_diagonal = Vec::Zero(n);
  w->scratch = Vec::Zero(n);
  w->solver = make_linear_solver(m.solver);
  w->solver->analyze(m.pattern.matrix);
  s.work = std::move(w);
  return s;
}

namespace {

// Gives up on this step: the state goes back to the step's start and says why.
void fail_step(const TissueModel& m, SimState& s, const char* why) {
  rewind_step(m, s);
  s.failed = true;
  s.failure = why;
  add_warning(s, why);
}

// The direct solver as a fallback for a failed iterative solve; factorised lazily.
LinearSolver& fallback_solver(const TissueModel& m, StepWorkspace& w) {
  if (!w.fallback) {
    SolverSettings fs = m.solver;
    fs.method = SolverMethod::direct;
    w.fallback = make_linear_solver(fs);
    w.fallback->analyze(m.pattern.matrix);
    w.fallback_stale = true;
  }
  if (w.fallback_stale) {
    w.fallback->matrices_changed(w.K_masked);
    w.fallback_stale = false;
  }
  return *w.fallback;
}

}  // namespace

void rewind_step(const TissueModel& m, SimState& s) {
  StepWorkspace& w = *s.work;
  s.u = w.u_start;
  s.x = m.rest.positions + s.u;
  s.velocity = w.velocity_start;
  s.pressure = w.pressure_start;
  s.step = w.step_start;
  s.time = w.time_start;
  if (w.refreshed_in_step) {
    // K, A_i, V_i were rebuilt during the step: bring back those of the step's start (the
    // next step refreshes anyway when the counter says so, or when there was no geometry).
    if (!w.have_geometry_start) {
      w.have_geometry = false;
    } else if (w.since_refresh_start < m.solver.refresh_every) {
      w.x_refresh = w.x_refresh_start;
      refresh_geometry(m, w.x_refresh, s, w);
    }
    w.refreshed_in_step = false;
  }
  w.steps_since_refresh = w.since_refresh_start;
}

void step(const TissueModel& m, const StepInput& in, SimState& s) {
  const auto t_step = Clock::now();
  StepWorkspace& w = *s.work;
  StepStats& st = s.stats;
  st.iterations = 0;
  st.converged = true;
  st.nonlinear_iterations = 0;
  st.nonlinear_change = 0;
  st.relaxation = 1;
  st.fallbacks = 0;
  st.fallback = nullptr;
  st.refreshed = false;
  st.factorizations = 0;
  st.assemble_ms = st.solve_ms = st.stress_ms = 0;
  s.failed = false;
  s.failure.clear();
  // The start of the step, for rewind_step().
  w.u_start = s.u;
  w.velocity_start = s.velocity;
  w.pressure_start = s.pressure;
  w.step_start = s.step;
  w.time_start = s.time;
  w.since_refresh_start = w.steps_since_refresh;
  w.have_geometry_start = w.have_geometry;
  w.refreshed_in_step = false;
  if (m.solver.refresh_every > 1 && m.solver.nonlinear_iterations > 1) w.x_refresh_start = w.x_refresh;
  if (const char* bad = check_input(m, in)) {
    fail_step(m, s, bad);
    return;
  }
  double current_volume = 0.0;
  double last_c = 0.0;
  double last_du = 0.0;
  double omega = 1.0;  // Aitken relaxation of the nonlinear (fixed-point) iteration

  const int max_it = m.solver.nonlinear_iterations;
  for (int it = 0; it < max_it; ++it) {
    const auto t_asm = Clock::now();
    const bool refresh = !w.have_geometry || it > 0 || w.steps_since_refresh >= m.solver.refresh_every;
    current_volume = -1.0;
    if (refresh) {
      current_volume = refresh_geometry(m, s.x, s, w);
      if (current_volume > 0.0) {
        st.refreshed = true;
        w.refreshed_in_step = true;
        ++st.total_refreshes;
      } else if (!w.have_geometry) {
        fail_step(m, s, "the geometry encloses no positive volume");
        return;
      } else {
        add_warning(s, "the deformed surface encloses no positive volume: kept the last valid geometry");
        ++st.fallbacks;
        st.fallback = "inverted geometry: kept the last valid one";
      }
    }
    if (current_volume <= 0.0) current_volume = enclosed_volume(s.x, m.rest.triangles, m.origin);

    build_constraints(m, in, w);
    const bool springs = in.spring_k.rows() == m.n;
    const bool springs_changed = springs ? in.spring_k != w.last_springs : !w.last_springs.isZero(0.0);
    if (w.matrix_dirty || w.mask != w.last_mask || springs_changed) {
      for (int d = 0; d < 3; ++d) mask_constrained(w.K[d], w.mask.col(d).data(), w.K_masked[d]);
      if (springs) {
        w.last_springs = in.spring_k;
        for (int d = 0; d < 3; ++d) {
          double* diag = w.K_masked[d].valuePtr();
          for (int i = 0; i < m.n; ++i)
            if (!w.mask(i, d)) diag[m.pattern.diagonal[i]] += in.spring_k(i, d);
        }
      } else {
        w.last_springs.setZero();
      }
      w.a_free = s.area_vectors;
      for (int d = 0; d < 3; ++d)
        for (int i = 0; i < m.n; ++i)
          if (w.mask(i, d)) w.a_free(i, d) = 0.0;
      w.solver->matrices_changed(w.K_masked);
      w.fallback_stale = true;
      w.last_mask = w.mask;
      w.matrix_dirty = false;
    }
    build_loads(m, in, s, w);
    for (int d = 0; d < 3; ++d)
      eliminate_rhs(w.K[d], w.mask.col(d).data(), w.force.col(d).data(), w.u_fixed.col(d).data(),
                    w.rhs.col(d).data());
    // Eq (11) as a Newton step on the exact volume: a.u^{n+1} = V_0 - V(x^n) + a.u^n,
    // with the constrained part moved to the right.
    double c = m.rest_volume - current_volume;
    for (int d = 0; d < 3; ++d) {
      c += s.area_vectors.col(d).dot(s.u.col(d));
      for (int i = 0; i < m.n; ++i)
        if (w.mask(i, d)) c -= s.area_vectors(i, d) * w.u_fixed(i, d);
    }
    last_c = c;
    st.assemble_ms += ms_since(t_asm);

    const auto t_solve = Clock::now();
    LinearSolver* solver = w.solver.get();
    w.u_new = s.u;
    double p_new = s.pressure;
    SolveReport rep = solver->solve(w.K_masked, w.rhs, w.a_free, c, m.volume_constraint, w.u_new, p_new);
    st.iterations += rep.iterations;
    st.factorizations += rep.factorizations;
    bool ok = rep.converged && w.u_new.allFinite() && std::isfinite(p_new);
    if (!ok && m.solver.method != SolverMethod::direct) {
      // Fallback: the same system by the direct solver (exact up to round-off).
      st.fallback = rep.converged ? "iterative solve gave a non-finite result: redone by the direct solver"
                                  : "iterative solve did not converge: redone by the direct solver";
      ++st.fallbacks;
      add_warning(s, st.fallback);
      solver = &fallback_solver(m, w);
      w.u_new = s.u;
      p_new = s.pressure;
      rep = solver->solve(w.K_masked, w.rhs, w.a_free, c, m.volume_constraint, w.u_new, p_new);
      st.factorizations += rep.factorizations;
      ok = rep.converged && w.u_new.allFinite() && std::isfinite(p_new);
    }
    st.solve_ms += ms_since(t_solve);
    ++st.nonlinear_iterations;
    if (!ok) {
      fail_step(m, s, "no solver could solve the step (singular or non-finite system)");
      return;
    }
    // Constrained entries take their prescribed values exactly (an iterative solve meets
    // its identity rows only to tolerance).
    for (int d = 0; d < 3; ++d)
      for (int i = 0; i < m.n; ++i)
        if (w.mask(i, d)) w.u_new(i, d) = w.u_fixed(i, d);
    // Nonlinear iterations are a fixed point u <- G(u) on the geometry. Aitken's relaxation
    // (the first solve, the load increment, is taken whole): u += omega (G(u) - u), omega
    // from the last two residuals; it saves iterations where the plain iteration converges.
    w.u_new -= s.u;  // the fixed-point residual r = G(u) - u
    const double du = w.u_new.cwiseAbs().maxCoeff();
    if (it >= 2 && du > last_du && du > 10.0 * m.solver.nonlinear_tolerance * m.size) {
      // Diverging: past some deformation the geometric fixed point loses stability (its
      // contraction factor passes 1). Keep the current iterate, the best so far.
      st.nonlinear_change = du / m.size;
      break;
    }
    last_du = du;
    if (it > 0) {
      const double num = (w.residual_prev.array() * (w.u_new - w.residual_prev).array()).sum();
      const double den = (w.u_new - w.residual_prev).squaredNorm();
      if (den > 0.0 && std::isfinite(num)) omega = std::clamp(-omega * num / den, 0.05, 1.0);
    }
    st.relaxation = omega;
    st.nonlinear_change = du / m.size;
    if (it + 1 < max_it) w.residual_prev = w.u_new;
    s.u.noalias() += omega * w.u_new;
    s.pressure += omega * (p_new - s.pressure);
    s.x = m.rest.positions + s.u;
    if (m.volume_constraint) {
      last_c += correct_volume(m, s, w, *solver);
      // s is zero on constrained entries only to solver tolerance: pin them again.
      for (int d = 0; d < 3; ++d)
        for (int i = 0; i < m.n; ++i)
          if (w.mask(i, d)) s.u(i, d) = w.u_fixed(i, d);
      s.x = m.rest.positions + s.u;
    }
    if (it + 1 < max_it && du <= m.solver.nonlinear_tolerance * m.size) break;
  }
  ++w.steps_since_refresh;
  st.total_factorizations += st.factorizations;
  st.total_fallbacks += st.fallbacks;

  // Results: volume, reactions at constrained entries, contact pressure, strain and stress.
  s.volume = enclosed_volume(s.x, m.rest.triangles, m.origin);
  s.volume_rel_error = (s.volume - m.rest_volume) / m.rest_volume;
  // True residual of the last solve's eliminated 3N+1 system (volume row scaled like the
  // reference solver's), and the reactions on the unmasked system.
  const double alpha = pressure_scale(w.K_masked, w.a_free);
  double res2 = 0.0, rhs2 = 0.0, vol_row = -last_c;
  for (int d = 0; d < 3; ++d) {
    symmetric_multiply(w.K_masked[d], s.u.col(d).data(), w.scratch.data());
    w.scratch.noalias() -= s.pressure * w.a_free.col(d) + w.rhs.col(d);
    res2 += w.scratch.squaredNorm();
    rhs2 += w.rhs.col(d).squaredNorm();
    vol_row += w.a_free.col(d).dot(s.u.col(d));
    symmetric_multiply_rows(w.K[d], w.mask.col(d).data(), s.u.col(d).data(), w.scratch.data());  // constrained rows only
    for (int i = 0; i < m.n; ++i)
      s.reaction(i, d) =
          w.mask(i, d) ? w.scratch[i] - s.pressure * s.area_vectors(i, d) - w.force(i, d) : 0.0;
  }
  if (m.volume_constraint) {
    res2 += alpha * alpha * vol_row * vol_row;
    rhs2 += alpha * alpha * last_c * last_c;
  }
  st.residual = rhs2 > 0 ? std::sqrt(res2 / rhs2) : std::sqrt(res2);
  for (int i = 0; i < m.n; ++i) {
    const double a = s.area_vectors.row(i).norm();
    s.reaction_pressure[i] = a > 0 ? s.reaction.row(i).norm() / a : 0.0;
  }
  if (m.compute_stress) {
    const auto t_stress = Clock::now();
    compute_strain_stress(m, s);
    st.stress_ms = ms_since(t_stress);
  }
  s.velocity = (s.u - w.u_start) / m.dt;
  ++s.step;
  s.time += m.dt;
  st.step_ms = ms_since(t_step);
}

}  // namespace vdm
