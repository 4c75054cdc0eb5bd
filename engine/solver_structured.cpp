// Structured solver: u = r + dP s with K^d r^d = rhs^d and K^d s^d = a^d (six SPD solves by
// PCG with a modified IC(0), each warm-started), dP = (c - a.r) / (a.s). While the matrices are
// unchanged s is reused and only the three r solves run. The three axes are one system: each
// axis stops when its residual is below the tolerance times the norm of the whole right-hand
// side (all axes) over sqrt(3), so an axis that carries little load (x and y under a
// vertical probe) is not solved to a finer absolute accuracy than the others. (Warm starts
// extrapolated from the last two solutions were tried: with this ordering they saved one
// iteration in 50 and broke the 60 % cube's mirror symmetry test; not kept.)
// The solves run on a copy of K^d in reverse Cuthill-McKee order (engine/node_ordering), the
// three axes stored together (engine/axis_matrices): the three r solves, and the three s
// solves with them when s is due, run as one block PCG (engine/block_pcg.hpp) whose every
// column is its own PCG with its own stop; the matrix product and the IC(0) sweeps serve the
// whole block in one pass over the indices. Per contact frame of the bench's 10k liver this
// is one block of about 11 iterations (the s columns take longest) where the six separate
// solves took 50 iterations of one vector each with plain IC(0).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <vector>

#include "engine/axis_incomplete_cholesky.hpp"
#include "engine/axis_matrices.hpp"
#include "engine/block_pcg.hpp"
#include "engine/linear_solver.hpp"
#include "engine/node_ordering.hpp"

namespace vdm {
namespace {

// Relaxation of the modified IC(0) preconditioner (axis_incomplete_cholesky.hpp). On the
// bench's liver probe, PCG iterations per solve (the longest column of the block; 0 = plain
// IC(0)): 14.6 at omega 0, 11.3 at 0.8, 10.6 at 0.9 and 0.95, 11.5 at 1 (10k nodes); 11.3
// at 0, 9.2 at 0.9 (2.5k).
constexpr double kMicOmega = 0.9;

// Preconditioner reuse (matrices_changed()). On the bench's 10k liver probe at tolerance
// 1e-3, 60 frames: refactorising on every change, 67 factorisations, 4.27 iterations per
// frame; only when the constrained set changes or the iterations grow, 23 and 4.33; with a
// changed constrained set refitted instead (three runs of the 60 frames, callgrind), 72 -> 12
// factorisations, 4.47 -> 5.33 iterations per frame, 3 % fewer instructions per frame.
// kMaxStale 32 or 64 with the refit: 5.6 and 6.1 iterations, more instructions than 16.
constexpr int kMaxStale = 16;          // matrix changes a factorisation may serve at most
constexpr double kStaleGrowth = 1.5;   // refactorise once a solve needs this many times the first's (+2)
constexpr double kMaxRefit = 0.02;     // entries (over the node count) a refit may change at most

// The accuracy of s. u = r + P s leaves the residual P (K s - a) in K u = rhs + P a, so s
// needs |K s - a| below the tolerance times |rhs| / |P| (half of it, with the last solve's
// pressure for P), not times |a|: under an instrument |rhs| / |P| is often far above |a|, and
// with the membrane capsule the s columns (new on every change of the matrices) took most of
// the iterations. On the bench's 10k liver probe at tolerance 5e-3, s iterations per solve:
// 4.2 with s to |a|, 2.5 / 0.8 / 0.5 with s allowed 3 / 10 / 30 times that, the steps'
// residuals unchanged (8e-5 mean). At most kLooseS times: P may grow from one solve to the
// next, and dP's own accuracy (a.s) must not drift.
constexpr double kLooseS = 10.0;

// A matrix with more than this share of positive off-diagonal entries is far from an
// M-matrix (the capsule's bending term: about half of its two-ring pairs are positive; the
// membrane's cotangent weights make a few per cent positive, on obtuse triangles): its
// incomplete factorisation moves them onto the diagonal first (factorize's `compensate`).
// Without it the modified IC(0) of the bending term meets pivots near zero and overflows.
constexpr double kPositiveShare = 0.1;
// The relaxation for such a matrix: the compensated one is diagonally dominant, where MIC(0)
// keeps its row sums safely. probe_poke with bending_modulus 1e-3 N m (10k liver): 583 PCG
// iterations per contact frame at 0.9, 428 at 1, 984 at 0.5, 1252 at 0.
constexpr double kCompensatedOmega = 1.0;

// Counted on the assembled weights (entry (i, j) is -w_ij), before any constraint: the same
// answer for a run and for its resume from any step. A weight counts when it is below -1e-9
// of the largest: a right angle's cotangent comes out as +-1e-17 or so, not as 0.
bool far_from_m_matrix(const AxisStiffness& K) {
  const double floor = -1e-9 * (K.weight.size() ? K.weight.cwiseAbs().maxCoeff() : 0.0);
  Eigen::Index positive = 0;
  for (Eigen::Index e = 0; e < K.weight.size(); ++e) positive += K.weight[e] < floor;
  return double(positive) > kPositiveShare * double(K.weight.size());
}

class StructuredSolver final : public LinearSolver {
 public:
  explicit StructuredSolver(const SolverSettings& s) : settings_(s) {}

  void analyze(const StiffnessPattern& pattern) override {
    n_ = static_cast<int>(pattern.matrix.rows());
    perm_ = reverse_cuthill_mckee(pattern.matrix);
    iperm_.assign(size_t(n_), 0);
    for (int i = 0; i < n_; ++i) iperm_[size_t(perm_[size_t(i)])] = i;
    K_.analyze(pattern, perm_);
    ic_.analyze(K_);
    s_ = NodeMat::Zero(n_, 3);
    x_.assign(6 * size_t(n_), 0.0);
    r_last_.assign(3 * size_t(n_), 0.0f);
    have_last_ = {false, false, false};
    rate_ = {0.0, 0.0, 0.0};
    last_pressure_ = 0.0;
    std::vector<double>().swap(x3_);  // made by the first W = 3 solve (refresh_every > 1)
    work_.resize(6 * size_t(n_));
  }

  // The block PCG's z/q array: dead between solves, 6 N doubles once a block of both systems
  // has been solved (sized so by analyze()); growing within its capacity allocates nothing.
  double* spare_doubles(size_t count) override {
    std::vector<double>& z = work_.zq;
    if (z.capacity() < count) return nullptr;
    if (z.size() < count) z.resize(count);
    return z.data();
  }

  // A tolerance looser than the settings' (StepInput::tolerance) serves solves that will be
  // redone; s solved to it is not good enough for a tighter solve, which solves s again.
  void set_tolerance(double tolerance) override {
    if (tolerance < s_tolerance_) s_valid_ = false;
    tolerance_ = tolerance;
  }

  const NodeMat& pressure_response(const NodeMat& a) override {
    if (!s_valid_) {
      solve_block<3>(nullptr, &a, nullptr);
      s_valid_ = true;
      s_tolerance_ = tolerance_;
    }
    return s_;
  }

  // The new values are gathered at once; the preconditioner is refactorised only when there
  // are springs, when the solves since the last factorisation have grown (kStaleGrowth),
  // after kMaxStale matrix changes, or when the constrained set changed in more than
  // kMaxRefit of the entries (a smaller change refits the factors: fit_to_mask). Between
  // those, the last MIC(0) factors (of matrices a few steps old) still precondition well,
  // and PCG converges to the tolerance with any SPD preconditioner.
  void matrices_changed(const AxisSystem& system) override {
    K_.gather(*system.K, *system.mask, system.springs);
    s_valid_ = false;
    step_start_ = system.step_start;
    const bool new_shape = factor_mask_.rows() != system.mask->rows();
    if (new_shape) compensate_ = far_from_m_matrix(*system.K);
    const bool mask_changed = new_shape || std::memcmp(factor_mask_.data(), system.mask->data(), size_t(factor_mask_.size())) != 0;
    // Springs (penalty contact) are stiff diagonal terms that change with every solve.
    if (factor_due_ || new_shape || system.springs || ++stale_ > kMaxStale) {
      ic_.factorize(K_, compensate_ ? kCompensatedOmega : kMicOmega, compensate_);
      factor_mask_ = *system.mask;
      stale_ = 0;
      baseline_ = -1;
      factor_due_ = false;
      pending_factorizations_ = 3;
    } else if (mask_changed) {
      // A changed constrained set (the contact's nodes) refits the factors in place: a
      // factorisation again only when many entries changed at once, or when the solves
      // grow (kStaleGrowth).
      if (ic_.fit_to_mask(K_) > kMaxRefit * n_) {
        ic_.factorize(K_, compensate_ ? kCompensatedOmega : kMicOmega, compensate_);
        stale_ = 0;
        baseline_ = -1;
        pending_factorizations_ = 3;
      }
      factor_mask_ = *system.mask;
    }
  }

  void save_warm_state(std::vector<double>& out) const override {
    // r in node order (as put_warm() writes a NodeMat: column by column), from the block.
    for (size_t d = 0; d < 3; ++d)
      for (int node = 0; node < n_; ++node) out.push_back(x_[6 * size_t(iperm_[size_t(node)]) + 2 * d]);
    put_warm(out, s_);
    for (int g = 0; g < 2; ++g)  // the last solutions in solver order, r's then s's, 3 per row
      for (size_t i = 0; i < size_t(n_); ++i)
        for (size_t d = 0; d < 3; ++d) out.push_back(x_[6 * i + 2 * d + size_t(g)]);
    out.push_back(s_valid_ ? 1.0 : 0.0);
    out.push_back(pending_factorizations_);
    // The preconditioner in use may be older than the matrices: its values and reuse state.
    ic_.save_values(out);
    out.push_back(double(factor_mask_.rows()));
    out.insert(out.end(), factor_mask_.data(), factor_mask_.data() + factor_mask_.size());
    out.push_back(stale_);
    out.push_back(baseline_);
    out.push_back(factor_due_ ? 1.0 : 0.0);
    // The Galerkin steps' directions (floats: exact as doubles).
    out.insert(out.end(), r_last_.begin(), r_last_.end());
    for (size_t d = 0; d < 3; ++d) {
      out.push_back(have_last_[d] ? 1.0 : 0.0);
      out.push_back(rate_[d]);
    }
    out.push_back(last_pressure_);
  }

  // After matrices_changed() with the snapshot's matrices (which refactorised: the saved
  // factors replace those).
  bool load_warm_state(const std::vector<double>& in) override {
    size_t pos = 0;
    // r in node order: the block's r lanes below hold it (in solver order).
    if (in.size() < pos + 3 * size_t(n_)) return false;
    pos += 3 * size_t(n_);
    if (!take_warm(in, pos, s_)) return false;
    if (in.size() < pos + x_.size() + 2) return false;
    for (int g = 0; g < 2; ++g)
      for (size_t i = 0; i < size_t(n_); ++i)
        for (size_t d = 0; d < 3; ++d) x_[6 * i + 2 * d + size_t(g)] = in[pos++];
    s_valid_ = in[pos] != 0.0;
    pending_factorizations_ = static_cast<int>(in[pos + 1]);
    pos += 2;
    if (!ic_.load_values(in, pos) || in.size() <= pos) return false;
    const double rows = in[pos++];
    const size_t rest = size_t(3 * rows) + 3 + r_last_.size() + 7;  // mask, reuse state, Galerkin steps, P
    if (!(rows == 0.0 || rows == double(n_)) || in.size() != pos + rest) return false;
    factor_mask_.resize(Eigen::Index(rows), 3);
    for (Eigen::Index k = 0; k < factor_mask_.size(); ++k) factor_mask_.data()[k] = static_cast<std::uint8_t>(in[pos++]);
    stale_ = static_cast<int>(in[pos]);
    baseline_ = static_cast<int>(in[pos + 1]);
    factor_due_ = in[pos + 2] != 0.0;
    pos += 3;
    for (float& v : r_last_) v = float(in[pos++]);
    for (size_t d = 0; d < 3; ++d) {
      have_last_[d] = in[pos++] != 0.0;
      rate_[d] = in[pos++];
    }
    last_pressure_ = in[pos++];
    return true;
  }

  // K_ holds the permuted, eliminated values of the system last given to matrices_changed().
  SolveReport solve(const NodeMat& rhs, const NodeMat& a, double c, bool volume_constraint, NodeMat& u,
                    double& dP) override {
    SolveReport rep;
    rep.factorizations = pending_factorizations_;
    pending_factorizations_ = 0;
    const bool new_s = volume_constraint && !s_valid_;
    const bool project = step_start_ && settings_.warm_start;  // (only the first solve after the step's matrices)
    step_start_ = false;
    // Both systems: u = r + dP s made by solve_block<6> (from the block, dP on the way);
    // r alone: straight into u, then u = r + dP s.
    const BlockReport br =
        new_s ? solve_block<6>(&rhs, &a, &u, project, c, &dP) : solve_block<3>(&rhs, nullptr, &u, project);
    rep.iterations = br.iterations;
    rep.converged = br.converged;
    // The first solve on new matrices tells how well the factors fit; only solves to the
    // settings' tolerance are compared (a looser one takes fewer iterations).
    if (new_s && tolerance_ == settings_.tolerance) {
      if (baseline_ < 0) baseline_ = br.iterations;
      else if (br.iterations > kStaleGrowth * baseline_ + 2) factor_due_ = true;
    }
    if (new_s) s_tolerance_ = tolerance_;
    if (volume_constraint) s_valid_ = true;
    if (!new_s) {
      dP = volume_constraint ? pressure_for_volume(a, u, s_, c) : 0.0;
      u += dP * s_;
    }
    return rep;
  }

 private:
  struct BlockReport {
    int iterations = 0;  // summed over the columns (the per-axis solves)
    bool converged = true;
  };

  // K^d r^d = rhs^d (rhs given) and K^d s^d = a^d (a given) by block PCG with IC(0) in the
  // permuted order, warm-started from the last solutions (x_), each axis until
  // |b - K x| <= tolerance |b_all| / sqrt(3) (b_all: that right-hand side on all axes). The
  // results go to *r (the caller's) and s_ in node order. W = 3 for one of them, 6 for both:
  // then *r is u = r + dP s instead, with *dP the pressure that gives the volume row a.u = c.
  // project_r: a step's first solve, whose columns of r may take a Galerkin step first.
  template <int W>
  BlockReport solve_block(const NodeMat* rhs, const NodeMat* a, NodeMat* r, bool project_r = false, double c = 0.0,
                          double* dP = nullptr) {
    constexpr int G = W / 3;  // systems per axis: column d G + g is axis d of system g
    const NodeMat* src[2] = {rhs ? rhs : a, rhs ? a : nullptr};
    const size_t lane[2] = {rhs ? 0u : 1u, 1u};  // the system's lane in x_ (0: r, 1: s)
    NodeMat* out[2] = {rhs ? r : &s_, &s_};
    // The block of both systems is x_ itself; one system alone iterates in x3_, made by the
    // first such solve: a scene that refreshes the geometry every step never has one (1 MB
    // at 40k nodes; a warmed-up step still allocates nothing: the second step has one).
    if (W == 3 && x3_.size() != 3 * size_t(n_)) x3_.assign(3 * size_t(n_), 0.0);
    double* x = W == 6 ? x_.data() : x3_.data();
    // The right-hand sides, column c = d G + g of the block being axis d of system g, in node
    // order: residual_block reads each row of them where its pass needs it. Only when it
    // cannot (rows constrained on some axes only) are they copied into the block PCG's
    // residual array, which block_pcg() then reads as b before it writes the residual there
    // (sized first: resizing would clear them); each node's entries to its row of the block
    // (reading the columns in solver order missed on every load).
    work_.resize(size_t(n_) * W);
    double* const bw = work_.r.data();
    if (W == 6 && !settings_.warm_start) std::fill(x_.begin(), x_.end(), 0.0);
    double threshold[W];
    std::array<const double*, G> b_src;
    for (int g = 0; g < G; ++g) b_src[size_t(g)] = src[g]->data();
    const bool b_in_block = K_.partial_count != 0;
    if (b_in_block) {
      const double* bc[G][3];
      for (int g = 0; g < G; ++g)
        for (int d = 0; d < 3; ++d) bc[g][d] = src[g]->col(d).data();
      const int* iperm = iperm_.data();
      for (int node = 0; node < n_; ++node) {
        double* row = bw + size_t(iperm[node]) * W;
        for (int g = 0; g < G; ++g)
          for (int d = 0; d < 3; ++d) row[d * G + g] = bc[g][d][node];
      }
    }
    for (int g = 0; g < G; ++g) {
      if (W == 3)
        for (size_t i = 0; i < size_t(n_); ++i)
          for (size_t d = 0; d < 3; ++d) x[i * 3 + d] = settings_.warm_start ? x_[6 * i + 2 * d + lane[g]] : 0.0;
      // sqrt(3): the three axes together then meet the tolerance on the whole system.
      double t = tolerance_ * src[g]->norm() / std::sqrt(3.0);
      if (W == 6 && g == 1 && last_pressure_ != 0.0) {  // s: as exact as its share of u needs (kLooseS)
        const double needed = 0.5 * tolerance_ * src[0]->norm() / (std::sqrt(3.0) * std::abs(last_pressure_));
        t = std::max(t, std::min(needed, kLooseS * t));
      }
      for (int d = 0; d < 3; ++d) threshold[d * G + g] = t;
    }
    const AxisMatrices& K = K_;
    const AxisIncompleteCholesky& ic = ic_;
    auto op = [&K](const double* in, double* res, double* dot) { multiply_block<W>(K, in, res, dot); };
    auto pre = [&ic](const double* in, double* res, double* dot, const double* live) {
      ic.apply<W>(in, res, dot, live);
    };
    // A column left iterating alone (usually r^z under a vertical probe) is taken out of the
    // block and runs on the one-vector kernels: the same iterates, bit for bit. The start's
    // residual and norms in one pass.
    // The start's residual takes b from the node-order columns (block_pcg() reads b only when
    // residual() fails: with b_in_block).
    // At a step's first solve, a column of r whose warm start misses the tolerance first
    // takes a Galerkin step along its change since the last such step (project_along_step):
    // while an instrument holds or moves steadily the solution changes from one step to the
    // next by about the same shape.
    const bool project = rhs != nullptr && project_r;
    double start[W] = {};
    struct Columns {
      const AxisMatrices& K;
      const AxisIncompleteCholesky& ic;
      const std::array<const double*, G>& b_src;
      StructuredSolver& solver;
      bool project_r;  // Galerkin steps for the columns of r
      double* start;   // per column of r: |r_c| / |b_c| when its iterations start (0: not at a
                       // step's first solve, or under its threshold)
      double multiply(int c, const double* in, double* out) const { return multiply_axis(K, axis_of<W>(c), in, out); }
      double apply(int c, const double* in, double* out) const { return ic.apply_axis(axis_of<W>(c), in, out); }
      bool residual(const double*, const double* in, double* r, double* bn, double* rn) const {
        return residual_block<W>(K, b_src, in, r, bn, rn);
      }
      bool project(int c, double* x, double* r, double& rn, double bn, double threshold, double* scratch) const {
        if (!project_r || c % G != 0) return false;  // columns of s
        const bool moved = solver.project_along_step<W>(c, x, r, rn, threshold, scratch);
        start[c] = std::sqrt(rn / bn);
        return moved;
      }
    };
    std::array<KrylovResult, W> kr;
    block_pcg<W>(op, pre, n_, bw, x, threshold, settings_.max_iterations, work_, kr,
                 Columns{K, ic, b_src, *this, project, start});
    // Each column of r that iterated at a step's first solve: its convergence factor per
    // iteration, for the next step's choice (project_along_step).
    for (int c = 0; c < W; c += G)
      if (start[c] > 0.0 && kr[size_t(c)].iterations > 0 && kr[size_t(c)].relative_residual > 0.0)
        rate_[size_t(axis_of<W>(c))] =
            std::pow(kr[size_t(c)].relative_residual / start[c], 1.0 / kr[size_t(c)].iterations);
    BlockReport rep;
    for (const KrylovResult& k : kr) {
      rep.iterations += k.iterations;
      rep.converged = rep.converged && k.converged;
    }
    if (W == 3)
      for (size_t i = 0; i < size_t(n_); ++i)
        for (size_t d = 0; d < 3; ++d) x_[6 * i + 2 * d + lane[0]] = x[i * 3 + d];
    // Out in node order (gathering rows of the block: one cache line each, where scattering
    // into the three columns of `out` missed on every store).
    double* o[2][3];
    for (int g = 0; g < G; ++g)
      for (int d = 0; d < 3; ++d) o[g][d] = out[g]->col(d).data();
    if constexpr (W == 6) {
      // s out, with the volume row's a.r and a.s on the way; then u = r + dP s from the block:
      // u written once, and no pass over a, u and s of their own (at 40k nodes, 2-3 % of the
      // step).
      const double* ad[3] = {a->col(0).data(), a->col(1).data(), a->col(2).data()};
      double as = 0.0, ar = 0.0;
      for (int node = 0; node < n_; ++node) {
        const double* row = x + size_t(iperm_[size_t(node)]) * W;
        for (int d = 0; d < 3; ++d) {
          const double ai = ad[d][node];
          ar += ai * row[2 * d];
          as += ai * row[2 * d + 1];
          o[1][d][node] = row[2 * d + 1];
        }
      }
      // a.s > 0 whenever some node can move (pressure_for_volume()).
      const double p = (as > 0.0 && std::isfinite(as)) ? (c - ar) / as : 0.0;
      *dP = p;
      last_pressure_ = p;
      for (int node = 0; node < n_; ++node) {
        const double* row = x + size_t(iperm_[size_t(node)]) * W;
        for (int d = 0; d < 3; ++d) o[0][d][node] = row[2 * d] + p * row[2 * d + 1];
      }
      return rep;
    }
    for (int node = 0; node < n_; ++node) {
      const double* row = x + size_t(iperm_[size_t(node)]) * W;
      for (int g = 0; g < G; ++g)
        for (int d = 0; d < 3; ++d) o[g][d][node] = row[d * G + g];
    }
    return rep;
  }

  // The Galerkin step of column c (a column of r, axis d) at a step's first solve, along
  // v = x_c - r_last_ (its change since the last step that took one): x_c += t v and
  // r_c -= t K v with t = v.r_c / v.K v, the point of the line x_c + t v nearest the solution
  // in K's norm (never farther than x_c). rn = |r_c|^2 after it; r_last_ becomes x_c as it
  // was. It costs about half an iteration and saves about one, so it is taken only where the
  // column would need two or more: when the residual is more than 1 / rate over the
  // threshold, rate being the column's convergence factor per iteration at the last step
  // (rate_; none measured yet: not taken). False, with x and r unchanged, when not taken.
  // scratch: 2 n doubles (v, then K v).
  template <int W>
  bool project_along_step(int c, double* x, double* r, double& rn, double threshold, double* scratch) {
    const size_t d = size_t(axis_of<W>(c));
    float* last = r_last_.data() + d * size_t(n_);
    if (!(rate_[d] > 0.0 && std::sqrt(rn) * rate_[d] > threshold)) return false;
    if (!have_last_[d]) {  // the first: only its start kept
      for (int i = 0; i < n_; ++i) last[i] = float(x[size_t(i) * W + size_t(c)]);
      have_last_[d] = true;
      return false;
    }
    double* v = scratch;
    double* kv = scratch + n_;
    double vr = 0.0;
    for (int i = 0; i < n_; ++i) {
      const size_t k = size_t(i) * W + size_t(c);
      v[i] = x[k] - double(last[i]);
      last[i] = float(x[k]);
      vr += v[i] * r[k];
    }
    const double vkv = multiply_axis(K_, int(d), v, kv);
    const double t = vr / vkv;
    if (!(vkv > 0.0) || !std::isfinite(t)) return false;
    double sum = 0.0;
    for (int i = 0; i < n_; ++i) {
      const size_t k = size_t(i) * W + size_t(c);
      x[k] += t * v[i];
      r[k] -= t * kv[i];
      sum += r[k] * r[k];
    }
    rn = sum;
    return true;
  }

  SolverSettings settings_;
  double tolerance_ = settings_.tolerance;    // the solves' (set_tolerance)
  double s_tolerance_ = settings_.tolerance;  // the tolerance s_ was solved to
  int n_ = 0;
  std::vector<int> perm_;        // solver index -> node (reverse Cuthill-McKee)
  std::vector<int> iperm_;       // node -> solver index
  AxisMatrices K_;               // permuted K^x, K^y, K^z
  AxisIncompleteCholesky ic_;
  NodeMat s_;                    // node order (r goes to the caller's u)
  std::vector<double> x_;        // solver order, 6 per row (r^x s^x r^y s^y r^z s^z): the last
                                 // solutions, the warm starts, and the block of a W = 6 solve
  std::vector<double> x3_;       // the block of a W = 3 solve (one system; empty before one)
  // Per axis of r: its value at the last Galerkin step's start (3 n floats, axis after axis,
  // solver order; floats: a direction needs no more), whether there is one, and the column's
  // last convergence factor per iteration (project_along_step).
  std::vector<float> r_last_;
  std::array<bool, 3> have_last_ = {false, false, false};
  std::array<double, 3> rate_ = {0.0, 0.0, 0.0};
  bool step_start_ = false;  // the matrices are a step's first (AxisSystem::step_start)
  BlockPcgWorkspace work_;
  bool s_valid_ = false;
  int pending_factorizations_ = 0;
  // Preconditioner reuse: the constrained set of the factors, matrix changes since they were
  // made, the iterations of the first solve with them, whether to refactorise next time.
  FlagMat factor_mask_;
  int stale_ = 0, baseline_ = -1;
  double last_pressure_ = 0.0;
  bool compensate_ = false;  // far_from_m_matrix() at the first gather
  bool factor_due_ = false;
};

}  // namespace

std::unique_ptr<LinearSolver> make_structured_solver(const SolverSettings& s) {
  return std::make_unique<StructuredSolver>(s);
}

}  // namespace vdm
