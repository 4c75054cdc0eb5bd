// The elastic core's static step (engine/core/elastic_core.hpp).
//
// With the cubes' rotations held, the energy is quadratic and the same on every axis but for
// which surface entries are prescribed. A free surface entry is tied only to the lattice, so it
// is eliminated exactly: u_i = (W v)_i + (f_i - lambda A_i) / k_i, where lambda is the volume
// row's multiplier (the fluid's pressure is -lambda). What is left per axis is the lattice's
// system, K_d v_d = b_d - lambda a_d, with
//   K_d = K_core + sum over prescribed entries k_i W_i^T W_i,
//   b_d = the rotations' load + the weight + sum over free entries W_i^T f_i
//         + sum over prescribed k_i u_i W_i^T,
//   a_d = sum over free entries A_i W_i^T,
// and the volume row (linearised at the current surface) gives lambda. The rotations are fitted
// again after each solve (the as-rigid-as-possible fixed point), accelerated by Anderson mixing.
#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#ifdef VDMSIM_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#endif

#include <algorithm>
#include <cmath>
#include <vector>

#include "engine/core/elastic_core.hpp"
#include "engine/geometry.hpp"
#include "engine/warnings.hpp"

namespace vdm::core {

struct CoreWorkspace {
  SpMat K[3];
#ifdef VDMSIM_HAVE_CHOLMOD
  Eigen::CholmodSupernodalLLT<SpMat, Eigen::Lower> chol[3];
#else
  Eigen::SimplicialLDLT<SpMat> chol[3];
#endif
  FlagMat factored_mask;      // the prescribed entries each axis's factor was made for
  bool factored[3] = {false, false, false};
  bool analyzed = false;
  std::vector<Eigen::Matrix3d> rotation;
  std::vector<Eigen::Quaterniond> quaternion;  // per tet, the last rotations (warm start)
  NodeMat area, force, target, x;
  FlagMat mask;
  Vec b, a, y0, y1;
  NodeMat v_new, u_new;
  // Anderson mixing of the lattice's displacements: differences of iterates and of residuals.
  Eigen::MatrixXd dX, dG;
  Vec response;  // per axis K_d^-1 a_d (3 ng)
  Vec x_prev, g_prev, g, mixed;
  int history = 0, next = 0;
};

namespace {

// The rotation R maximising tr(R^T F), by rotating q towards F about the axis of the torque
// sum_k R e_k x F e_k (Mueller, Chentanez, Kim and Macklin 2016): from a warm start it takes
// one to three iterations, where a 3x3 SVD costs several times one.
Eigen::Matrix3d nearest_rotation(const Eigen::Matrix3d& F, Eigen::Quaterniond& q) {
  Eigen::Matrix3d R = q.toRotationMatrix();
  for (int it = 0; it < 40; ++it) {
    const Vec3 torque = R.col(0).cross(F.col(0)) + R.col(1).cross(F.col(1)) + R.col(2).cross(F.col(2));
    const double scale = std::abs(R.col(0).dot(F.col(0)) + R.col(1).dot(F.col(1)) + R.col(2).dot(F.col(2))) + 1e-12;
    const Vec3 omega = torque / scale;
    const double angle = omega.norm();
    if (angle < 1e-10) break;  // the rotation to 1e-10 rad: its load is then exact to far below the tolerance
    q = Eigen::Quaterniond(Eigen::AngleAxisd(angle, omega / angle)) * q;
    q.normalize();
    R = q.toRotationMatrix();
  }
  return R;
}

void factorize(const CoreModel& m, int d, CoreWorkspace& w, CoreState& s) {
  SpMat& K = w.K[d];
  K = m.K_core;
  // A tiny share of the diagonal keeps an axis with no prescribed entry (free translation)
  // solvable: it moves the answer by about 1e-10 of itself.
  const double reg = 1e-10 * m.K_core.diagonal().maxCoeff();
  for (int k = 0; k < m.ng; ++k) K.coeffRef(k, k) += reg;
  for (int i = 0; i < m.ns; ++i) {
    if (!w.mask(i, d)) continue;
    for (int p = 0; p < 4; ++p)
      for (int q = 0; q < 4; ++q)
        K.coeffRef(m.tie_node(i, p), m.tie_node(i, q)) += m.tie_k[i] * m.tie_weight(i, p) * m.tie_weight(i, q);
  }
#ifdef VDMSIM_HAVE_CHOLMOD
  w.chol[d].cholmod().print = 0;
#endif
  if (!w.analyzed) {
    for (int e = 0; e < 3; ++e) w.chol[e].analyzePattern(K);  // the ties' entries are Kuhn-tet edges: same pattern
    w.analyzed = true;
  }
  w.chol[d].factorize(K);
  w.factored[d] = w.chol[d].info() == Eigen::Success;
  ++s.stats.factorizations;
}

// The lattice's motion at surface node i's rest position, axis d: (W v)_i^d.
double tied(const CoreModel& m, const NodeMat& v, int i, int d) {
  double wv = 0;
  for (int p = 0; p < 4; ++p) wv += m.tie_weight(i, p) * v(m.tie_node(i, p), d);
  return wv;
}

// The surface from the lattice: prescribed entries at their targets, free ones eliminated,
// u_i = (W v)_i + (f_i - lambda A_i) / k_i.
void surface_from_lattice(const CoreModel& m, const CoreWorkspace& w, const NodeMat& v, double lambda, NodeMat& u) {
  for (int i = 0; i < m.ns; ++i)
    for (int d = 0; d < 3; ++d)
      u(i, d) = w.mask(i, d) ? w.target(i, d) : tied(m, v, i, d) + (w.force(i, d) - lambda * w.area(i, d)) / m.tie_k[i];
}

}  // namespace

CoreState::CoreState() = default;
CoreState::~CoreState() = default;
CoreState::CoreState(CoreState&&) noexcept = default;
CoreState& CoreState::operator=(CoreState&&) noexcept = default;

CoreState make_core_state(const CoreModel& m) {
  CoreState s;
  s.u = NodeMat::Zero(m.ns, 3);
  s.v = NodeMat::Zero(m.ng, 3);
  s.reaction = NodeMat::Zero(m.ns, 3);
  s.volume = m.rest_volume;
  s.work = std::make_unique<CoreWorkspace>();
  CoreWorkspace& w = *s.work;
  w.rotation.assign(static_cast<size_t>(6 * m.cubes.rows()), Eigen::Matrix3d::Identity());
  w.quaternion.assign(w.rotation.size(), Eigen::Quaterniond::Identity());
  w.area = w.force = w.target = w.x = w.u_new = NodeMat::Zero(m.ns, 3);
  w.mask = w.factored_mask = FlagMat::Zero(m.ns, 3);
  w.b = w.a = w.y0 = w.y1 = Vec::Zero(m.ng);
  w.v_new = NodeMat::Zero(m.ng, 3);
  const int n = 3 * m.ng, h = std::max(1, m.settings.anderson);
  w.dX = w.dG = Eigen::MatrixXd::Zero(n, h);
  w.x_prev = w.g_prev = w.g = w.mixed = w.response = Vec::Zero(n);
  return s;
}

void tet_rotations(const CoreModel& m, const NodeMat& v, std::vector<Eigen::Quaterniond>& Q, std::vector<Eigen::Matrix3d>& R) {
  R.resize(static_cast<size_t>(6 * m.cubes.rows()));
  Q.resize(R.size(), Eigen::Quaterniond::Identity());
  const UnitCube& cube = unit_cube();
  for (Eigen::Index q = 0; q < m.cubes.rows(); ++q)
    for (int t = 0; t < 6; ++t) {
      // F = I + sum_a v_a (x) grad N_a, the unit cube's gradients over h.
      Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
      for (int a = 0; a < 4; ++a) F += v.row(m.cubes(q, cube.corner[t][a])).transpose() * cube.grad[t].row(a) / m.h;
      R[static_cast<size_t>(6 * q + t)] = nearest_rotation(F, Q[static_cast<size_t>(6 * q + t)]);
    }
}

void step(const CoreModel& m, const StepInput& in, CoreState& s) {
  CoreWorkspace& w = *s.work;
  s.stats = CoreStats{};
  const int ns = m.ns, ng = m.ng;
  // What is prescribed, to what; the external forces.
  w.mask = m.fixed;
  w.target.setZero();
  if (in.prescribed.rows() == ns)
    for (int i = 0; i < ns; ++i)
      for (int d = 0; d < 3; ++d)
        if (in.prescribed(i, d) && !m.fixed(i, d)) {
          w.mask(i, d) = 1;
          w.target(i, d) = in.prescribed_u(i, d);
        }
  w.force.setZero();
  if (in.force.rows() == ns) w.force = in.force;
  if (in.pressure.size() == ns) {
    w.x = m.surface.positions + s.u;
    distributed_area_vectors(w.x, m.surface.triangles, w.area);
    for (int i = 0; i < ns; ++i) w.force.row(i) -= in.pressure[i] * w.area.row(i);
  }
  for (int d = 0; d < 3; ++d)
    if (!w.factored[d] || w.factored_mask.col(d) != w.mask.col(d)) {
      factorize(m, d, w, s);
      w.factored_mask.col(d) = w.mask.col(d);
      if (!w.factored[d]) {
        s.stats.converged = false;
        if (s.warnings.size() < kMaxWarnings) s.warnings.emplace_back("elastic core: the lattice's matrix did not factorise");
        return;
      }
    }
  const int depth = m.settings.anderson;
  w.history = w.next = 0;
  double lambda = 0;
  const double tol = m.settings.tolerance * m.size;
  Eigen::Map<Vec> v_flat(s.v.data(), 3 * ng), v_new_flat(w.v_new.data(), 3 * ng);
  double g_norm_prev = 0;
  bool done = false;
  for (int it = 0; it < m.settings.max_iterations && !done; ++it) {
    ++s.stats.iterations;
    w.x = m.surface.positions + s.u;
    distributed_area_vectors(w.x, m.surface.triangles, w.area);
    const double V = enclosed_volume(w.x, m.surface.triangles, Vec3::Zero());
    double c = m.rest_volume - V;
    for (int i = 0; i < ns; ++i)
      for (int d = 0; d < 3; ++d) c += w.area(i, d) * (s.u(i, d) - (w.mask(i, d) ? w.target(i, d) : 0.0));
    tet_rotations(m, s.v, w.quaternion, w.rotation);
    double num = -c, den = 0;
    for (int d = 0; d < 3; ++d) {
      if (m.gravity_load.rows() == ng) w.b = m.gravity_load.col(d);
      else w.b.setZero();
      w.a.setZero();
      const UnitCube& cube = unit_cube();
      for (Eigen::Index q = 0; q < m.cubes.rows(); ++q) {
        // The lagged rotation's load, 2 mu f V_t (R_t - I) grad N_a per corner (V_t = h^3 / 6).
        const double scale = 2 * m.mu * m.fill[q] * m.h * m.h / 6;
        for (int t = 0; t < 6; ++t) {
          const Eigen::RowVector3d r = w.rotation[static_cast<size_t>(6 * q + t)].row(d) - Eigen::RowVector3d::Unit(d);
          for (int a = 0; a < 4; ++a) w.b[m.cubes(q, cube.corner[t][a])] += scale * r.dot(cube.grad[t].row(a));
        }
      }
      for (int i = 0; i < ns; ++i) {
        const double load = w.mask(i, d) ? m.tie_k[i] * w.target(i, d) : w.force(i, d);
        for (int p = 0; p < 4; ++p) w.b[m.tie_node(i, p)] += m.tie_weight(i, p) * load;
        if (w.mask(i, d)) continue;
        const double A = w.area(i, d);
        for (int p = 0; p < 4; ++p) w.a[m.tie_node(i, p)] += m.tie_weight(i, p) * A;
        num += A * w.force(i, d) / m.tie_k[i];
        den += A * A / m.tie_k[i];
      }
      w.y0 = w.chol[d].solve(w.b);
      w.y1 = w.chol[d].solve(w.a);
      num += w.a.dot(w.y0);
      den += w.a.dot(w.y1);
      w.v_new.col(d) = w.y0;
      w.response.segment(d * ng, ng) = w.y1;
    }
    lambda = den > 0 ? num / den : 0.0;
    for (int d = 0; d < 3; ++d) w.v_new.col(d) -= lambda * w.response.segment(d * ng, ng);
    // How far the surface and the lattice moved (the lattice too: with every surface entry
    // prescribed the surface does not tell).
    surface_from_lattice(m, w, w.v_new, lambda, w.u_new);
    const double change = std::max((w.u_new - s.u).cwiseAbs().maxCoeff(), (w.v_new - s.v).cwiseAbs().maxCoeff());
    s.stats.change = change / m.size;
    if (change <= tol) {
      s.v = w.v_new;
      s.u = w.u_new;
      done = true;
      break;
    }
    // Anderson mixing on v: x = v, G(x) = v_new, residual g = G(x) - x.
    w.g = v_new_flat - v_flat;
    const double g_norm = w.g.norm();
    if (depth <= 0) {
      s.v = w.v_new;
    } else {
      if (it > 0) {
        if (g_norm > 2 * g_norm_prev) {  // the mix diverges: start its history afresh
          w.history = w.next = 0;
        } else {
          w.dX.col(w.next) = v_flat - w.x_prev;
          w.dG.col(w.next) = w.g - w.g_prev;
          w.next = (w.next + 1) % depth;
          w.history = std::min(w.history + 1, depth);
        }
      }
      w.x_prev = v_flat;
      w.g_prev = w.g;
      if (w.history > 0) {
        const auto dG = w.dG.leftCols(w.history);
        const auto dX = w.dX.leftCols(w.history);
        Eigen::MatrixXd M = dG.transpose() * dG;
        M.diagonal().array() += 1e-12 * M.diagonal().maxCoeff() + 1e-300;
        const Vec gamma = M.ldlt().solve(dG.transpose() * w.g);
        w.mixed = v_flat + w.g - (dX + dG) * gamma;
        v_flat = w.mixed;
      } else {
        s.v = w.v_new;
      }
    }
    g_norm_prev = g_norm;
    // The surface follows the mixed lattice for the next linearisation.
    surface_from_lattice(m, w, s.v, lambda, s.u);
  }
  if (!done) {
    s.v = w.v_new;
    s.u = w.u_new;
    s.stats.converged = false;
    if (s.warnings.size() < kMaxWarnings) s.warnings.emplace_back("elastic core: a step did not converge");
  }
  // Reactions at the prescribed entries: the tie's pull, less the load, plus the pressure.
  s.reaction.setZero();
  for (int i = 0; i < ns; ++i)
    for (int d = 0; d < 3; ++d) {
      if (!w.mask(i, d)) continue;
      s.reaction(i, d) = m.tie_k[i] * (s.u(i, d) - tied(m, s.v, i, d)) - w.force(i, d) + lambda * w.area(i, d);
    }
  s.pressure = -lambda;
  w.x = m.surface.positions + s.u;
  s.volume = enclosed_volume(w.x, m.surface.triangles, Vec3::Zero());
  s.volume_rel_error = (s.volume - m.rest_volume) / m.rest_volume;
}

}  // namespace vdm::core
