#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <type_traits>

#include "engine/all_finite.hpp"
#include "engine/capsule_rotations.hpp"
#include "engine/geometry.hpp"
#include "engine/loads.hpp"
#include "engine/sim_state.hpp"
#include "engine/simd2.hpp"
#include "engine/step_results.hpp"
#include "engine/step_workspace.hpp"
#include "engine/stopwatch.hpp"
#include "engine/stiffness.hpp"
#include "engine/volume_along.hpp"
#include "engine/warnings.hpp"

namespace vdm {
namespace {

// Each distinct trouble is listed once (a repeat allocates nothing).
void add_warning(SimState& s, const char* what) {
  for (const std::string& w : s.warnings)
    if (w == what) return;
  if (s.warnings.size() < kMaxWarnings) s.warnings.emplace_back(what);
}

// The volume enclosed at x, with x and its area sums left in w.packed: a volume check at the
// end of a step leaves them, and the next step's refresh at the same positions (bit for bit)
// only unpacks them instead of going over the triangles again.
double packed_geometry(const TissueModel& m, const NodeMat& x, StepWorkspace& w) {
  if (!(w.packed_valid && packed_positions_equal(x, w.packed))) {
    w.packed_volume = packed_area_sums_and_volume(x, m.rest.triangles, m.origin, w.packed);
    w.packed_valid = true;
  }
  return w.packed_volume;
}

// Step 1 of section 4: A_i, V_i, V and every K^d at the positions `x`. Returns V. A geometry
// that encloses no positive volume (inverted mid-run) would make K indefinite: then the last
// valid geometry is kept (returns -1 after restoring it) and the caller says so.
double refresh_geometry(const TissueModel& m, const NodeMat& x, SimState& s, StepWorkspace& w) {
  const double v = packed_geometry(m, x, w);
  // A_i and |A_i| in one pass; their sum is finite only when every A_i is.
  const AreaNormSums sums = unpack_area_vectors_and_norms(w.packed, s.area_vectors, w.area_norms);
  if (!(v > 0.0) || !std::isfinite(v) || !std::isfinite(sums.total)) {
    if (w.have_geometry) {  // back to the geometry K was built from
      const double v_refresh = packed_geometry(m, w.x_refresh, w);
      const AreaNormSums valid = unpack_area_vectors_and_norms(w.packed, s.area_vectors, w.area_norms);
      distributed_volumes_from_norms(w.area_norms, valid, v_refresh, s.node_volumes);
    }
    return -1.0;
  }
  const VolumeScale volume_scale = distributed_volumes_from_norms(w.area_norms, sums, v, s.node_volumes);
  if (m.use_inertia) {
    const double h = m.dt;
    for (int i = 0; i < m.n; ++i) {
      const double mass = m.density * s.node_volumes[i];
      w.extra_diagonal[i] = mass / (h * h) + m.damping * mass / h;
    }
  }
  assemble_stiffness(m, s.area_vectors, w.area_norms, s.node_volumes, volume_scale, w.extra_diagonal, w.K, w.scratch);
  if (&x != &w.x_refresh) w.x_refresh = x;
  w.volume_at_refresh = v;
  w.matrix_dirty = true;
  w.have_geometry = true;
  w.steps_since_refresh = 0;
  return v;
}

// Scratch for compute_step_results(): the solver's (spare_doubles), else the workspace's own
// (sized by make_sim_state() when the solver lends none).
double* results_rows(const TissueModel& m, StepWorkspace& w) {
  double* rows = w.solver->spare_doubles(result_rows_size(m.n));
  return rows ? rows : w.result_rows.data();
}

// Whether prescribed_u is finite wherever prescribed is set. The flags are read 8 at a time:
// most are zero (a few held or driven nodes), and a zero word needs no look at its values.
bool prescribed_finite(const StepInput& in) {
  const size_t count = size_t(in.prescribed.size());
  const std::uint8_t* flags = in.prescribed.data();
  const double* values = in.prescribed_u.data();  // the same N x 3 column-major layout
  size_t k = 0;
  for (; k + 8 <= count; k += 8) {
    std::uint64_t word;
    std::memcpy(&word, flags + k, sizeof word);
    if (word == 0) continue;
    for (size_t j = k; j < k + 8; ++j)
      if (flags[j] && !std::isfinite(values[j])) return false;
  }
  for (; k < count; ++k)
    if (flags[k] && !std::isfinite(values[k])) return false;
  return true;
}

// The input's arrays must be sized for the model and finite where used. Returns the reason
// when not (static text), null when the input is fine.
const char* check_input(const TissueModel& m, const StepInput& in) {
  const bool has_prescribed = in.prescribed.rows() != 0;
  if (has_prescribed && in.prescribed.rows() != m.n) return "StepInput.prescribed has the wrong number of rows";
  if (has_prescribed && in.prescribed_u.rows() != m.n)
    return "StepInput.prescribed_u has the wrong number of rows";
  if (!(in.tolerance >= 0.0) || !std::isfinite(in.tolerance) || in.tolerance >= 1.0)
    return "StepInput.tolerance must be 0 (the model's) or a relative residual in (0, 1)";
  if (in.force.rows() != 0 && in.force.rows() != m.n) return "StepInput.force has the wrong number of rows";
  if (in.pressure.size() != 0 && in.pressure.size() != m.n) return "StepInput.pressure has the wrong size";
  if (in.force.rows() == m.n && !all_finite(in.force)) return "StepInput.force is not finite";
  if (in.pressure.size() == m.n && !all_finite(in.pressure.data(), size_t(in.pressure.size()))) return "StepInput.pressure is not finite";
  if (has_prescribed && !prescribed_finite(in)) return "StepInput.prescribed_u is not finite at a prescribed entry";
  if (in.spring_k.rows() != 0) {
    if (in.spring_k.rows() != m.n || in.spring_u.rows() != m.n)
      return "StepInput.spring_k and spring_u must both have one row per node";
    if (!all_finite(in.spring_u)) return "StepInput.spring_u is not finite";
    for (int d = 0; d < 3; ++d)
      for (int i = 0; i < m.n; ++i)
        if (!(in.spring_k(i, d) >= 0.0) || !std::isfinite(in.spring_k(i, d)))
          return "StepInput.spring_k must be finite and >= 0";
  }
  return nullptr;
}

// x . y over n entries, in pairs (four independent sums).
double dot(const double* x, const double* y, size_t n) {
  using simd::V2;
  V2 s0 = {0.0, 0.0}, s1 = {0.0, 0.0};
  size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    s0 += simd::load2(x + i) * simd::load2(y + i);
    s1 += simd::load2(x + i + 2) * simd::load2(y + i + 2);
  }
  const V2 s = s0 + s1;
  double sum = s[0] + s[1];
  for (; i < n; ++i) sum += x[i] * y[i];
  return sum;
}

// Constrained entries this step: held (fixed, infinite B) and prescribed by the input
// (sizes checked by check_input), in w.mask; the N x 3 flags as one run of 3 N, 16 at a time.
// Returns whether they differ from last_mask. The prescribed entries that are not held (few:
// the contact's) go to w.prescribed_entries, their values to w.u_fixed (zero elsewhere). Also
// adds up a . u over all entries minus a . u_fixed (`a_u`): the volume row's right-hand side
// needs it.
bool build_constraints(const TissueModel& m, const StepInput& in, const NodeMat& a, const NodeMat& u, StepWorkspace& w,
                       double& a_u) {
  const bool has_prescribed = in.prescribed.rows() == m.n && in.prescribed_u.rows() == m.n;
  double* fixed = w.u_fixed.data();
  // The last step's values, and what they moved into rhs (eliminate_rhs()).
  if (w.rhs_zero_elsewhere) clear_prescribed_support(m.neighbours, w.prescribed_entries, w.rhs);
  for (const int k : w.prescribed_entries) fixed[k] = 0.0;
  w.prescribed_entries.clear();
  const size_t count = 3 * size_t(m.n);
  const std::uint8_t* held = m.held.data();
  const std::uint8_t* presc = has_prescribed ? in.prescribed.data() : nullptr;
  const std::uint8_t* last = w.last_mask.data();
  std::uint8_t* mask = w.mask.data();
  auto load16 = [](const std::uint8_t* p) { return _mm_loadu_si128(reinterpret_cast<const __m128i*>(p)); };
  const __m128i zero = _mm_setzero_si128(), one = _mm_set1_epi8(1);
  __m128i differ = zero;
  size_t k = 0;
  for (; k + 16 <= count; k += 16) {
    const __m128i not_held = _mm_cmpeq_epi8(load16(held + k), zero);  // bytes: all ones or zero
    __m128i free = not_held;
    if (presc) {
      const __m128i not_prescribed = _mm_cmpeq_epi8(load16(presc + k), zero);
      free = _mm_and_si128(not_held, not_prescribed);
      for (int bits = _mm_movemask_epi8(_mm_andnot_si128(not_prescribed, not_held)); bits != 0; bits &= bits - 1)
        w.prescribed_entries.push_back(int(k) + __builtin_ctz(unsigned(bits)));
    }
    const __m128i c = _mm_andnot_si128(free, one);  // 1: constrained
    _mm_storeu_si128(reinterpret_cast<__m128i*>(mask + k), c);
    differ = _mm_or_si128(differ, _mm_xor_si128(c, load16(last + k)));
  }
  bool changed = _mm_movemask_epi8(_mm_cmpeq_epi8(differ, zero)) != 0xFFFF;
  for (; k < count; ++k) {
    const bool h = held[k] != 0, p = presc && presc[k] != 0;
    if (p && !h) w.prescribed_entries.push_back(int(k));
    mask[k] = std::uint8_t(h || p);
    changed = changed || mask[k] != last[k];
  }
  const double* ad = a.data();
  double moved = 0.0;  // a . u_fixed
  if (has_prescribed) {
    const double* pu = in.prescribed_u.data();
    for (const int e : w.prescribed_entries) {
      fixed[e] = pu[e];
      moved += ad[e] * pu[e];
    }
  }
  a_u = dot(ad, u.data(), count) - moved;
  return changed;
}

// The system of K with the entries of last_mask constrained and last_springs on the free
// diagonal.
AxisSystem axis_system(const TissueModel& m, const StepWorkspace& w) {
  return {&w.K, &m.pattern, &w.last_mask, w.last_springs_any ? &w.last_springs : nullptr};
}

// The solver told of the system (K, last_mask, last_springs); the free area vectors and the
// eliminated matrices' mean diagonal, in one pass.
void update_solver_system(const TissueModel& m, const SimState& s, StepWorkspace& w, bool step_start = false) {
  AxisSystem system = axis_system(m, w);
  system.step_start = step_start;
  w.mean_diagonal = eliminated_mean_diagonal(system, &s.area_vectors, &w.a_free);
  w.solver->matrices_changed(system);
  w.fallback_stale = true;
}

// Loads f (section 3): external forces and pressures, hydrostatic gravity (eq 9), inertia.
// Returns false, and leaves w.force as it was, when there are none (f = 0: most contact
// steps), so that no pass zeroes it and none reads it.
bool build_loads(const TissueModel& m, const StepInput& in, SimState& s, StepWorkspace& w) {
  const bool corotational = m.capsule == CapsuleForm::corotational;
  const bool any = in.force.rows() == m.n || in.pressure.size() == m.n || in.spring_k.rows() == m.n ||
                   m.use_gravity || m.use_inertia || corotational;
  if (!any) return false;
  const NodeMat& A = s.area_vectors;
  if (in.force.rows() == m.n) w.force = in.force;
  else w.force.setZero();
  if (in.pressure.size() == m.n)
    for (int i = 0; i < m.n; ++i) w.force.row(i) -= in.pressure[i] * A.row(i);
  // Springs: k (u_s - u) with k on the matrix's diagonal (the solver's system), k u_s here.
  if (in.spring_k.rows() == m.n) w.force.array() += in.spring_k.array() * in.spring_u.array();
  // Area vectors and depths of the same geometry (the last refresh), so that between
  // refreshes the load is that of one surface: summed, exactly the weight.
  if (m.use_gravity) add_hydrostatic_loads(m, w.x_refresh, A, w.scratch, w.force);
  // The corotational capsule's rotations, fitted at the current positions (docs/model.md).
  if (corotational) {
    fit_capsule_rotations(m, s.x, w.rotations);
    add_corotation_load(m, w.rotations, w.force);
  }
  if (m.use_inertia) {
    const double h = m.dt;
    for (int i = 0; i < m.n; ++i) {
      const double mass = m.density * s.node_volumes[i];
      w.force.row(i) += (mass / (h * h)) * (w.start.u.row(i) + h * w.start.velocity.row(i)) +
                        (m.damping * mass / h) * w.start.u.row(i);
    }
  }
  return true;
}

// The constrained entries' u = u_fixed exactly, and x = X + u there (after a pass that moved
// every entry: u + (u_fixed - u) may be an ulp off).
void pin_constrained(const StepWorkspace& w, const NodeMat& rest, NodeMat& u, NodeMat& x) {
  const double* fixed = w.u_fixed.data();
  const double* X = rest.data();
  double* ud = u.data();
  double* xd = x.data();
  for (const std::vector<int>* entries : {&w.held_entries, &w.prescribed_entries})
    for (const int k : *entries) {
      ud[k] = fixed[k];
      xd[k] = X[k] + ud[k];
    }
}

// What pin_and_difference() found.
struct Difference {
  double largest = 0.0;  // max |r|
  bool finite = false;   // every free entry of the solve's result was finite
  bool u_finite = false; // (with `x`) every entry of u as written is finite
};

// The solve's result `u_new` with the constrained entries set to their values, minus u0: the
// fixed-point residual r, in place (only when `keep_r`: the nonlinear iterations read it;
// otherwise u_new is left with the result). Also whether the result is finite on the free
// entries (x * 0 summed, as all_finite(): the constrained ones take their values anyway).
// With `x` (a step's first solve, taken whole: omega = 1) also advance_positions() in the
// same pass: u = u0 + r on the free entries, u_fixed on the constrained ones, x = rest + u
// (the same values, bit for bit; u0 is the step's start, swapped out of u: u is written
// whole), and the velocity (u - u0) / dt as the step's end makes it (the same bits), with
// `velocity`; and whether u is finite. Without `x`, u0 is u.
// The N x 3 arrays as runs of 3 N entries: the constrained ones set before, and the few
// prescribed ones again after (a held one's u0 + (+0 - u0) is +0 exactly already).
Difference pin_and_difference(const StepWorkspace& w, const NodeMat& u0, NodeMat& u, NodeMat& u_new,
                              const NodeMat& rest, bool keep_r, NodeMat* x, NodeMat* velocity = nullptr,
                              double inv_dt = 0.0) {
  const double* fixed = w.u_fixed.data();
  double* r = u_new.data();
  // The held entries' value is +0 (u_fixed there; the solvers leave them at +0 anyway: their
  // rows and columns are the identity's and their right-hand side 0, but like the prescribed
  // ones they take their value whatever the solve gave). Their list is long (a fixed
  // underside: 13 % of the entries in the probe scene): written without reading u_fixed.
  for (const int k : w.prescribed_entries) r[k] = fixed[k];
  for (const int k : w.held_entries) r[k] = 0.0;
  const size_t count = size_t(u.size());
  double* ud = u.data();
  using simd::V2;
  const V2 zero = {0.0, 0.0};
  V2 largest = zero, nan_in = zero, nan_u = zero;  // x * 0 summed: 0 while all are finite
  size_t i = 0;
  if (x) {
    const double* X = rest.data();
    const double* u0d = u0.data();
    double* xd = x->data();
    auto pass = [&](double* vd, auto keep) {
      const V2 inv2 = simd::splat(inv_dt);
      auto two = [&](size_t k, V2 solved) {  // entries k and k + 1
        const V2 u0i = simd::load2(u0d + k);
        nan_in += solved * zero;
        const V2 ri = solved - u0i;
        if (keep) simd::store2(r + k, ri);
        largest = simd::max2(largest, simd::abs2(ri));
        const V2 ui = u0i + ri;
        nan_u += ui * zero;
        simd::store2(ud + k, ui);
        simd::store2(xd + k, simd::load2(X + k) + ui);
        if (vd) simd::store2(vd + k, (ui - u0i) * inv2);
      };
      for (; i + 2 <= count; i += 2) two(i, simd::load2(r + i));
      for (; i < count; ++i) {
        nan_in[0] += r[i] * 0.0;
        const double ri = r[i] - u0d[i];
        if (keep) r[i] = ri;
        largest[0] = std::max(largest[0], std::abs(ri));
        ud[i] = u0d[i] + ri;
        nan_u[0] += ud[i] * 0.0;
        xd[i] = X[i] + ud[i];
        if (vd) vd[i] = (ud[i] - u0d[i]) * inv_dt;
      }
    };
    // (copies of the loop: no test per entry in them)
    if (keep_r) {
      if (velocity) pass(velocity->data(), std::true_type());
      else pass(nullptr, std::true_type());
    } else {
      if (velocity) pass(velocity->data(), std::false_type());
      else pass(nullptr, std::false_type());
    }
    // The prescribed entries pinned to their values (u0 + (u_fixed - u0) may be an ulp off);
    // a held one's u0 + (+0 - u0) is +0 exactly, its x X + 0 and its velocity -u0 / dt as
    // pinning would make them.
    double* vd = velocity ? velocity->data() : nullptr;
    for (const int k : w.prescribed_entries) {  // (finite values: check_input)
      ud[k] = fixed[k];
      xd[k] = X[k] + ud[k];
      if (vd) vd[k] = (ud[k] - u0d[k]) * inv_dt;
    }
  } else {
    for (; i + 2 <= count; i += 2) {
      const V2 solved = simd::load2(r + i);
      nan_in += solved * zero;
      const V2 ri = solved - simd::load2(ud + i);
      simd::store2(r + i, ri);
      largest = simd::max2(largest, simd::abs2(ri));
    }
    for (; i < count; ++i) {
      nan_in[0] += r[i] * 0.0;
      r[i] -= ud[i];
      largest[0] = std::max(largest[0], std::abs(r[i]));
    }
  }
  Difference d;
  d.largest = std::max(largest[0], largest[1]);
  d.finite = nan_in[0] + nan_in[1] == 0.0;
  d.u_finite = x && nan_u[0] + nan_u[1] == 0.0;
  return d;
}

// u += omega r on the free entries, u = u_fixed exactly on the constrained ones, and x = X +
// u, in one pass over all entries and one over the constrained.
void advance_positions(const StepWorkspace& w, const NodeMat& rest, double omega, const NodeMat& r, NodeMat& u,
                       NodeMat& x) {
  const size_t count = size_t(u.size());
  const double* X = rest.data();
  const double* dr = r.data();
  double* ud = u.data();
  double* xd = x.data();
  for (size_t i = 0; i < count; ++i) {
    ud[i] += omega * dr[i];
    xd[i] = X[i] + ud[i];
  }
  pin_constrained(w, rest, u, x);
}

// Newton on the exact volume along the fluid's own response s (K s = a): u += dP' s and
// dP += dP', with dV/d(dP') = A(x) . s. K u - dP a = f still holds exactly, and V -> V_0.
// The first check measures the volume and its slope along s in one pass (engine/volume_along).
// The constrained entries stay at their values (s is zero there only to the solver's
// tolerance): they do not move, and do not count in the slope.
// Returns the change of the volume row's right-hand side, sum dP' (a . s), so the reported
// residual is that of the corrected system.
// `volume` gets the enclosed volume at the final positions when the last check measured it
// there, NaN otherwise.
// Which check is made first is a guess, from the last step: volume_along when a correction
// is likely, else the plain volume (packed_geometry, whose triangle pass the next step's
// refresh reuses when it passes). Both measure the same volume, bit for bit.
double correct_volume(const TissueModel& m, SimState& s, StepWorkspace& w, LinearSolver& solver, double& volume,
                      bool& moved) {
  const int max_corr = m.solver.volume_corrections;
  double c_shift = 0.0;
  volume = std::numeric_limits<double>::quiet_NaN();
  if (max_corr <= 0) return c_shift;
  // With the volume constraint every solver has s from its solve: this costs nothing.
  // (Not checked for finiteness: a non-finite free entry makes the slope below non-finite,
  // and the constrained entries are neither read nor moved.)
  const NodeMat& response = solver.pressure_response(w.a_free);
  const double tolerance = m.solver.volume_tolerance * m.rest_volume;
  double as = std::numeric_limits<double>::quiet_NaN();  // a . s, on the first correction
  for (int k = 0; k < max_corr; ++k) {
    // After a correction the volume is usually restored, and a solve usually meets a loose
    // tolerance when the last one did: checked first without the slope (a third of
    // volume_along's cost), which is measured only when a correction is due.
    if (k > 0 || w.volume_met) {
      const double v = packed_geometry(m, s.x, w);  // the next refresh's triangle pass, if it passes
      if (std::abs(m.rest_volume - v) <= tolerance) {
        volume = v;
        return c_shift;
      }
      w.volume_met = false;
    }
    w.packed_valid = false;  // volume_along's rows go there
    const VolumeAlong v = volume_along(s.x, response, &w.mask, m.rest.triangles, m.origin, w.packed);
    const double err = m.rest_volume - v.volume;
    if (std::abs(err) <= tolerance) {
      volume = v.volume;
      w.volume_met = k == 0;
      return c_shift;
    }
    // A(x).s not positive: the surface is locally inverted (step() then splits the step).
    if (!(v.slope > 0.0) || !std::isfinite(v.slope)) return c_shift;
    const double dp = err / v.slope;
    if (std::isnan(as)) {
      as = 0.0;
      for (int d = 0; d < 3; ++d) as += w.a_free.col(d).dot(response.col(d));
    }
    c_shift += dp * as;
    moved = true;
    w.u_verified_finite = false;
    for (int d = 0; d < 3; ++d) {
      const std::uint8_t* mask = w.mask.col(d).data();
      const double* r = response.col(d).data();
      const double* rest = m.rest.positions.col(d).data();
      double* u = s.u.col(d).data();
      double* x = s.x.col(d).data();
      for (int i = 0; i < m.n; ++i)
        if (!mask[i]) {
          u[i] += dp * r[i];
          x[i] = rest[i] + u[i];
        }
    }
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
  tolerance = 0.0;
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
  s.warnings.reserve(kMaxWarnings);
  auto w = std::make_unique<StepWorkspace>();
  w->K.weight = Vec::Zero(Eigen::Index(m.edges.size()));
  w->K.diagonal = NodeMat::Zero(n, 3);
  w->mask = FlagMat::Zero(n, 3);
  for (int k = 0; k < 3 * n; ++k)
    if (m.held.data()[k]) w->held_entries.push_back(k);
  w->prescribed_entries.reserve(3 * size_t(n));
  w->last_mask = FlagMat::Constant(n, 3, 2);  // never equal: the first step tells the solver
  w->u_fixed = NodeMat::Zero(n, 3);
  w->a_free = NodeMat::Zero(n, 3);
  w->force = NodeMat::Zero(n, 3);
  if (m.capsule == CapsuleForm::corotational) w->rotations.assign(9 * size_t(n), 0.0);
  w->rhs = NodeMat::Zero(n, 3);
  w->start.u = NodeMat::Zero(n, 3);
  w->u_new = NodeMat::Zero(n, 3);
  w->x_refresh = m.rest.positions;
  // Only what the settings use: the rewind point's geometry positions (kept when the step
  // refreshes inside itself between periodic refreshes) and Aitken's last residual.
  const bool nonlinear = m.solver.nonlinear_iterations > 1;
  if (nonlinear && m.solver.refresh_every > 1) w->start.x_refresh = m.rest.positions;
  if (nonlinear) w->residual_prev = NodeMat::Zero(n, 3);
  w->start.velocity = NodeMat::Zero(n, 3);
  if (m.use_inertia) w->extra_diagonal = Vec::Zero(n);
  w->scratch = Vec::Zero(n);
  w->area_norms = Vec::Zero(n);
  w->packed.assign(6 * size_t(n), 0.0);
  // sub_input and whole_*: made by the first step done in parts (make_halving_arrays);
  // last_springs, force_* and pressure_*: by the first step that has them.
  w->solver = make_linear_solver(m.solver);
  w->solver->analyze(m.pattern);
  // The results pass's rows: in the solver's scratch when it lends some, else its own.
  if (!w->solver->spare_doubles(result_rows_size(n))) w->result_rows.assign(result_rows_size(n), 0.0);
  s.work = std::move(w);
  return s;
}

namespace {

// Gives up on this step: the state goes back to the step's start and says why.
void fail_step(const TissueModel& m, SimState& s, const char* why) {
  rewind_step(m, s);
  s.work->rewound = false;  // the geometry of a failed attempt is rebuilt, not trusted
  s.work->failure_reason = why;
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
    w.fallback->analyze(m.pattern);
    w.fallback_stale = true;
  }
  if (w.fallback_stale) {
    w.fallback->matrices_changed(axis_system(m, w));
    w.fallback_stale = false;
  }
  return *w.fallback;
}

}  // namespace

void rebuild_matrices(const TissueModel& m, SimState& s) {
  StepWorkspace& w = *s.work;
  if (!w.have_geometry) return;
  const int since = w.steps_since_refresh;
  const bool dirty = w.matrix_dirty;
  refresh_geometry(m, w.x_refresh, s, w);
  w.steps_since_refresh = since;
  w.matrix_dirty = dirty;
  if (dirty || w.last_mask(0, 0) > 1) return;  // the next step tells the solver
  update_solver_system(m, s, w);  // with the mask and springs of the last step
}

void rewind_step(const TissueModel& m, SimState& s) {
  StepWorkspace& w = *s.work;
  w.rewound = true;
  w.results_pending = false;  // those of the step undone
  w.u_verified_finite = false;
  s.u = w.start.u;
  s.x = m.rest.positions + s.u;
  s.velocity = w.start.velocity;
  s.pressure = w.start.pressure;
  s.step = w.start.step;
  s.time = w.start.time;
  if (w.refreshed_in_step) {
    // K, A_i, V_i were rebuilt during the step: bring back those of the step's start (the
    // next step refreshes anyway when the counter says so, or when there was no geometry).
    if (!w.start.have_geometry) {
      w.have_geometry = false;
    } else if (w.start.since_refresh < m.solver.refresh_every) {
      w.x_refresh = w.start.x_refresh;
      refresh_geometry(m, w.x_refresh, s, w);
    }
    w.refreshed_in_step = false;
  }
  w.steps_since_refresh = w.start.since_refresh;
  if (w.input_remembered) {  // the step's loads are no longer the last ones
    w.force_last.swap(w.force_prev);
    w.pressure_last.swap(w.pressure_prev);
    std::swap(w.force_last_zero, w.force_prev_zero);
    std::swap(w.pressure_last_zero, w.pressure_prev_zero);
    w.input_remembered = false;
  }
}

namespace {

// How one attempt at a step ended (step() retries the last two in smaller increments).
enum class Attempt {
  done,       // solved (the result is judged by step())
  bad_input,  // malformed input: failed, no retry
  failed,     // no solver could do it, or no valid geometry: failed (state rewound)
  inverted,   // done, but a refresh inside the step found the surface turned inside out
};

// The results of the step just done (w.results_*): the true residual of its last solve's
// eliminated 3N+1 system (volume row scaled like the reference solver's), the reactions,
// contact pressure, strain and stress, in one gather over the neighbour lists with the
// unmasked K per axis (compute_step_results). The pass does both: its time is reported as
// the stress's when the model computes stress.
void step_results(const TissueModel& m, SimState& s, StepWorkspace& w) {
  const auto t_results = Clock::now();
  const ResidualSums sums = compute_step_results(
      m,
      {w.K, w.mask, w.results_loads ? &w.force : nullptr, w.last_springs_any ? &w.last_springs : nullptr, w.area_norms,
       w.rhs},
      s, results_rows(m, w));
  if (m.compute_stress) s.stats.stress_ms += ms_since(t_results);
  const double c = w.results_volume_rhs;
  const double alpha = pressure_scale(w.mean_diagonal, w.a_free);
  double res2 = 0.0, rhs2 = 0.0, vol_row = -c;
  for (int d = 0; d < 3; ++d) {
    res2 += sums.free2[d];
    rhs2 += sums.rhs2[d];
    vol_row += sums.volume_row[d];
  }
  if (m.volume_constraint) {
    res2 += alpha * alpha * vol_row * vol_row;
    rhs2 += alpha * alpha * c * c;
  }
  s.stats.residual = rhs2 > 0 ? std::sqrt(res2 / rhs2) : std::sqrt(res2);
  w.results_pending = false;
}

// s.reaction at the entries the input prescribes alone (the held entries among them too):
// (K u)_i - dP A_i - f_i, each with the operations of the results pass for that entry (its
// neighbour sum from zero in list order), so the same bits.
void prescribed_reactions(const TissueModel& m, const StepInput& in, SimState& s, const StepWorkspace& w) {
  const size_t n = size_t(m.n);
  const int* begin = m.neighbours.begin.data();
  const NeighbourLists::Entry* entries = m.neighbours.entries.data();
  const double* weight = w.K.weight.data();
  const double* diag = w.K.diagonal.data();
  const double* u = s.u.data();
  const double* a = s.area_vectors.data();
  const double* f = w.results_loads ? w.force.data() : nullptr;
  double* reaction = s.reaction.data();
  const double p = s.pressure;
  auto one = [&](int k) {
    const size_t i = size_t(k) % n;
    const double* ud = u + (size_t(k) - i);  // the entry's axis column
    double wu = 0.0;
    for (int q = begin[i]; q < begin[i + 1]; ++q) wu += weight[entries[q].edge] * ud[entries[q].node];
    double r = diag[k] * u[k] - wu - p * a[k];
    if (f) r -= f[k];
    reaction[k] = r;
  };
  for (const int k : w.prescribed_entries) one(k);
  if (in.prescribed.rows() == m.n) {
    const std::uint8_t* prescribed = in.prescribed.data();
    for (const int k : w.held_entries)
      if (prescribed[k]) one(k);
  }
}

// The VDM step proper (section 4) for one input.
Attempt step_once(const TissueModel& m, const StepInput& in, SimState& s, StepResults results) {
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
  // The start of the step, for rewind_step(). u and the velocity are swapped, not copied:
  // until the first solve's result is taken (pin_and_difference, which writes s.u whole from
  // w.start.u) the step reads the start's u from w.start.u, and it writes s.velocity whole
  // at its end; an attempt that fails is rewound, which copies them back.
  w.start.u.swap(s.u);
  w.start.velocity.swap(s.velocity);
  w.start.pressure = s.pressure;
  w.start.step = s.step;
  w.start.time = s.time;
  w.start.since_refresh = w.steps_since_refresh;
  w.start.have_geometry = w.have_geometry;
  w.refreshed_in_step = false;
  if (m.solver.refresh_every > 1 && m.solver.nonlinear_iterations > 1) w.start.x_refresh = w.x_refresh;
  if (const char* bad = check_input(m, in)) {
    fail_step(m, s, bad);
    return Attempt::bad_input;
  }
  // A looser tolerance for this step's solves (its caller will solve it again), or the model's.
  w.solver->set_tolerance(in.tolerance > 0.0 ? in.tolerance : m.solver.tolerance);

  bool inverted = false;
  double current_volume = 0.0;
  double last_c = 0.0;
  double last_du = 0.0;
  double omega = 1.0;  // Aitken relaxation of the nonlinear (fixed-point) iteration
  double final_volume = std::numeric_limits<double>::quiet_NaN();  // at s.x, when known
  bool loads = false;  // w.force holds this step's loads (false: f = 0)
  const double inv_dt = 1.0 / m.dt;
  bool velocity_stale = true;  // s.velocity is not (s.u - w.start.u) / dt

  const int max_it = m.solver.nonlinear_iterations;
  for (int it = 0; it < max_it; ++it) {
    const auto t_asm = Clock::now();
    bool refresh = !w.have_geometry || it > 0 || w.steps_since_refresh >= m.solver.refresh_every;
    current_volume = -1.0;
    if (refresh && it == 0 && w.rewound && w.have_geometry && s.x == w.x_refresh) {
      // A step redone after rewind_step() (the contact's next active set, a halved part) at
      // the positions of the last refresh: the geometry is current, exactly what a refresh
      // would build again. The step goes on as after one (the geometry itself is unchanged:
      // nothing for a rewind to bring back).
      refresh = false;
      current_volume = w.volume_at_refresh;
      w.matrix_dirty = true;
      w.steps_since_refresh = 0;
      st.refreshed = true;
    }
    const bool step_start = it == 0 && !w.rewound;  // (the solver's guess of the change: AxisSystem)
    w.rewound = false;
    if (refresh) {
      current_volume = refresh_geometry(m, s.x, s, w);
      if (current_volume > 0.0) {
        st.refreshed = true;
        w.refreshed_in_step = true;
        ++st.total_refreshes;
      } else if (!w.have_geometry) {
        fail_step(m, s, "the geometry encloses no positive volume");
        return Attempt::failed;
      } else {
        inverted = true;
        add_warning(s, "the deformed surface encloses no positive volume: kept the last valid geometry");
        ++st.fallbacks;
        st.fallback = "inverted geometry: kept the last valid one";
      }
    }
    if (current_volume <= 0.0) current_volume = packed_geometry(m, s.x, w);

    double a_u = 0.0;
    const bool mask_changed = build_constraints(m, in, s.area_vectors, it == 0 ? w.start.u : s.u, w, a_u);
    const bool springs = in.spring_k.rows() == m.n;
    if (springs && w.last_springs.rows() != m.n) w.last_springs = NodeMat::Zero(m.n, 3);  // the first step with springs
    const bool springs_changed = springs ? in.spring_k != w.last_springs : w.last_springs_any;
    if (w.matrix_dirty || mask_changed || springs_changed) {
      if (mask_changed) w.last_mask = w.mask;
      if (springs) {
        w.last_springs = in.spring_k;
        w.last_springs_any = !w.last_springs.isZero(0.0);
      } else if (w.last_springs_any) {
        w.last_springs.setZero();  // zero already otherwise
        w.last_springs_any = false;
      }
      update_solver_system(m, s, w, step_start);
      w.matrix_dirty = false;
    }
    loads = build_loads(m, in, s, w);
    eliminate_rhs(m.neighbours, w.K, w.mask, w.held_entries, w.prescribed_entries, loads ? &w.force : nullptr, w.u_fixed,
                  w.rhs, w.rhs_zero_elsewhere);
    w.rhs_zero_elsewhere = !loads;
    // Eq (11) as a Newton step on the exact volume: a.u^{n+1} = V_0 - V(x^n) + a.u^n,
    // with the constrained part moved to the right.
    const double c = m.rest_volume - current_volume + a_u;
    last_c = c;
    st.assemble_ms += ms_since(t_asm);

    const auto t_solve = Clock::now();
    LinearSolver* solver = w.solver.get();
    const NodeMat& u_now = it == 0 ? w.start.u : s.u;  // s.u is written by the first solve's result
    if (w.solver->warm_starts_from_u()) w.u_new = u_now;
    double p_new = s.pressure;
    SolveReport rep = solver->solve(w.rhs, w.a_free, c, m.volume_constraint, w.u_new, p_new);
    st.iterations += rep.iterations;
    st.factorizations += rep.factorizations;
    st.solve_ms += ms_since(t_solve);
    // Constrained entries take their prescribed values exactly (an iterative solve meets
    // its identity rows only to tolerance).
    // Nonlinear iterations are a fixed point u <- G(u) on the geometry. Aitken's relaxation
    // (the first solve, the load increment, is taken whole): u += omega (G(u) - u), omega
    // from the last two residuals; it saves iterations where the plain iteration converges.
    // u_new becomes the fixed-point residual r = G(u) - u (G(u) pinned), du = max |r| (r is
    // kept in u_new only when a later iteration may read it).
    // The first solve is taken whole (omega = 1): u and x move in the same pass.
    // The first solve's pass also makes the velocity; a later move of u makes it stale.
    // The same pass tells whether the solve's result is finite: when it is not (or the solve
    // did not converge) u, x and the velocity are made again from the fallback's result.
    const bool keep_r = max_it > 1;
    auto take_result = [&]() {
      return pin_and_difference(w, u_now, s.u, w.u_new, m.rest.positions, keep_r, it == 0 ? &s.x : nullptr,
                                it == 0 ? &s.velocity : nullptr, inv_dt);
    };
    Difference diff;
    bool ok = rep.converged && std::isfinite(p_new);
    if (ok) {
      diff = take_result();
      ok = diff.finite;
    }
    if (!ok && m.solver.method != SolverMethod::direct) {
      // Fallback: the same system by the direct solver (exact up to round-off).
      const auto t_fallback = Clock::now();
      st.fallback = rep.converged ? "iterative solve gave a non-finite result: redone by the direct solver"
                                  : "iterative solve did not converge: redone by the direct solver";
      ++st.fallbacks;
      add_warning(s, st.fallback);
      solver = &fallback_solver(m, w);
      if (solver->warm_starts_from_u()) w.u_new = u_now;
      p_new = s.pressure;
      rep = solver->solve(w.rhs, w.a_free, c, m.volume_constraint, w.u_new, p_new);
      st.factorizations += rep.factorizations;
      st.solve_ms += ms_since(t_fallback);
      ok = rep.converged && std::isfinite(p_new);
      if (ok) {
        diff = take_result();
        ok = diff.finite;
      }
    }
    ++st.nonlinear_iterations;
    if (!ok) {
      fail_step(m, s, "no solver could solve the step (singular or non-finite system)");
      return Attempt::failed;
    }
    w.u_verified_finite = diff.u_finite;
    const double du = diff.largest;
    velocity_stale = it > 0;
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
    if (it > 0) {
      advance_positions(w, m.rest.positions, omega, w.u_new, s.u, s.x);
      w.u_verified_finite = false;
    }
    s.pressure += omega * (p_new - s.pressure);
    if (m.volume_constraint) {
      last_c += correct_volume(m, s, w, *solver, final_volume, velocity_stale);
    } else {
      final_volume = std::numeric_limits<double>::quiet_NaN();
    }
    if (it + 1 < max_it && du <= m.solver.nonlinear_tolerance * m.size) break;
  }
  ++w.steps_since_refresh;
  st.total_factorizations += st.factorizations;
  st.total_fallbacks += st.fallbacks;

  // Results: volume (measured at these positions by the last volume check, if any),
  // reactions at constrained entries, contact pressure, strain and stress.
  s.volume = std::isnan(final_volume) ? packed_geometry(m, s.x, w) : final_volume;
  s.volume_rel_error = (s.volume - m.rest_volume) / m.rest_volume;
  w.results_loads = loads;
  w.results_volume_rhs = last_c;
  w.results_pending = true;
  if (results == StepResults::all) step_results(m, s, w);
  else if (results == StepResults::reactions) prescribed_reactions(m, in, s, w);
  if (velocity_stale) s.velocity = (s.u - w.start.u) * inv_dt;  // one division, not one per entry
  ++s.step;
  s.time += m.dt;
  st.step_ms = ms_since(t_step);
  return inverted ? Attempt::inverted : Attempt::done;
}

// --- Halved load increments: a step that cannot be done whole is done in parts ---

// A step is split at most this many times: down to 1/8 of its load increment.
constexpr int kMaxHalvings = 3;
constexpr int kParts = 1 << kMaxHalvings;
// With the volume constraint and its corrections a done step keeps the volume to ~1e-11;
// a drift past this means the surface turned inside out locally (the corrections' slope
// A(x).s went negative) and the increment was too large for the step's linearisation.
constexpr double kVolumeDrift = 1e-4;

const char* const kHalvedText[kMaxHalvings + 1] = {
    nullptr,
    "step too large (solve failed or surface inverted): done in halves of the load increment",
    "step too large (solve failed or surface inverted): done in parts down to 1/4 of the load increment",
    "step too large (solve failed or surface inverted): done in parts down to 1/8 of the load increment",
};

// Why a step's result cannot be kept (static text), or null when it can.
const char* trouble_with(const TissueModel& m, const SimState& s, Attempt a) {
  if (a == Attempt::failed || a == Attempt::bad_input) return s.work->failure_reason;
  if (a == Attempt::inverted) return "the deformed surface turned inside out (no positive enclosed volume)";
  if (!(s.work->u_verified_finite || all_finite(s.u)) || !std::isfinite(s.pressure)) return "the step's result is not finite";
  if (m.volume_constraint && m.solver.volume_corrections > 0 && !(std::abs(s.volume_rel_error) <= kVolumeDrift))
    return "the volume drifted by more than 1e-4 (the surface turned inside out locally)";
  return nullptr;
}

// The loads of the last completed step (and of the one before, for rewind_step): a halved
// step interpolates forces and pressures from them to the new input.
void remember_input(const TissueModel& m, const StepInput& in, StepWorkspace& w) {
  w.force_prev.swap(w.force_last);  // pointer swaps, no allocation
  w.pressure_prev.swap(w.pressure_last);
  std::swap(w.force_prev_zero, w.force_last_zero);
  std::swap(w.pressure_prev_zero, w.pressure_last_zero);
  // Zero loads are only flagged (the first nonzero one sizes its array: allocates once).
  w.force_last_zero = in.force.rows() != m.n || in.force.isZero(0.0);
  if (!w.force_last_zero) w.force_last = in.force;
  w.pressure_last_zero = in.pressure.size() != m.n || in.pressure.isZero(0.0);
  if (!w.pressure_last_zero) w.pressure_last = in.pressure;
  w.input_remembered = true;
}

// The input at fraction t of the way from the last step's input to `in`: forces and
// pressures interpolated, prescribed entries from where they are at the step's start.
void interpolate_input(const TissueModel& m, const StepInput& in, double t, StepWorkspace& w) {
  StepInput& sub = w.sub_input;
  if (w.force_last_zero) sub.force.setZero();
  else sub.force = (1.0 - t) * w.force_last;
  if (in.force.rows() == m.n) sub.force.noalias() += t * in.force;
  if (w.pressure_last_zero) sub.pressure.setZero();
  else sub.pressure = (1.0 - t) * w.pressure_last;
  if (in.pressure.size() == m.n) sub.pressure.noalias() += t * in.pressure;
  if (in.prescribed.rows() == m.n) {
    sub.prescribed = in.prescribed;
    for (int d = 0; d < 3; ++d)
      for (int i = 0; i < m.n; ++i)
        sub.prescribed_u(i, d) = in.prescribed(i, d) ? w.whole.u(i, d) + t * (in.prescribed_u(i, d) -
                                                                              w.whole.u(i, d))
                                                     : 0.0;
  } else {
    sub.prescribed.setZero();
  }
  // Springs (penalty contact) as given: they are the contact's own linearisation, not a load.
  // Zero springs where there are none: the same matrices and loads, bit for bit.
  if (in.spring_k.rows() == m.n) {
    sub.spring_k = in.spring_k;
    sub.spring_u = in.spring_u;
  } else {
    sub.spring_k.setZero();
    sub.spring_u.setZero();
  }
}

// The arrays only a step done in parts uses (sub_input, whole: 8 N x 3 arrays and an N
// vector), made by the first such step rather than with the state: most runs never halve a
// step. That step allocates once; later ones, and every step done whole, allocate nothing.
void make_halving_arrays(const TissueModel& m, StepWorkspace& w) {
  const int n = m.n;
  w.sub_input = make_step_input(m);
  w.sub_input.pressure = Vec::Zero(n);
  w.sub_input.spring_k = NodeMat::Zero(n, 3);
  w.sub_input.spring_u = NodeMat::Zero(n, 3);
  w.whole.u = NodeMat::Zero(n, 3);
  w.whole.velocity = NodeMat::Zero(n, 3);
  w.whole.x_refresh = m.rest.positions;
}

// Makes the rewind point (rewind_step) that of the whole step again.
void restore_whole_start(StepWorkspace& w, bool refreshed) {
  w.start = w.whole;
  w.refreshed_in_step = refreshed;
}

}  // namespace

void step(const TissueModel& m, const StepInput& in, SimState& s, StepResults results) {
  const auto t_step = Clock::now();
  StepWorkspace& w = *s.work;
  StepStats& st = s.stats;
  w.input_remembered = false;
  const long total_factorizations = st.total_factorizations, total_fallbacks = st.total_fallbacks;
  const Attempt first = step_once(m, in, s, results);
  const char* why = trouble_with(m, s, first);
  // Done, or not for smaller increments to mend (malformed input; with inertia the sub-steps
  // would need their own time step: as before, a done step is kept).
  if (!why || first == Attempt::bad_input || (m.use_inertia && first != Attempt::failed)) {
    if (!s.failed) remember_input(m, in, w);
    return;
  }
  if (m.use_inertia) return;  // failed, state as it was

  // The whole step's start (the first attempt has been rewound to it).
  if (first != Attempt::failed) rewind_step(m, s);
  if (w.whole.u.rows() != m.n) make_halving_arrays(m, w);
  w.whole = w.start;
  w.whole.x_refresh = w.x_refresh;  // the geometry's positions now, not the step's kept ones

  // What every attempt cost, reported for the whole step.
  StepStats sum = st;
  auto add = [&sum](const StepStats& a) {
    sum.iterations += a.iterations;
    sum.nonlinear_iterations += a.nonlinear_iterations;
    sum.fallbacks += a.fallbacks;
    sum.factorizations += a.factorizations;
    sum.refreshed = sum.refreshed || a.refreshed;
    sum.assemble_ms += a.assemble_ms;
    sum.solve_ms += a.solve_ms;
    sum.stress_ms += a.stress_ms;
  };
  bool refreshed = false;  // the geometry was rebuilt by a kept sub-step
  bool converged = true;   // every kept sub-step's solves converged
  int pos = 0, size = kParts / 2, halvings = 1;
  while (pos < kParts) {
    const bool last = pos + size == kParts;  // the last part takes the input itself
    if (!last) interpolate_input(m, in, static_cast<double>(pos + size) / kParts, w);
    const Attempt a = step_once(m, last ? in : w.sub_input, s, results);
    add(st);
    why = trouble_with(m, s, a);
    if (!why) {
      refreshed = refreshed || w.refreshed_in_step;
      converged = converged && st.converged;
      pos += size;
      continue;
    }
    if (a != Attempt::failed) rewind_step(m, s);
    if (size == 1) break;  // already at 1/8: give up
    size /= 2;
    ++halvings;
  }
  const bool done = pos == kParts;
  if (!done) {
    // The step cannot be done: everything back to its start, and why.
    restore_whole_start(w, refreshed);
    rewind_step(m, s);
    s.failed = true;
    s.failure = std::string(why) + " (also in parts of 1/8 of the load increment)";
    add_warning(s, s.failure.c_str());
  } else {
    // One step for the caller: counters, velocity and the rewind point are the whole step's.
    s.step = w.whole.step + 1;
    s.time = w.whole.time + m.dt;
    s.velocity = (s.u - w.whole.u) * (1.0 / m.dt);
    restore_whole_start(w, refreshed);
    remember_input(m, in, w);
    add_warning(s, kHalvedText[halvings]);
  }
  // The last sub-step's residual, change and relaxation; summed counts and times.
  sum.residual = st.residual;
  sum.converged = done && converged;
  sum.nonlinear_change = st.nonlinear_change;
  sum.relaxation = st.relaxation;
  sum.fallbacks += halvings;
  sum.fallback = done ? kHalvedText[halvings] : nullptr;
  sum.total_refreshes = st.total_refreshes;
  sum.total_factorizations = total_factorizations + sum.factorizations;
  sum.total_fallbacks = total_fallbacks + sum.fallbacks;
  sum.step_ms = ms_since(t_step);
  st = sum;
}

void finish_step_results(const TissueModel& m, SimState& s) {
  StepWorkspace& w = *s.work;
  if (w.results_pending) step_results(m, s, w);
}

}  // namespace vdm
