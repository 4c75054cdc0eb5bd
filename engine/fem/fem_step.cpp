#include <Eigen/SVD>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#ifdef VDMSIM_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#endif

#include <chrono>
#include <cmath>
#include <limits>

#include "engine/fem/fem_state.hpp"
#include "engine/geometry.hpp"
#include "engine/stopwatch.hpp"
#include "engine/warnings.hpp"

namespace vdm::fem {

// Per-tet kinematics at the current iterate.
struct TetEval {
  Eigen::Matrix3d U, V, R;  // rotation-variant SVD F = U diag(sigma) V^T, R = U V^T
  Vec3 sigma;
  double det = 1;           // det F
};

struct FemWorkspace {
  std::vector<TetEval> tet;
  Vec theta_group;          // theta_g
  Vec q;                    // per tet: lambda x mean theta over its groups (Pa)
  std::vector<Eigen::Triplet<double>> triplets, gtriplets;
  SpMat K, G;
#ifdef VDMSIM_HAVE_CHOLMOD
  // Supernodal Cholesky (SuiteSparse): a 3D tet mesh's factor has dense fronts that a
  // simplicial factorisation handles an order of magnitude slower.
  Eigen::CholmodSupernodalLLT<SpMat, Eigen::Lower> chol;
#else
  Eigen::SimplicialLDLT<SpMat> ldlt;
#endif
  Eigen::ConjugateGradient<SpMat, Eigen::Lower | Eigen::Upper, Eigen::IncompleteCholesky<double>> cg;
  long analyzed_nonzeros = -1;
  bool have_factor = false;  // chol holds the factors of a tangent with the mask factor_mask
  FlagMat factor_mask;
  Vec rhs, du, dof_mask, du_c;
  NodeMat f_ext, grad, u_try, u_target;
  FlagMat mask;
};

FemState::FemState() = default;
FemState::~FemState() = default;
FemState::FemState(FemState&&) noexcept = default;
FemState& FemState::operator=(FemState&&) noexcept = default;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

Eigen::Matrix3d deformation_gradient(const FemModel& m, const NodeMat& u, int t) {
  Eigen::Matrix<double, 4, 3> x;
  for (int q = 0; q < 4; ++q) {
    const int a = m.mesh.tets(t, q);
    x.row(q) = m.mesh.positions.row(a) + u.row(a);
  }
  return x.transpose() * m.grad[static_cast<size_t>(t)];
}

// GCC 12 reports a false "may be used uninitialized" inside Eigen's 3x3 JacobiSVD.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
void polar(const Eigen::Matrix3d& F, TetEval& e) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  e.U = svd.matrixU();
  e.V = svd.matrixV();
  e.sigma = svd.singularValues();
  if (e.U.determinant() < 0) {
    e.U.col(2) *= -1;
    e.sigma[2] *= -1;
  }
  if (e.V.determinant() < 0) {
    e.V.col(2) *= -1;
    e.sigma[2] *= -1;
  }
  e.R = e.U * e.V.transpose();
  e.det = F.determinant();
}
#pragma GCC diagnostic pop

// Fills every tet's kinematics, theta per group and q per tet; returns the elastic energy
// (+inf when a tet is inverted or flat).
double evaluate(const FemModel& m, const NodeMat& u, FemWorkspace& w) {
  double energy = 0;
  bool inverted = false;
  for (int t = 0; t < m.tets; ++t) {
    TetEval& e = w.tet[static_cast<size_t>(t)];
    polar(deformation_gradient(m, u, t), e);
    if (!(e.det > 0)) inverted = true;
    energy += m.tet_volume[t] * m.mu * (e.sigma.array() - 1.0).square().sum();
  }
  const int groups = static_cast<int>(m.group_volume.size());
  w.q.setZero();
  for (int g = 0; g < groups; ++g) {
    double th = 0;
    for (int k = m.group_start[g]; k < m.group_start[g + 1]; ++k)
      th += m.group_weight[k] * (w.tet[static_cast<size_t>(m.group_tet[k])].sigma.sum() - 3.0);
    w.theta_group[g] = th;
    energy += 0.5 * m.lambda * m.group_volume[g] * th * th;
  }
  // dE_vol/dtheta_e = sum_g lambda V_g theta_g w_ge; q_e is that per unit tet volume.
  for (int g = 0; g < groups; ++g)
    for (int k = m.group_start[g]; k < m.group_start[g + 1]; ++k)
      w.q[m.group_tet[k]] += m.lambda * m.group_volume[g] * w.theta_group[g] * m.group_weight[k];
  for (int t = 0; t < m.tets; ++t) w.q[t] /= m.tet_volume[t];
  return inverted ? kInf : energy;
}

// dE_elastic/du (n x 3), after evaluate().
void internal_force(const FemModel& m, const FemWorkspace& w, NodeMat& grad) {
  grad.setZero();
  for (int t = 0; t < m.tets; ++t) {
    const TetEval& e = w.tet[static_cast<size_t>(t)];
    const Eigen::Matrix3d S = e.V * e.sigma.asDiagonal() * e.V.transpose();
    const Eigen::Matrix3d P = 2 * m.mu * (e.R * S - e.R) + w.q[t] * e.R;
    const Eigen::Matrix<double, 4, 3> f = m.tet_volume[t] * m.grad[static_cast<size_t>(t)] * P.transpose();
    for (int q = 0; q < 4; ++q) grad.row(m.mesh.tets(t, q)) += f.row(q);
  }
}

// Tangent stiffness after evaluate(): exact, or with each tet's twist modes clamped at zero
// (`project`: positive semi-definite per tet) when the exact one is indefinite.
void assemble(const FemModel& m, FemWorkspace& w, bool project) {
  w.triplets.clear();
  w.gtriplets.clear();
  const int pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
  for (int t = 0; t < m.tets; ++t) {
    const TetEval& e = w.tet[static_cast<size_t>(t)];
    const Eigen::Matrix<double, 4, 3>& G = m.grad[static_cast<size_t>(t)];
    const double Ve = m.tet_volume[t];
    Eigen::Matrix<double, 12, 12> Ke = Eigen::Matrix<double, 12, 12>::Zero();
    // 2 mu V_e |dF|^2 part: (G G^T) (x) I3.
    const Eigen::Matrix4d GG = G * G.transpose();
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) Ke.block<3, 3>(3 * a, 3 * b).diagonal().setConstant(2 * m.mu * Ve * GG(a, b));
    // Twist modes of dR/dF: eigenvalue V_e (2 mu + (q_e - 2 mu) 2 / (s_i + s_j)), clamped at 0.
    for (const auto& p : pairs) {
      const int i = p[0], j = p[1];
      const double s = std::max(e.sigma[i] + e.sigma[j], 1e-6);
      const double c = 2.0 / s;
      const double exact = Ve * (2 * m.mu + (w.q[t] - 2 * m.mu) * c);
      const double lam = project ? std::max(exact, 0.0) : exact;
      Eigen::Matrix3d T = Eigen::Matrix3d::Zero();
      T(i, j) = 1 / std::sqrt(2.0);
      T(j, i) = -1 / std::sqrt(2.0);
      const Eigen::Matrix3d Tw = e.U * T * e.V.transpose();
      Eigen::Matrix<double, 12, 1> b;
      for (int a = 0; a < 4; ++a) b.segment<3>(3 * a) = Tw * G.row(a).transpose();
      Ke += (lam - 2 * m.mu * Ve) * b * b.transpose();
    }
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c)
            w.triplets.emplace_back(3 * m.mesh.tets(t, a) + r, 3 * m.mesh.tets(t, b) + c, Ke(3 * a + r, 3 * b + c));
  }
  // Volumetric coupling: sum_g lambda V_g (dtheta_g/du)(dtheta_g/du)^T, as (D^1/2 G)^T (D^1/2 G).
  const int groups = static_cast<int>(m.group_volume.size());
  for (int g = 0; g < groups; ++g) {
    const double s = std::sqrt(m.lambda * m.group_volume[g]);
    for (int k = m.group_start[g]; k < m.group_start[g + 1]; ++k) {
      const int t = m.group_tet[k];
      const TetEval& e = w.tet[static_cast<size_t>(t)];
      const Eigen::Matrix<double, 4, 3>& Gt = m.grad[static_cast<size_t>(t)];
      for (int a = 0; a < 4; ++a) {
        const Vec3 d = e.R * Gt.row(a).transpose() * (s * m.group_weight[k]);
        for (int r = 0; r < 3; ++r) w.gtriplets.emplace_back(g, 3 * m.mesh.tets(t, a) + r, d[r]);
      }
    }
  }
  w.K.setFromTriplets(w.triplets.begin(), w.triplets.end());
  w.G.setFromTriplets(w.gtriplets.begin(), w.gtriplets.end());
  w.K += SpMat(w.G.transpose()) * w.G;
}

// Constrained rows and columns become identities.
void apply_mask(FemWorkspace& w) {
  for (int j = 0; j < w.K.outerSize(); ++j)
    for (SpMat::InnerIterator it(w.K, j); it; ++it)
      if (w.dof_mask[it.row()] != 0 || w.dof_mask[j] != 0) it.valueRef() = it.row() == j ? 1.0 : 0.0;
}

Eigen::Map<const Vec> flat(const NodeMat& a) { return Eigen::Map<const Vec>(a.data(), a.size()); }

// Newton from the current u to equilibrium under w.f_ext with the masked entries at
// w.u_target. False (u left anywhere) when a tet inverts or it does not converge.
bool newton(const FemModel& m, FemState& s, FemWorkspace& w) {
  const int n = m.n, dofs = 3 * n;
  // Interleaved dof index 3a + r; NodeMat is column-major, so convert explicitly.
  auto to_dofs = [&](const NodeMat& a, Vec& out) {
    for (int i = 0; i < n; ++i)
      for (int r = 0; r < 3; ++r) out[3 * i + r] = a(i, r);
  };
  for (int i = 0; i < n; ++i)
    for (int r = 0; r < 3; ++r) w.dof_mask[3 * i + r] = w.mask(i, r);
  // Force scale at rest: far above the gradient's rounding (~1e-13 of it), far below any load.
  const double floor = m.mu * m.size * m.size * 1e-6;
  // Modified Newton: the tangent changes little from one iteration or step to the next, and a
  // factorisation of a 3D mesh's tangent costs far more than a solve with it (on the 2.5k
  // liver's 21k unknowns, 95 % of the calibration's time went to the factorisations). So the
  // last factors (of a tangent with the same constrained entries) are reused while the
  // residual keeps falling to at most half at each iteration (the iteration after a move of
  // the constrained entries is not judged: that move raised the residual); a slower fall, a
  // failed line search, or the last iterations' budget factorise afresh. A move of the
  // constrained entries takes the current tangent's K du_c with the old factors.
  if (w.factor_mask.rows() != w.mask.rows() || w.factor_mask != w.mask) w.have_factor = false;
  double previous_residual = kInf;
  for (int it = 0; it < m.settings.max_iterations; ++it) {
    const double e0 = evaluate(m, s.u, w);
    if (!std::isfinite(e0)) {
      w.have_factor = false;  // (a retry in smaller increments starts from fresh factors)
      return false;
    }
    internal_force(m, w, w.grad);
    w.grad -= w.f_ext;
    double free2 = 0, fixed2 = 0, jump = 0;
    for (int i = 0; i < n; ++i)
      for (int r = 0; r < 3; ++r) {
        if (w.mask(i, r)) {
          fixed2 += w.grad(i, r) * w.grad(i, r);
          w.du_c[3 * i + r] = w.u_target(i, r) - s.u(i, r);
          jump = std::max(jump, std::abs(w.du_c[3 * i + r]));
        } else {
          free2 += w.grad(i, r) * w.grad(i, r);
          w.du_c[3 * i + r] = 0;
        }
      }
    const double scale = std::max({flat(w.f_ext).norm(), std::sqrt(fixed2), floor});
    s.stats.residual = std::sqrt(free2) / scale;
    if (jump == 0 && s.stats.residual <= m.settings.tolerance) return true;
    ++s.stats.iterations;
    // Exact tangent first (quadratic convergence); projected when it is not positive definite.
    // Large meshes: projected tangent, preconditioned CG.
#ifdef VDMSIM_HAVE_CHOLMOD
    const bool direct = dofs <= m.settings.direct_max_dofs_supernodal;
#else
    const bool direct = dofs <= m.settings.direct_max_dofs;
#endif
    bool factored = false;
    const bool reuse = direct && w.have_factor && s.stats.residual <= 0.5 * previous_residual &&
                       it + 4 < m.settings.max_iterations;
    previous_residual = jump > 0 ? kInf : s.stats.residual;
    if (reuse) {
      to_dofs(w.grad, w.rhs);
      if (jump > 0) {
        assemble(m, w, false);
        w.rhs = -w.rhs - w.K * w.du_c;
      } else {
        w.rhs = -w.rhs;
      }
      for (int k = 0; k < dofs; ++k)
        if (w.dof_mask[k] != 0) w.rhs[k] = w.du_c[k];
      factored = true;
    }
    if (!direct) {
      assemble(m, w, true);
      to_dofs(w.grad, w.rhs);
      w.rhs = -w.rhs - w.K * w.du_c;
      for (int k = 0; k < dofs; ++k)
        if (w.dof_mask[k] != 0) w.rhs[k] = w.du_c[k];
      apply_mask(w);
      w.cg.setTolerance(m.settings.cg_tolerance);
      w.cg.setMaxIterations(m.settings.cg_max_iterations);
      w.cg.compute(w.K);
      if (w.cg.info() != Eigen::Success) return false;
      w.du = w.cg.solve(w.rhs);
      factored = true;
    }
    for (int project = 0; project < 2 && !factored; ++project) {
      assemble(m, w, project != 0);
      if (project == 0) {
        to_dofs(w.grad, w.rhs);
        w.rhs = -w.rhs - w.K * w.du_c;
        for (int k = 0; k < dofs; ++k)
          if (w.dof_mask[k] != 0) w.rhs[k] = w.du_c[k];
      }
      apply_mask(w);
#ifdef VDMSIM_HAVE_CHOLMOD
      if (w.K.nonZeros() != w.analyzed_nonzeros) {
        w.chol.cholmod().print = 0;  // an indefinite exact tangent is an expected path: no warnings
        w.chol.analyzePattern(w.K);
        w.analyzed_nonzeros = w.K.nonZeros();
      }
      w.chol.factorize(w.K);  // fails (info) when K is not positive definite
      factored = w.chol.info() == Eigen::Success;
#else
      if (w.K.nonZeros() != w.analyzed_nonzeros) {
        w.ldlt.analyzePattern(w.K);
        w.analyzed_nonzeros = w.K.nonZeros();
      }
      w.ldlt.factorize(w.K);
      factored = w.ldlt.info() == Eigen::Success && w.ldlt.vectorD().minCoeff() > 0;
#endif
    }
    if (!factored) return false;
    if (direct && !reuse) {
      w.have_factor = true;
      w.factor_mask = w.mask;
    }
#ifdef VDMSIM_HAVE_CHOLMOD
    if (direct) w.du = w.chol.solve(w.rhs);
#else
    if (direct) w.du = w.ldlt.solve(w.rhs);
#endif
    if (!w.du.allFinite()) return false;
    if (jump > 0) {  // the constrained entries move to their targets: take the full step
      for (int i = 0; i < n; ++i)
        for (int r = 0; r < 3; ++r) s.u(i, r) += w.du[3 * i + r];
      continue;
    }
    // Backtracking on the energy (the constrained entries do not move).
    Vec g(dofs);
    to_dofs(w.grad, g);
    const double slope = g.dot(w.du);
    const double base = e0 - flat(w.f_ext).dot(flat(s.u));
    double alpha = 1;
    bool accepted = false;
    for (int ls = 0; ls < 30 && !accepted; ++ls, alpha /= 2) {
      for (int i = 0; i < n; ++i)
        for (int r = 0; r < 3; ++r) w.u_try(i, r) = s.u(i, r) + alpha * w.du[3 * i + r];
      const double e = evaluate(m, w.u_try, w) - flat(w.f_ext).dot(flat(w.u_try));
      if (!std::isfinite(e)) continue;
      if (e <= base + 1e-4 * alpha * slope) {
        accepted = true;
      } else if (std::abs(e - base) <= 1e-10 * std::abs(base)) {
        // The energy change is at round-off: accept when the free residual falls instead.
        internal_force(m, w, w.grad);
        w.grad -= w.f_ext;
        double trial2 = 0;
        for (int i = 0; i < n; ++i)
          for (int r = 0; r < 3; ++r)
            if (!w.mask(i, r)) trial2 += w.grad(i, r) * w.grad(i, r);
        accepted = std::sqrt(trial2) < (1 - 0.25 * alpha) * std::sqrt(free2);
      }
    }
    if (!accepted) {
      if (!reuse) return false;
      w.have_factor = false;  // the old tangent's direction failed: the next iteration factorises
      continue;
    }
    s.u = w.u_try;
    if (w.du.cwiseAbs().maxCoeff() * alpha < 1e-15 * m.size) return true;  // at round-off
  }
  const double e = evaluate(m, s.u, w);
  return std::isfinite(e) && s.stats.residual <= std::sqrt(m.settings.tolerance);
}

}  // namespace

FemState make_fem_state(const FemModel& m) {
  FemState s;
  s.u = NodeMat::Zero(m.n, 3);
  s.reaction = NodeMat::Zero(m.n, 3);
  s.applied = NodeMat::Zero(m.n, 3);
  s.volume = m.rest_volume;
  s.work = std::make_unique<FemWorkspace>();
  FemWorkspace& w = *s.work;
  w.tet.resize(static_cast<size_t>(m.tets));
  w.theta_group = Vec::Zero(m.group_volume.size());
  w.q = Vec::Zero(m.tets);
  w.triplets.reserve(static_cast<size_t>(m.tets) * 144);
  w.gtriplets.reserve(m.group_tet.size() * 12);
  w.K.resize(3 * m.n, 3 * m.n);
  w.G.resize(static_cast<Eigen::Index>(m.group_volume.size()), 3 * m.n);
  w.rhs = w.du = w.dof_mask = w.du_c = Vec::Zero(3 * m.n);
  w.f_ext = w.grad = w.u_try = w.u_target = NodeMat::Zero(m.n, 3);
  w.mask = FlagMat::Zero(m.n, 3);
  return s;
}

double energy(const FemModel& m, const NodeMat& u, const NodeMat& f, NodeMat* gradient) {
  FemState s = make_fem_state(m);
  FemWorkspace& w = *s.work;
  const double e = evaluate(m, u, w);
  if (gradient) {
    gradient->resize(m.n, 3);
    internal_force(m, w, *gradient);
    if (f.rows() == m.n) *gradient -= f;
  }
  return e - (f.rows() == m.n ? flat(f).dot(flat(u)) : 0.0);
}

void step(const FemModel& m, const StepInput& in, FemState& s) {
  const auto t0 = Clock::now();
  FemWorkspace& w = *s.work;
  s.stats = FemStats{};
  // Targets of this step: external force and the constrained entries' values.
  NodeMat f_target = NodeMat::Zero(m.n, 3);
  if (in.force.rows() == m.ns) f_target.topRows(m.ns) = in.force;
  if (m.gravity_force.rows() == m.n) f_target += m.gravity_force;
  if (in.pressure.size() == m.ns) {
    NodeMat x = m.mesh.surface.positions + s.u.topRows(m.ns);
    NodeMat area(m.ns, 3);
    distributed_area_vectors(x, m.mesh.surface.triangles, area);
    for (int i = 0; i < m.ns; ++i) f_target.row(i) -= in.pressure[i] * area.row(i);
  }
  FlagMat mask = m.fixed;
  NodeMat u_end = NodeMat::Zero(m.n, 3);
  if (in.prescribed.rows() == m.ns)
    for (int i = 0; i < m.ns; ++i)
      for (int r = 0; r < 3; ++r)
        if (in.prescribed(i, r) && !m.fixed(i, r)) {
          mask(i, r) = 1;
          u_end(i, r) = in.prescribed_u(i, r);
        }
  w.mask = mask;
  const NodeMat u_start = s.u, f_start = s.applied;
  // Increments from the last equilibrium to the targets, halved on failure.
  double done = 0, h = 1;
  const double h_min = std::ldexp(1.0, -m.settings.max_bisections);
  NodeMat u_good = s.u;
  while (done < 1) {
    const double a = std::min(1.0, done + h);
    w.f_ext = f_start + a * (f_target - f_start);
    for (int i = 0; i < m.n; ++i)
      for (int r = 0; r < 3; ++r) w.u_target(i, r) = u_start(i, r) + a * (u_end(i, r) - u_start(i, r));
    if (newton(m, s, w)) {
      done = a;
      u_good = s.u;
      ++s.stats.substeps;
      h = std::min(2 * h, 1.0);
    } else {
      s.u = u_good;
      h /= 2;
      if (h < h_min) {
        s.stats.converged = false;
        if (s.warnings.size() < kMaxWarnings) s.warnings.emplace_back("fem: a step did not converge (kept the last equilibrium)");
        break;
      }
    }
  }
  // Results: reactions, applied load, volume, mean pressure.
  evaluate(m, s.u, w);
  internal_force(m, w, w.grad);
  s.applied = f_start + done * (f_target - f_start);
  s.reaction.setZero();
  for (int i = 0; i < m.n; ++i)
    for (int r = 0; r < 3; ++r)
      if (mask(i, r)) s.reaction(i, r) = w.grad(i, r) - s.applied(i, r);
  double vol = 0, p = 0;
  for (int t = 0; t < m.tets; ++t) {
    vol += m.tet_volume[t] * w.tet[static_cast<size_t>(t)].det;
    p -= m.tet_volume[t] * w.q[t];
  }
  s.volume = vol;
  s.volume_rel_error = (vol - m.rest_volume) / m.rest_volume;
  s.pressure = p / m.rest_volume;
  s.stats.step_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

}  // namespace vdm::fem
