#include "engine/mass_spring.hpp"

#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <map>

#include "engine/geometry.hpp"
#include "engine/sparse.hpp"

namespace vdm {

struct MassSpringWorkspace {
  std::vector<Eigen::Triplet<double>> triplets;
  SpMat K;
  Eigen::SimplicialLDLT<SpMat> ldlt;
  long analyzed = -1;
  NodeMat area;
};

namespace {

Vec to_vec(const NodeMat& a) {
  Vec v(a.size());
  for (Eigen::Index i = 0; i < a.rows(); ++i)
    for (int r = 0; r < 3; ++r) v[3 * i + r] = a(i, r);
  return v;
}

}  // namespace

bool build_mass_spring_model(const MassSpringDef& def, MassSpringModel& m, std::string& error) {
  m.n = static_cast<int>(def.positions.rows());
  if (m.n == 0) return error = "no nodes", false;
  m.rest = def.positions;
  m.triangles = def.triangles;
  m.edges = def.edges;
  if (m.edges.empty()) {
    std::map<std::array<int, 2>, int> seen;
    for (int t = 0; t < m.triangles.rows(); ++t)
      for (int c = 0; c < 3; ++c) {
        int a = m.triangles(t, c), b = m.triangles(t, (c + 1) % 3);
        if (a > b) std::swap(a, b);
        if (seen.emplace(std::array<int, 2>{a, b}, 0).second) m.edges.push_back({a, b});
      }
  }
  const int ne = static_cast<int>(m.edges.size());
  m.rest_length.resize(ne);
  for (int e = 0; e < ne; ++e) {
    const auto [a, b] = m.edges[static_cast<size_t>(e)];
    if (a < 0 || b < 0 || a >= m.n || b >= m.n || a == b) return error = "edge " + std::to_string(e) + " is invalid", false;
    m.rest_length[e] = (m.rest.row(a) - m.rest.row(b)).norm();
    if (!(m.rest_length[e] > 0)) return error = "edge " + std::to_string(e) + " has zero length", false;
  }
  if (def.stiffness.size() == ne) {
    m.stiffness = def.stiffness;
  } else {
    if (!(def.young_modulus > 0) || !(def.thickness > 0)) return error = "young_modulus and thickness must be > 0", false;
    // Van Gelder: k_e = E t sum_{triangles on e} area / L_e^2.
    std::map<std::array<int, 2>, double> area;
    for (int t = 0; t < m.triangles.rows(); ++t) {
      const Vec3 a = m.rest.row(m.triangles(t, 0)), b = m.rest.row(m.triangles(t, 1)), c = m.rest.row(m.triangles(t, 2));
      const double A = (b - a).cross(c - a).norm() / 2;
      for (int k = 0; k < 3; ++k) {
        int i = m.triangles(t, k), j = m.triangles(t, (k + 1) % 3);
        if (i > j) std::swap(i, j);
        area[{i, j}] += A;
      }
    }
    m.stiffness.resize(ne);
    for (int e = 0; e < ne; ++e)
      m.stiffness[e] = def.young_modulus * def.thickness * area[m.edges[static_cast<size_t>(e)]] /
                       (m.rest_length[e] * m.rest_length[e]);
  }
  m.volume_modulus = def.volume_modulus;
  m.origin = m.rest.colwise().mean().transpose();
  m.rest_volume = m.triangles.rows() ? enclosed_volume(m.rest, m.triangles, m.origin) : 0.0;
  if (m.volume_modulus > 0 && !(m.rest_volume > 0)) return error = "a volume spring needs a closed outward surface", false;
  m.fixed = def.fixed.rows() == m.n ? def.fixed : FlagMat::Zero(m.n, 3);
  m.size = (m.rest.colwise().maxCoeff() - m.rest.colwise().minCoeff()).norm();
  m.tolerance = def.tolerance;
  m.max_iterations = def.max_iterations;
  return true;
}

MassSpringState make_mass_spring_state(const MassSpringModel& m) {
  MassSpringState s;
  s.u = NodeMat::Zero(m.n, 3);
  s.reaction = NodeMat::Zero(m.n, 3);
  s.volume = m.rest_volume;
  s.work = std::make_shared<MassSpringWorkspace>();
  s.work->K.resize(3 * m.n, 3 * m.n);
  s.work->area = NodeMat::Zero(m.n, 3);
  return s;
}

double energy(const MassSpringModel& m, const NodeMat& u, const NodeMat& f, NodeMat* grad) {
  const NodeMat x = m.rest + u;
  double e = 0;
  if (grad) grad->setZero(m.n, 3);
  for (size_t k = 0; k < m.edges.size(); ++k) {
    const auto [a, b] = m.edges[k];
    const Vec3 d = x.row(a) - x.row(b);
    const double l = d.norm(), s = l - m.rest_length[static_cast<Eigen::Index>(k)];
    const double kk = m.stiffness[static_cast<Eigen::Index>(k)];
    e += 0.5 * kk * s * s;
    if (grad && l > 0) {
      const Vec3 g = kk * s * d / l;
      grad->row(a) += g.transpose();
      grad->row(b) -= g.transpose();
    }
  }
  if (m.volume_modulus > 0) {
    const double dv = enclosed_volume(x, m.triangles, m.origin) - m.rest_volume;
    e += 0.5 * m.volume_modulus * dv * dv / m.rest_volume;
    if (grad) {
      NodeMat A(m.n, 3);
      distributed_area_vectors(x, m.triangles, A);
      *grad += (m.volume_modulus * dv / m.rest_volume) * A;
    }
  }
  if (f.rows() == m.n) {
    e -= (f.array() * u.array()).sum();
    if (grad) *grad -= f;
  }
  return e;
}

void step(const MassSpringModel& m, const StepInput& in, MassSpringState& s) {
  MassSpringWorkspace& w = *s.work;
  const int dofs = 3 * m.n;
  NodeMat f = in.force.rows() == m.n ? in.force : NodeMat::Zero(m.n, 3);
  FlagMat mask = m.fixed;
  NodeMat target = NodeMat::Zero(m.n, 3);
  if (in.prescribed.rows() == m.n)
    for (int i = 0; i < m.n; ++i)
      for (int r = 0; r < 3; ++r)
        if (in.prescribed(i, r) && !m.fixed(i, r)) {
          mask(i, r) = 1;
          target(i, r) = in.prescribed_u(i, r);
        }
  // The constrained entries jump to their targets; the free ones follow by Newton.
  for (int i = 0; i < m.n; ++i)
    for (int r = 0; r < 3; ++r)
      if (mask(i, r)) s.u(i, r) = target(i, r);
  const double kmean = m.stiffness.size() ? m.stiffness.mean() : 1.0;
  s.iterations = 0;
  s.converged = false;
  NodeMat grad(m.n, 3);
  for (int it = 0; it < m.max_iterations; ++it) {
    const double e0 = energy(m, s.u, f, &grad);
    double free2 = 0, fixed2 = 0;
    for (int i = 0; i < m.n; ++i)
      for (int r = 0; r < 3; ++r) (mask(i, r) ? fixed2 : free2) += grad(i, r) * grad(i, r);
    const double scale = std::max({std::sqrt(f.squaredNorm()), std::sqrt(fixed2), kmean * m.size * 1e-6});  // at rest: above rounding
    s.residual = std::sqrt(free2) / scale;
    if (s.residual <= m.tolerance) {
      s.converged = true;
      break;
    }
    ++s.iterations;
    // Springs' Hessian, projected (a compressed spring gives no negative transverse stiffness),
    // plus a Levenberg-Marquardt term that vanishes with the residual.
    const NodeMat x = m.rest + s.u;
    w.triplets.clear();
    const double lm = kmean * std::min(1e-3, s.residual);
    for (int k = 0; k < dofs; ++k) w.triplets.emplace_back(k, k, lm);
    for (size_t k = 0; k < m.edges.size(); ++k) {
      const auto [a, b] = m.edges[k];
      const Vec3 d = x.row(a) - x.row(b);
      const double l = std::max(d.norm(), 1e-12 * m.size);
      const Vec3 nrm = d / l;
      const double kk = m.stiffness[static_cast<Eigen::Index>(k)];
      const double tr = std::max(0.0, 1.0 - m.rest_length[static_cast<Eigen::Index>(k)] / l);
      const Eigen::Matrix3d H = kk * (nrm * nrm.transpose() + tr * (Eigen::Matrix3d::Identity() - nrm * nrm.transpose()));
      const int nodes[2] = {a, b};
      for (int p = 0; p < 2; ++p)
        for (int q = 0; q < 2; ++q)
          for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) w.triplets.emplace_back(3 * nodes[p] + r, 3 * nodes[q] + c, (p == q ? 1 : -1) * H(r, c));
    }
    w.K.setFromTriplets(w.triplets.begin(), w.triplets.end());
    Vec mvec(dofs);
    for (int i = 0; i < m.n; ++i)
      for (int r = 0; r < 3; ++r) mvec[3 * i + r] = mask(i, r);
    for (int j = 0; j < w.K.outerSize(); ++j)
      for (SpMat::InnerIterator itk(w.K, j); itk; ++itk)
        if (mvec[itk.row()] != 0 || mvec[j] != 0) itk.valueRef() = itk.row() == j ? 1.0 : 0.0;
    if (w.K.nonZeros() != w.analyzed) {
      w.ldlt.analyzePattern(w.K);
      w.analyzed = w.K.nonZeros();
    }
    w.ldlt.factorize(w.K);
    Vec g = to_vec(grad);
    for (int k = 0; k < dofs; ++k)
      if (mvec[k] != 0) g[k] = 0;
    Vec du = w.ldlt.solve(-g);
    // The volume spring's Gauss-Newton term (K_v / V_0) a a^T, by Sherman-Morrison.
    if (m.volume_modulus > 0) {
      distributed_area_vectors(x, m.triangles, w.area);
      Vec a = to_vec(w.area);
      for (int k = 0; k < dofs; ++k)
        if (mvec[k] != 0) a[k] = 0;
      const Vec z = w.ldlt.solve(a);
      const double beta = m.volume_modulus / m.rest_volume;
      du -= z * (beta * a.dot(du) / (1 + beta * a.dot(z)));
    }
    const double slope = g.dot(du);
    double alpha = 1;
    bool ok = false;
    NodeMat trial(m.n, 3);
    for (int ls = 0; ls < 40 && !ok; ++ls, alpha /= 2) {
      for (int i = 0; i < m.n; ++i)
        for (int r = 0; r < 3; ++r) trial(i, r) = s.u(i, r) + alpha * du[3 * i + r];
      const double e = energy(m, trial, f, nullptr);
      ok = std::isfinite(e) && e <= e0 + 1e-4 * alpha * slope + 1e-13 * std::abs(e0);
    }
    if (!ok) break;
    s.u = trial;
    // A step at round-off: the residual cannot fall further (its floor is the gradient's
    // own rounding), so this is equilibrium.
    // Only a full Newton step counts: a tiny accepted step after many halvings is a stall.
    if (2 * alpha == 1.0 && du.cwiseAbs().maxCoeff() < 1e-13 * m.size) {
      s.converged = true;
      break;
    }
  }
  energy(m, s.u, f, &grad);
  s.reaction.setZero();
  for (int i = 0; i < m.n; ++i)
    for (int r = 0; r < 3; ++r)
      if (mask(i, r)) s.reaction(i, r) = grad(i, r);
  if (m.rest_volume > 0) {
    s.volume = enclosed_volume(m.rest + s.u, m.triangles, m.origin);
    s.volume_rel_error = (s.volume - m.rest_volume) / m.rest_volume;
    s.pressure = -m.volume_modulus * s.volume_rel_error;
  }
}

}  // namespace vdm
