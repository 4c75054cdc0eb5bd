#pragma once
// Preconditioned conjugate gradients on a block of W independent SPD systems at once (node-
// major storage, entry (i, c) at [i * W + c]): every column runs its own PCG, exactly the
// iteration of pcg() in krylov.hpp, with its own step lengths and its own stop, while the
// operator and the preconditioner are applied to the whole block in one pass. A column that
// has stopped is frozen (its direction is zeroed), so its result is what it would be alone.
// The caller owns the workspace: a warmed-up solve allocates nothing.
#include <array>
#include <cmath>
#include <initializer_list>
#include <type_traits>
#include <utility>
#include <vector>

#include "engine/krylov.hpp"

namespace vdm {

// z (the preconditioned residual) and q (A p) share one array: q is dead once r is updated,
// before z is made, and z once p is, before the next q.
struct BlockPcgWorkspace {
  std::vector<double> r, zq, p;
  void resize(size_t size) {
    if (r.size() != size) {
      r.assign(size, 0.0);
      zq.assign(size, 0.0);
      p.assign(size, 0.0);
    }
  }
};

// Optional column kernels for block_pcg(): `multiply(c, in, out)` writes A_c in into out
// and returns in . out, `apply(c, in, out)` the same for P^{-1}, on vectors of n entries
// stored contiguously (column c taken out of the block), each with the block kernels'
// operations on column c (the same values bit for bit). Once a single column is still
// iterating, it is taken out of the block and its iterations run on it alone: the same
// iterates, touching n values per vector where the block's every cache line was touched.
// NoColumnKernels: never.
// The same object may also have `residual(b, x, r, bn, rn)`: r = b - A x on the whole block
// (r may be b) with bn[c] = |b_c|^2 and rn[c] = |r_c|^2 summed row by row from 0, in one
// pass (block_pcg's own passes, the product and its dot in three passes otherwise: the same
// bits); it returns false, having written nothing, when it cannot. b is read only when there
// is no residual() or it returns false (a residual() may read the same b from elsewhere).
// And `project(c, x, r, rn, bn, threshold, scratch)`: called for each column whose starting
// residual is over its threshold, before the first iteration; it may improve the guess x_c
// along a direction of its own (a Galerkin step: x_c += t v, r_c -= t A v, t = v.r / v.A v),
// writing rn (|r_c|^2) when it does, and returns whether it did. bn = |b_c|^2. `scratch`:
// 2 n doubles free until the iterations start.
struct NoColumnKernels {};

namespace detail {

template <class Col, class = void>
struct HasResidual : std::false_type {};
template <class Col>
struct HasResidual<Col, std::void_t<decltype(std::declval<const Col&>().residual(
                            std::declval<const double*>(), std::declval<const double*>(), std::declval<double*>(),
                            std::declval<double*>(), std::declval<double*>()))>> : std::true_type {};

template <class Col, class = void>
struct HasProject : std::false_type {};
template <class Col>
struct HasProject<Col, std::void_t<decltype(std::declval<const Col&>().project(
                           0, std::declval<double*>(), std::declval<double*>(), std::declval<double&>(), 0.0,
                           0.0, std::declval<double*>()))>> : std::true_type {};

// The rest of column c's PCG, alone, from the point where its residual r_c is to be
// preconditioned: p_c = z_c the first time (`first`), else z_c + (r.z / rz_old) p_c; the
// iteration counter at `it` (the iterations done). The same recurrence as block_pcg's.
// The other columns of r, p, z and q are dead (stopped: only x is kept), so column c of r and
// p moves to the first n entries of its own array (row i's entry to entry i, each read before
// it is overwritten: i <= i W + c), z and q share the first n of the z/q array and x_c its next
// n; x_c goes back into the block at the end.
template <int W, class Col>
void column_pcg(const Col& col, int c, int n, double* x, double threshold, double bn, int max_iter, int it, bool first,
                double rz_old, BlockPcgWorkspace& w, KrylovResult& result) {
  double* r = w.r.data();
  double* p = w.p.data();
  double* z = w.zq.data();
  double* q = z;
  double* xc = z + n;
  for (int i = 0; i < n; ++i) {
    const size_t k = size_t(i) * W + size_t(c);
    r[i] = r[k];
    xc[i] = x[k];
  }
  if (!first)
    for (int i = 0; i < n; ++i) p[i] = p[size_t(i) * W + size_t(c)];
  for (;;) {
    const double rz = col.apply(c, r, z);
    const double beta = first ? 0.0 : rz / rz_old;
    for (int i = 0; i < n; ++i) p[i] = first ? z[i] : z[i] + beta * p[i];
    first = false;
    rz_old = rz;
    if (++it > max_iter) {
      result.converged = false;
      break;
    }
    const double dot = col.multiply(c, p, q);
    if (!(dot > 0.0) || !std::isfinite(dot)) {  // breakdown: A not SPD along p, or NaN
      result.iterations = it;
      result.converged = false;
      break;
    }
    const double alpha = rz / dot;
    double rn = 0.0;
    for (int i = 0; i < n; ++i) {
      xc[i] += alpha * p[i];
      r[i] -= alpha * q[i];
      rn += r[i] * r[i];
    }
    result.iterations = it;
    result.relative_residual = std::sqrt(rn / bn);
    if (std::sqrt(rn) <= threshold) break;
  }
  for (int i = 0; i < n; ++i) x[size_t(i) * W + size_t(c)] = xc[i];
}

}  // namespace detail

// Solves A_c x_c = b_c for c < W from the guesses in x, column c until |b_c - A_c x_c| <=
// threshold[c] (absolute), or max_iter iterations. `op(in, out, dot)`: out = A in on the
// block and dot[c] = in_c . out_c; `pre(in, out, dot, live)`: out = P^{-1} in and dot[c] =
// in_c . out_c, with in_c taken as zero where live[c] is 0 (a stopped column: its residual is
// left in place, not zeroed by a pass of its own). A column with b_c = 0 gets x_c = 0.
// result[c]: iterations and convergence per column (breakdown: A_c not SPD along the
// direction, or not finite). b may be w.r itself
// (sized n W beforehand): each entry is read before the residual overwrites it.
template <int W, class Op, class Pre, class Col = NoColumnKernels>
void block_pcg(const Op& op, const Pre& pre, int n, const double* b, double* x, const double* threshold,
               int max_iter, BlockPcgWorkspace& w, std::array<KrylovResult, W>& result, const Col& col = Col()) {
  w.resize(size_t(n) * W);
  double* r = w.r.data();
  double* z = w.zq.data();
  double* p = w.p.data();
  double* q = w.zq.data();
  double bn[W] = {}, rn[W] = {}, dot[W], rz[W], alpha[W], beta[W], live[W];
  bool fused = false;
  if constexpr (detail::HasResidual<Col>::value) {
    // Through copies: rn and bn themselves stay local (a pointer given away would let the
    // compiler keep them in memory through every later pass, stores to x and r possibly
    // aliasing them).
    double bn0[W], rn0[W];
    fused = col.residual(b, x, r, bn0, rn0);
    if (fused)
      for (int c = 0; c < W; ++c) {
        bn[c] = bn0[c];
        rn[c] = rn0[c];
      }
  }
  if (!fused) {
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < W; ++c) bn[c] += b[size_t(i) * W + c] * b[size_t(i) * W + c];
    op(x, q, dot);
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < W; ++c) {
        const double v = b[size_t(i) * W + c] - q[size_t(i) * W + c];
        r[size_t(i) * W + c] = v;
        rn[c] += v * v;
      }
  }
  if constexpr (detail::HasProject<Col>::value) {
    for (int c = 0; c < W; ++c)
      if (bn[c] != 0.0 && !(std::sqrt(rn[c]) <= threshold[c]))
        col.project(c, x, r, rn[c], bn[c], threshold[c], w.zq.data());
  }
  int active = 0;
  for (int c = 0; c < W; ++c) {
    result[size_t(c)] = KrylovResult();
    const double bnorm = std::sqrt(bn[c]);
    live[c] = 0.0;
    if (bnorm == 0.0) {
      for (int i = 0; i < n; ++i) x[size_t(i) * W + c] = 0.0;
    } else if (!(std::sqrt(rn[c]) <= threshold[c])) {  // NaN: iterate (and break down)
      live[c] = 1.0;
      ++active;
    }
    result[size_t(c)].relative_residual = bnorm > 0 ? std::sqrt(rn[c]) / bnorm : 0.0;
  }
  if (active == 0) return;
  // The one column still iterating, when the column kernels can take it alone (-1: none).
  auto alone = [&]() -> int {
    if constexpr (std::is_same_v<Col, NoColumnKernels>) {
      return -1;
    } else {
      if (active != 1) return -1;
      for (int c = 0; c < W; ++c)
        if (live[c] != 0.0) return c;
      return -1;
    }
  };
  if (const int c = alone(); c >= 0) {
    if constexpr (!std::is_same_v<Col, NoColumnKernels>)
      detail::column_pcg<W>(col, c, n, x, threshold[c], bn[c], max_iter, 0, true, 0.0, w, result[size_t(c)]);
    return;
  }
  // A stopped column has p = q = 0, and z = 0 (pre() takes its r as zero: r itself is left
  // as it was), so nothing changes it, unless the preconditioner is not finite there (its
  // direction is zeroed again after each update) or it broke down (r, p and q are zeroed:
  // p may not be finite). Columns are zeroed together, in one pass over the block (a pass
  // per column and vector cost as much as the iteration itself on large blocks).
  bool cut[W];
  auto zero = [&](std::initializer_list<double*> vs) {
    bool any = false;
    for (int c = 0; c < W; ++c) any = any || cut[c];
    if (!any) return;
    for (double* v : vs)
      for (int i = 0; i < n; ++i)
        for (int c = 0; c < W; ++c)
          if (cut[c]) v[size_t(i) * W + c] = 0.0;
  };
  auto stop = [&](int c) {
    live[c] = 0.0;
    --active;
  };
  pre(r, p, rz, live);  // p = z the first time: made in place (z is not needed before the next one)
  for (int c = 0; c < W; ++c) cut[c] = live[c] == 0.0 && rz[c] != 0.0;  // rz = 0 . z: not 0 only when z is not finite
  zero({p});
  for (int it = 1; it <= max_iter; ++it) {
    op(p, q, dot);
    for (int c = 0; c < W; ++c) {
      alpha[c] = 0.0;
      cut[c] = false;
      if (live[c] == 0.0) continue;
      if (!(dot[c] > 0.0) || !std::isfinite(dot[c])) {  // breakdown: A not SPD along p, or NaN
        result[size_t(c)].iterations = it;
        result[size_t(c)].converged = false;
        stop(c);
        cut[c] = true;  // zeroed below
        continue;
      }
      alpha[c] = rz[c] / dot[c];
    }
    zero({r, p, q});
    for (int c = 0; c < W; ++c) rn[c] = 0.0;
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < W; ++c) {
        const size_t k = size_t(i) * W + c;
        x[k] += alpha[c] * p[k];
        r[k] -= alpha[c] * q[k];
        rn[c] += r[k] * r[k];
      }
    for (int c = 0; c < W; ++c) {
      if (live[c] == 0.0) continue;
      result[size_t(c)].iterations = it;
      result[size_t(c)].relative_residual = std::sqrt(rn[c] / bn[c]);
      if (std::sqrt(rn[c]) <= threshold[c]) stop(c);
    }
    if (active == 0) return;
    if (const int c = alone(); c >= 0) {
      if constexpr (!std::is_same_v<Col, NoColumnKernels>)
        detail::column_pcg<W>(col, c, n, x, threshold[c], bn[c], max_iter, it, false, rz[c], w, result[size_t(c)]);
      return;
    }
    double rz_new[W];
    pre(r, z, rz_new, live);
    for (int c = 0; c < W; ++c) {
      beta[c] = live[c] != 0.0 ? rz_new[c] / rz[c] : 0.0;
      rz[c] = rz_new[c];
    }
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < W; ++c) {
        const size_t k = size_t(i) * W + c;
        p[k] = z[k] + beta[c] * p[k];
      }
    for (int c = 0; c < W; ++c) cut[c] = live[c] == 0.0 && rz_new[c] != 0.0;
    zero({p});
  }
  for (int c = 0; c < W; ++c)
    if (live[c] != 0.0) result[size_t(c)].converged = false;
}

}  // namespace vdm
