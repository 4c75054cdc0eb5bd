#pragma once
// Krylov solvers with caller-owned workspaces, so a warmed-up step allocates nothing.
// `op(x, y)` computes y = A x and `pre(r, z)` computes z = P^{-1} r on raw arrays.
#include <cmath>

#include "engine/types.hpp"

namespace vdm {

struct KrylovResult {
  int iterations = 0;
  double relative_residual = 0.0;  // |b - A x| / |b| at exit (0 when b = 0)
  bool converged = true;
};

struct PcgWorkspace {
  Vec r, z, p, q;
  void resize(Eigen::Index n) {
    if (r.size() != n) { r.resize(n); z.resize(n); p.resize(n); q.resize(n); }
  }
};

// Preconditioned conjugate gradients for SPD A, starting from the guess in x.
template <class Op, class Pre>
KrylovResult pcg(const Op& op, const Pre& pre, const Vec& b, Vec& x, double tol, int max_iter,
                 PcgWorkspace& w) {
  KrylovResult res;
  w.resize(b.size());
  const double bnorm = b.norm();
  if (bnorm == 0.0) {
    x.setZero();
    return res;
  }
  op(x.data(), w.q.data());
  w.r.noalias() = b - w.q;
  double rnorm = w.r.norm();
  if (rnorm <= tol * bnorm) {
    res.relative_residual = rnorm / bnorm;
    return res;
  }
  pre(w.r.data(), w.z.data());
  w.p = w.z;
  double rz = w.r.dot(w.z);
  for (int it = 1; it <= max_iter; ++it) {
    op(w.p.data(), w.q.data());
    const double pq = w.p.dot(w.q);
    if (!(pq > 0.0) || !std::isfinite(pq)) {  // breakdown: A not SPD along p, or NaN
      res.iterations = it;
      res.relative_residual = rnorm / bnorm;
      res.converged = false;
      return res;
    }
    const double alpha = rz / pq;
    x.noalias() += alpha * w.p;
    w.r.noalias() -= alpha * w.q;
    rnorm = w.r.norm();
    res.iterations = it;
    if (rnorm <= tol * bnorm) {
      res.relative_residual = rnorm / bnorm;
      return res;
    }
    pre(w.r.data(), w.z.data());
    const double rz_new = w.r.dot(w.z);
    w.p = w.z + (rz_new / rz) * w.p;
    rz = rz_new;
  }
  res.relative_residual = rnorm / bnorm;
  res.converged = false;
  return res;
}

struct BicgstabWorkspace {
  Vec r, r0, p, v, s, t, y, z;
  void resize(Eigen::Index n) {
    if (r.size() != n) {
      r.resize(n); r0.resize(n); p.resize(n); v.resize(n);
      s.resize(n); t.resize(n); y.resize(n); z.resize(n);
    }
  }
};

// Right-preconditioned BiCGSTAB (van der Vorst) for a general A, starting from x.
template <class Op, class Pre>
KrylovResult bicgstab(const Op& op, const Pre& pre, const Vec& b, Vec& x, double tol, int max_iter,
                      BicgstabWorkspace& w) {
  KrylovResult res;
  w.resize(b.size());
  const double bnorm = b.norm();
  if (bnorm == 0.0) {
    x.setZero();
    return res;
  }
  op(x.data(), w.v.data());
  w.r.noalias() = b - w.v;
  double rnorm = w.r.norm();
  if (rnorm <= tol * bnorm) {
    res.relative_residual = rnorm / bnorm;
    return res;
  }
  double rho = 1, alpha = 1, omega = 1;
  int restarts = 0;
  // (Re)start with the shadow residual r0 = r; a breakdown (r0 orthogonal to the new
  // direction) restarts from the current iterate, a few times at most.
  auto restart = [&] {
    w.r0 = w.r;
    rho = alpha = omega = 1;
    w.v.setZero();
    w.p.setZero();
  };
  restart();
  for (int it = 1; it <= max_iter; ++it) {
    const double rho_new = w.r0.dot(w.r);
    if (!std::isfinite(rho_new)) break;
    if (rho_new == 0.0) {
      if (++restarts > 5) break;
      restart();
      continue;
    }
    const double beta = (rho_new / rho) * (alpha / omega);
    rho = rho_new;
    w.p = w.r + beta * (w.p - omega * w.v);
    pre(w.p.data(), w.y.data());
    op(w.y.data(), w.v.data());
    const double r0v = w.r0.dot(w.v);
    if (!std::isfinite(r0v)) break;
    if (r0v == 0.0) {
      if (++restarts > 5) break;
      // Perturb the shadow residual: r0 = r + the preconditioned direction.
      w.r0 = w.r + w.y;
      rho = w.r0.dot(w.r);
      alpha = omega = 1;
      w.v.setZero();
      w.p.setZero();
      continue;
    }
    alpha = rho / r0v;
    w.s.noalias() = w.r - alpha * w.v;
    res.iterations = it;
    if (w.s.norm() <= tol * bnorm) {
      x.noalias() += alpha * w.y;
      res.relative_residual = w.s.norm() / bnorm;
      return res;
    }
    pre(w.s.data(), w.z.data());
    op(w.z.data(), w.t.data());
    const double tt = w.t.squaredNorm();
    omega = tt > 0 ? w.t.dot(w.s) / tt : 0.0;
    x.noalias() += alpha * w.y + omega * w.z;
    w.r.noalias() = w.s - omega * w.t;
    rnorm = w.r.norm();
    if (rnorm <= tol * bnorm) {
      res.relative_residual = rnorm / bnorm;
      return res;
    }
    if (omega == 0.0) break;
  }
  // Report the true residual on exit without convergence.
  op(x.data(), w.v.data());
  w.r.noalias() = b - w.v;
  res.relative_residual = w.r.norm() / bnorm;
  res.converged = res.relative_residual <= tol;
  return res;
}

}  // namespace vdm
