// What every solver does with an AxisSystem (linear_solver.hpp): the eliminated matrices, their
// mean diagonal, the pressure that meets the volume row.
#include <algorithm>
#include <cmath>

#include "engine/linear_solver.hpp"
#include "engine/simd2.hpp"

namespace vdm {

void eliminate_constraints(const AxisSystem& system, std::array<SpMat, 3>& K_masked) {
  const StiffnessPattern& p = *system.pattern;
  const AxisStiffness& K = *system.K;
  for (int d = 0; d < 3; ++d) {
    const std::uint8_t* mask = system.mask->col(d).data();
    const double* k = system.springs ? system.springs->col(d).data() : nullptr;
    double* v = K_masked[size_t(d)].valuePtr();
    for (size_t e = 0; e < p.edges.size(); ++e) {
      const bool held = mask[p.edges[e][0]] || mask[p.edges[e][1]];
      v[p.edge_slot[e][0]] = v[p.edge_slot[e][1]] = held ? 0.0 : -K.weight[Eigen::Index(e)];
    }
    const double* diag = K.diagonal.col(d).data();
    for (size_t i = 0; i < p.diagonal.size(); ++i) v[p.diagonal[i]] = mask[i] ? 1.0 : diag[i] + (k ? k[i] : 0.0);
  }
}

double eliminated_mean_diagonal(const AxisSystem& system, const NodeMat* a, NodeMat* a_free) {
  // The N x 3 arrays as one run of 3 N entries, 16 at a time: a block without a constrained
  // entry (most: the held and prescribed ones are few) is summed in pairs (four independent
  // sums), with a_free = a; the entries of the other blocks one by one.
  const size_t count = size_t(system.K->diagonal.size());
  const double* diag = system.K->diagonal.data();
  const std::uint8_t* mask = system.mask->data();
  const double* k = system.springs ? system.springs->data() : nullptr;
  const double* ad = a_free ? a->data() : nullptr;
  double* fd = a_free ? a_free->data() : nullptr;
  using simd::V2;
  using simd::load2;
  V2 s0 = {0.0, 0.0}, s1 = {0.0, 0.0};
  double rest = 0.0;
  auto one_by_one = [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      if (fd) fd[i] = mask[i] ? 0.0 : ad[i];
      rest += mask[i] ? 1.0 : std::abs(diag[i] + (k ? k[i] : 0.0));
    }
  };
  size_t i = 0;
  for (; i + 16 <= count; i += 16) {
    if (!simd::none_set16(mask + i)) {
      one_by_one(i, i + 16);
      continue;
    }
    for (size_t j = i; j < i + 16; j += 4) {
      V2 d0 = load2(diag + j), d1 = load2(diag + j + 2);
      if (k) {
        d0 += load2(k + j);
        d1 += load2(k + j + 2);
      }
      s0 += simd::abs2(d0);
      s1 += simd::abs2(d1);
      if (fd) {
        simd::store2(fd + j, load2(ad + j));
        simd::store2(fd + j + 2, load2(ad + j + 2));
      }
    }
  }
  one_by_one(i, count);
  const V2 sum = s0 + s1;
  return count > 0 ? (sum[0] + sum[1] + rest) / double(count) : 0.0;
}

double pressure_scale(double mean_diagonal, const NodeMat& a) {
  const double mean_a = a.cwiseAbs().sum() / std::max<double>(1.0, double(a.size()));
  if (!(mean_a > 0) || !(mean_diagonal > 0)) return 1.0;
  return mean_diagonal / mean_a;
}

double pressure_for_volume(const NodeMat& a, const NodeMat& r, const NodeMat& s, double c) {
  double as = 0.0, ar = 0.0;
  for (int d = 0; d < 3; ++d) {
    as += a.col(d).dot(s.col(d));
    ar += a.col(d).dot(r.col(d));
  }
  // a.s > 0 whenever some node can move; otherwise the fluid has nothing to push.
  return (as > 0.0 && std::isfinite(as)) ? (c - ar) / as : 0.0;
}

}  // namespace vdm
