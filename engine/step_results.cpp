#include "engine/step_results.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "engine/membrane_strain.hpp"
#include "engine/simd2.hpp"

namespace vdm {
namespace {

using simd::V2;
typedef long long V2i __attribute__((vector_size(16)));  // lane masks of a V2 (all ones: true)

// Lanes (a[0], b[0]) and (a[1], b[1]): two nodes' pairs turned into per-axis pairs and back.
inline V2 low_lanes(V2 a, V2 b) { return V2{a[0], b[0]}; }
inline V2 high_lanes(V2 a, V2 b) { return V2{a[1], b[1]}; }
inline V2 select(V2i m, V2 a) { return V2(V2i(a) & m); }      // m ? a : +0
inline V2 select_not(V2i m, V2 a) { return V2(V2i(a) & ~m); }  // m ? +0 : a

// What the gather reads of each node, packed: the pairs (u_x, u_y), (u_z, dV_x), (dV_y, dV_z)
// with dV = A o u (without the paper capsule's stress: (u_x, u_y), (u_z, 0) and no third),
// each kind in a plane of R pairs: pair k of node j at pair[k] + 2 (j & wrap). One index
// (2 j, scale 8) serves the three loads (node-major rows of 6 cost a multiply by 3, a shift
// and an add per neighbour).
// The planes are in the solver's spare scratch (6 N doubles; no array of the step's: the peak
// memory at 40k nodes).
//
// When every node's neighbours are within `reach` of it in node order (the generated livers:
// 321 at 40k nodes) the planes are a ring of R nodes, R a power of two (wrap = R - 1), packed
// `lead` nodes ahead of the gather: the pairs it reads are those just written, in the core's
// first caches, and the ring (48 KB at 40k nodes) is not written back to memory; nor are u
// and A read from it twice. Otherwise (an unordered mesh) R = N, wrap = -1 (every bit), and
// the planes are packed before the gather starts.
struct Planes {
  const double* pair[3];
  std::ptrdiff_t wrap;
};
inline Planes planes_of(const double* rows, std::ptrdiff_t ring, std::ptrdiff_t wrap) {
  Planes p{{rows, rows + 2 * ring, rows + 4 * ring}, wrap};
  // Three base registers: hide from the compiler that they are rows + 2 R k, or it may
  // rebuild the second and third from the first at every neighbour (one more add each).
  asm("" : "+r"(p.pair[1]), "+r"(p.pair[2]));
  return p;
}

// The ring's size in nodes: a power of two above kChunk + lead + reach (the results of nodes
// [i, i + kChunk) read nodes i - reach to i + kChunk - 1 + reach, and the packing before them
// goes up to node i + kChunk + lead - 1, so it must not yet have overwritten node i - reach),
// up to kMaxRing nodes (192 KB); else N (see Planes; result_ring_nodes(), below). lead:
// reach + 2 or 3 (even), past the last neighbour of the chunk's last node.
constexpr std::ptrdiff_t kMaxRing = 4096;
constexpr std::ptrdiff_t kChunk = 64;  // nodes whose results follow one packing (even)
inline std::ptrdiff_t lead_nodes(int reach) { return (std::ptrdiff_t(reach) + 3) / 2 * 2; }

// Per-axis entries of nodes i and i + 1 as a pair (Pair), or of node i alone (lane 1 zero:
// the last node of an odd count). The N x 3 arrays are read through their data and the
// column offsets (one pointer per array, not three).
template <bool Pair>
inline V2 load(const double* p) { return Pair ? simd::load2(p) : V2{p[0], 0.0}; }
template <bool Pair>
inline void store(double* p, V2 v) {
  if (Pair) simd::store2(p, v);
  else p[0] = v[0];
}
template <bool Pair>
inline V2i held_lanes(const std::uint8_t* m) {
  return V2i{m[0] ? -1LL : 0LL, Pair && m[1] ? -1LL : 0LL};
}

// sum_j w_ij u_j over node i's neighbours (x and y in `wu_xy`, z in lane 0 of `wu_z_dv_x`),
// and with the paper capsule's stress sum_j dV_j (lane 1 of `wu_z_dv_x`, then `dv_yz`).
struct NeighbourSums {
  V2 wu_xy = {0.0, 0.0}, wu_z_dv_x = {0.0, 0.0}, dv_yz = {0.0, 0.0};
};

// One neighbour j's terms: w_ij u_j on (x, y) and on z in lane 0; mulsd keeps lane 1, dV_x
// unweighted (the bits of V2{w, 1.0} * row without building that pair), then dV_y, dV_z.
// Without Tension lane 1 of wu_z_dv_x is unused.
template <bool Tension>
inline void add_neighbour(NeighbourSums& g, NeighbourLists::Entry e, const double* weight, const Planes& p) {
  const V2 w = simd::splat(weight[e.edge]);
  const std::ptrdiff_t j = 2 * (std::ptrdiff_t(e.node) & p.wrap);
  g.wu_xy += w * simd::load2(p.pair[0] + j);
  g.wu_z_dv_x += simd::mul_low(simd::load2(p.pair[1] + j), w);
  if (Tension) g.dv_yz += simd::load2(p.pair[2] + j);
  simd::keep_in_registers(g.wu_xy, g.wu_z_dv_x, g.dv_yz);
}

// Any node's list, in its order.
template <bool Tension>
inline NeighbourSums gather(const NeighbourLists::Entry* e, const NeighbourLists::Entry* end, const double* weight,
                            const Planes& p) {
  NeighbourSums g;
  for (; e != end; ++e) add_neighbour<Tension>(g, *e, weight, p);
  return g;
}

// The common case of a closed triangulated surface: two nodes of kDegree neighbours each
// (entries e[0, kDegree) and e[kDegree, 2 kDegree)), the loops unrolled and the two lists
// interleaved; each node's sums in its list's order (the bits of gather()).
constexpr int kDegree = 6;
template <bool Tension>
inline void gather_pair_fixed(const NeighbourLists::Entry* e, const double* weight, const Planes& p, NeighbourSums& g0,
                              NeighbourSums& g1) {
#pragma GCC unroll 6
  for (int k = 0; k < kDegree; ++k) {
    add_neighbour<Tension>(g0, e[k], weight, p);
    add_neighbour<Tension>(g1, e[kDegree + k], weight, p);
  }
}

// ResidualSums per axis, lane 0 the even nodes' sum and lane 1 the odd nodes'.
struct LaneSums {
  V2 free2[3] = {}, rhs2[3] = {}, volume_row[3] = {};
};

// The whole pass for one case (stress or not, loads, springs). Tension (with Stress): the
// paper's capsule, whose stress sums its neighbours' dV (the membrane's comes from its strain,
// after this pass: add_membrane_stress).
template <bool Stress, bool Tension, bool Loads, bool Springs>
class ResultsPass {
  static_assert(Stress || !Tension, "the capsule's tension is part of the stress");
 public:
  ResultsPass(const TissueModel& m, const StepResultsInput& in, SimState& s, double* rows)
      : m_(m), rows_(rows), n_(m.n), ring_(result_ring_nodes(m.neighbours.reach, n_)),
        lead_(ring_ < n_ ? lead_nodes(m.neighbours.reach) : n_),
        planes_(planes_of(rows, ring_, ring_ < n_ ? ring_ - 1 : -1)), col_{0, m.n, 2 * std::ptrdiff_t(m.n)},
        u_(s.u.data()), a_(s.area_vectors.data()), rhs_(in.rhs.data()),
        begin_(m.neighbours.begin.data()), entries_(m.neighbours.entries.data()), weight_(in.K.weight.data()),
        diag_(in.K.diagonal.data()), mask_(in.mask.data()), f_(Loads ? in.force->data() : nullptr),
        k_(Springs ? in.springs->data() : nullptr), reaction_(s.reaction.data()), pressure_(s.reaction_pressure.data()),
        norms_(in.area_norms.data()), strain_(s.strain.data()), sigma_(s.stress.data()), bulk_(m.bulk.data()),
        vol_(s.node_volumes.data()), bc_(m.connectivity_modulus), p_(s.pressure) {}

  ResidualSums run(SimState& s) {
    // The nodes' results in chunks of kChunk, each once the planes hold its nodes'
    // neighbours: the nodes packed lead_ ahead, two at a time, with the sums that need no
    // neighbour. The sums in locals, not members: the compiler may keep them in registers
    // (a store through a double* could change a member, so a member's sum is stored every
    // pair).
    LaneSums acc;
    std::ptrdiff_t packed = std::min(lead_, n_);
    pack_range(0, packed, acc);
    for (std::ptrdiff_t i = 0; i < n_; i += kChunk) {
      const std::ptrdiff_t end = std::min(i + kChunk, n_), ahead = std::min(end + lead_, n_);
      pack_range(packed, ahead, acc);
      packed = ahead;
      std::ptrdiff_t k = i;
      for (; k + 1 < end; k += 2) results<true>(k, acc);
      if (k < end) results<false>(k, acc);
    }
    if (Stress) infinite_bulk(s);
    ResidualSums sums;
    for (int d = 0; d < 3; ++d) {  // even nodes' sum + odd nodes'
      sums.free2[d] = acc.free2[d][0] + acc.free2[d][1];
      sums.rhs2[d] = acc.rhs2[d][0] + acc.rhs2[d][1];
      sums.volume_row[d] = acc.volume_row[d][0] + acc.volume_row[d][1];
    }
    return sums;
  }

 private:
  // Nodes [begin, end) into the planes, two at a time from an even `begin` (one alone at the
  // end of an odd count).
  void pack_range(std::ptrdiff_t begin, std::ptrdiff_t end, LaneSums& acc) const {
    std::ptrdiff_t i = begin;
    for (; i + 1 < end; i += 2) pack<true>(i, acc);
    if (i < end) pack<false>(i, acc);
  }

  // The pairs of nodes i and i + 1 (Pair) or i alone in the planes, and their terms of
  // |rhs|^2 and of the volume row (A u on the free entries).
  template <bool Pair>
  void pack(std::ptrdiff_t i, LaneSums& acc) const {
    V2 u[3], dv[3];
    const bool held = any_held<Pair>(i);
    for (int d = 0; d < 3; ++d) {
      const std::ptrdiff_t id = i + col_[d];
      u[d] = load<Pair>(u_ + id);
      const V2 a = load<Pair>(a_ + id);
      dv[d] = Tension ? a * u[d] : V2{0.0, 0.0};
      const V2 r = load<Pair>(rhs_ + id);
      acc.rhs2[d] += r * r;
      // The volume row's A u on the free entries: (A o u)_i there (a constrained entry's
      // +0, where 0 u_i may be -0, adds nothing: the sums start at +0).
      acc.volume_row[d] += (held ? select_not(held_lanes<Pair>(mask_ + id), a) : a) * u[d];
    }
    double* xy = rows_ + 2 * (i & planes_.wrap);  // planes_.pair[0]
    double* zx = xy + 2 * ring_;                   // planes_.pair[1]
    double* yz = zx + 2 * ring_;                   // planes_.pair[2]
    simd::store2(xy, low_lanes(u[0], u[1]));
    simd::store2(zx, low_lanes(u[2], dv[0]));
    if (Tension) simd::store2(yz, low_lanes(dv[1], dv[2]));
    if (Pair) {
      simd::store2(xy + 2, high_lanes(u[0], u[1]));
      simd::store2(zx + 2, high_lanes(u[2], dv[0]));
      if (Tension) simd::store2(yz + 2, high_lanes(dv[1], dv[2]));
    }
  }

  // Nodes i and i + 1 (Pair) or i alone, each axis's two entries as a pair.
  template <bool Pair>
  void results(std::ptrdiff_t i, LaneSums& acc) const {
    const int b0 = begin_[i], b1 = begin_[i + 1], b2 = Pair ? begin_[i + 2] : b1;
    NeighbourSums g0, g1;
    V2 degree;  // of nodes i and i + 1 (or 0)
    if (Pair && b2 - b0 == 2 * kDegree && b1 - b0 == kDegree) {
      gather_pair_fixed<Tension>(entries_ + b0, weight_, planes_, g0, g1);
      degree = simd::splat(double(kDegree));
    } else {
      g0 = gather<Tension>(entries_ + b0, entries_ + b1, weight_, planes_);
      if (Pair) g1 = gather<Tension>(entries_ + b1, entries_ + b2, weight_, planes_);
      degree = V2{double(b1 - b0), Pair ? double(b2 - b1) : 0.0};
    }
    const V2 wu[3] = {low_lanes(g0.wu_xy, g1.wu_xy), high_lanes(g0.wu_xy, g1.wu_xy), low_lanes(g0.wu_z_dv_x, g1.wu_z_dv_x)};
    // (K u)_i - dP A_i - f_i; on a free entry plus k_i u_i it is the eliminated system's
    // residual (the constrained u_j are their prescribed values), on a constrained one the
    // reaction (zero residual: u is pinned there).
    V2 base[3], free_r[3];
    for (int d = 0; d < 3; ++d) {
      const std::ptrdiff_t id = i + col_[d];
      const V2 u = load<Pair>(u_ + id);
      base[d] = load<Pair>(diag_ + id) * u - wu[d] - simd::splat(p_) * load<Pair>(a_ + id);
      if (Loads) base[d] -= load<Pair>(f_ + id);
      free_r[d] = base[d];
      if (Springs) free_r[d] += load<Pair>(k_ + id) * u;
    }
    if (!any_held<Pair>(i)) {  // most nodes: no reaction, every entry free
      for (int d = 0; d < 3; ++d) {
        acc.free2[d] += free_r[d] * free_r[d];
        store<Pair>(reaction_ + i + col_[d], V2{0.0, 0.0});
      }
      store<Pair>(pressure_ + i, V2{0.0, 0.0});
    } else {
      V2 r[3];
      for (int d = 0; d < 3; ++d) {
        const V2i held = held_lanes<Pair>(mask_ + i + col_[d]);
        r[d] = select(held, base[d]);
        acc.free2[d] += select_not(held, free_r[d] * free_r[d]);
        store<Pair>(reaction_ + i + col_[d], r[d]);
      }
      // The contact pressure |r_i| / |A_i| on a node with a constrained entry, both lanes at
      // once (the same operations as lane by lane: the same bits; one square root and one
      // division for the pair).
      const V2i any = {(mask_[i] | mask_[i + col_[1]] | mask_[i + col_[2]]) != 0 ? -1LL : 0LL,
                       Pair && (mask_[i + 1] | mask_[i + 1 + col_[1]] | mask_[i + 1 + col_[2]]) != 0 ? -1LL : 0LL};
      const V2 an = load<Pair>(norms_ + i);
      const V2 r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
      store<Pair>(pressure_ + i, select(any & V2i(an > simd::splat(0.0)), simd::sqrt2(r2) / an));
    }
    if (Stress) {
      // eps = dV_i / V_i; sigma = B eps + B_c sum_j (dV_i - dV_j) / V_i (one division by
      // V_i for the three axes), as for a finite B on every entry (the infinite: below).
      const V2 dv_sums[3] = {high_lanes(g0.wu_z_dv_x, g1.wu_z_dv_x), low_lanes(g0.dv_yz, g1.dv_yz),
                             high_lanes(g0.dv_yz, g1.dv_yz)};
      const V2 inv_v = simd::splat(1.0) / (Pair ? simd::load2(vol_ + i) : V2{vol_[i], 1.0});
      for (int d = 0; d < 3; ++d) {
        const std::ptrdiff_t id = i + col_[d];
        const V2 dv = load<Pair>(a_ + id) * load<Pair>(u_ + id);
        const V2 eps = dv * inv_v;
        store<Pair>(strain_ + id, eps);
        // The capsule's term: the paper's volumic tension; a membrane's stress comes from its
        // strain, after this pass (add_membrane_stress).
        const V2 capsule = Tension ? simd::splat(bc_) * (degree * dv - dv_sums[d]) * inv_v : V2{0.0, 0.0};
        store<Pair>(sigma_ + id, load<Pair>(bulk_ + id) * eps + capsule);
      }
    }
  }

  // Some entry of node i (and i + 1) constrained.
  template <bool Pair>
  bool any_held(std::ptrdiff_t i) const {
    if (!Pair) return (mask_[i] | mask_[i + col_[1]] | mask_[i + col_[2]]) != 0;
    std::uint16_t m[3];
    for (int d = 0; d < 3; ++d) std::memcpy(&m[d], mask_ + i + col_[d], sizeof m[d]);
    return (m[0] | m[1] | m[2]) != 0;
  }

  // An infinite B_i^d: no strain (u_i^d = 0 is a constraint), and the bulk term is the
  // constraint force over the patch area, -reaction_i^d / A_i^d. The stress written by
  // results() is the tension alone there (the model's B is 0 on infinite entries).
  void infinite_bulk(SimState& s) const {
    const NodeMat& A = s.area_vectors;
    for (const int i : m_.infinite_nodes) {
      const double tiny = 1e-9 * A.row(i).norm();
      for (int d = 0; d < 3; ++d) {
        if (!m_.infinite(i, d)) continue;
        s.strain(i, d) = 0.0;
        s.stress(i, d) += std::abs(A(i, d)) > tiny ? -s.reaction(i, d) / A(i, d) : 0.0;
      }
    }
  }

  const TissueModel& m_;
  double* rows_;
  const std::ptrdiff_t n_;
  const std::ptrdiff_t ring_;  // nodes in each plane (Planes)
  const std::ptrdiff_t lead_;  // how far ahead of the gather the planes are packed
  const Planes planes_;
  const std::ptrdiff_t col_[3];
  const double *u_, *a_, *rhs_;
  const int* begin_;
  const NeighbourLists::Entry* entries_;
  const double *weight_, *diag_;
  const std::uint8_t* mask_;
  const double *f_, *k_;
  double *reaction_, *pressure_;
  const double* norms_;
  double *strain_, *sigma_;
  const double *bulk_, *vol_;
  const double bc_, p_;
};

template <bool Stress, bool Tension, bool Loads, bool Springs>
ResidualSums results_pass(const TissueModel& m, const StepResultsInput& in, SimState& s, double* rows) {
  return ResultsPass<Stress, Tension, Loads, Springs>(m, in, s, rows).run(s);
}

template <bool Stress, bool Tension>
ResidualSums results_pass(const TissueModel& m, const StepResultsInput& in, SimState& s, double* rows) {
  const bool loads = in.force != nullptr, springs = in.springs != nullptr;
  if (loads && springs) return results_pass<Stress, Tension, true, true>(m, in, s, rows);
  if (loads) return results_pass<Stress, Tension, true, false>(m, in, s, rows);
  if (springs) return results_pass<Stress, Tension, false, true>(m, in, s, rows);
  return results_pass<Stress, Tension, false, false>(m, in, s, rows);
}

}  // namespace

std::ptrdiff_t result_ring_nodes(int reach, std::ptrdiff_t n) {
  if (reach < 0) return n;
  std::ptrdiff_t r = 4;
  while (r < kChunk + lead_nodes(reach) + std::ptrdiff_t(reach) + 2) r *= 2;
  return r <= kMaxRing && r < n ? r : n;
}

ResidualSums compute_step_results(const TissueModel& m, const StepResultsInput& in, SimState& s, double* rows) {
  if (!m.compute_stress) return results_pass<false, false>(m, in, s, rows);
  if (!m.membrane_capsule()) return results_pass<true, true>(m, in, s, rows);
  const ResidualSums sums = results_pass<true, false>(m, in, s, rows);
  add_membrane_stress(m, s, rows);  // rows: free again
  return sums;
}

}  // namespace vdm
