#include "engine/axis_incomplete_cholesky.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "engine/simd2.hpp"
#include "engine/simd4.hpp"

namespace vdm {

void AxisIncompleteCholesky::analyze(const AxisMatrices& K) {
  n_ = K.n;
  lo_start_.assign(size_t(n_) + 1, 0);
  lo_col_.clear();
  lo_src_.clear();
  for (int i = 0; i < n_; ++i) {
    for (int p = K.start[size_t(i)]; p < K.start[size_t(i) + 1]; ++p)
      if (K.column(size_t(p)) < i) {  // columns ascending: the lower ones come first
        lo_col_.push_back(K.column(size_t(p)));
        lo_src_.push_back(p);
      }
    lo_start_[size_t(i) + 1] = static_cast<int>(lo_col_.size());
  }
  // One float to spare after the last entry: the AVX2 sweeps read an entry's values as four.
  lo_val_.assign(3 * lo_col_.size() + 1, 0.0f);
  // Rows of L^T: entry (i, k) of L with k < i is entry (k, i) of L^T.
  up_start_.assign(size_t(n_) + 1, 0);
  for (size_t p = 0; p < lo_col_.size(); ++p) ++up_start_[size_t(lo_col_[p]) + 1];
  for (int k = 0; k < n_; ++k) up_start_[size_t(k) + 1] += up_start_[size_t(k)];
  up_col_.assign(lo_col_.size(), 0);
  up_src_.assign(lo_col_.size(), 0);
  std::vector<int> fill(up_start_.begin(), up_start_.end() - 1);
  for (int i = 0; i < n_; ++i)
    for (int p = lo_start_[size_t(i)]; p < lo_start_[size_t(i) + 1]; ++p) {
      const int k = lo_col_[size_t(p)];
      up_col_[size_t(fill[size_t(k)])] = i;
      up_src_[size_t(fill[size_t(k)]++)] = p;
    }
  up_val_.assign(3 * lo_col_.size() + 1, 0.0f);  // one to spare as well
  inv_diag_.assign(3 * size_t(n_), 0.0);
  mask_.assign(3 * size_t(n_), 0);
  work_diag_.assign(3 * size_t(n_), 0.0);
  // Where each update of the right-looking factorisation lands, in the order factorize()
  // makes them: entry (i, j) of L for rows i > j of column k, or -1 outside the pattern.
  update_target_.clear();
  for (int k = 0; k < n_; ++k)
    for (int q1 = up_start_[size_t(k)]; q1 < up_start_[size_t(k) + 1]; ++q1)
      for (int q2 = up_start_[size_t(k)]; q2 < q1; ++q2) {
        const int i = up_col_[size_t(q1)], j = up_col_[size_t(q2)];
        int m = -1;
        for (int t = lo_start_[size_t(i)]; t < lo_start_[size_t(i) + 1]; ++t)
          if (lo_col_[size_t(t)] == j) m = t;
        update_target_.push_back(m);
      }
}

int AxisIncompleteCholesky::factorize(const AxisMatrices& K, double omega, bool compensate) {
  // Right-looking: column k of L, then its updates of the rows below; an update that falls
  // outside the pattern is dropped and, times omega, taken off both diagonals instead.
  // In place: L holds K's lower values as the elimination updates them until column k
  // scales its own (an entry's updates all come from columns before its own).
  int repaired = 0;
  float* L = lo_val_.data();
  double* wd = work_diag_.data();
  // K's lower values, zero in the rows and columns of the constrained entries.
  const std::uint8_t* rm = K.row_mask.data();
  for (size_t k = 0; k < 3 * size_t(n_); ++k) wd[k] = K.diag[k];
  for (int i = 0; i < n_; ++i)
    for (int p = lo_start_[size_t(i)]; p < lo_start_[size_t(i) + 1]; ++p) {
      const double v = K.off[size_t(lo_src_[size_t(p)])];
      const size_t j = size_t(lo_col_[size_t(p)]);
      const std::uint8_t* mi = rm + 3 * size_t(i);
      const std::uint8_t* mj = rm + 3 * j;
      for (size_t d = 0; d < 3; ++d) {
        const bool off = mi[d] | mj[d];
        if (compensate && v > 0.0) {  // onto both diagonals (a constrained one stays 1)
          L[3 * size_t(p) + d] = 0.0f;
          if (!off) {
            wd[3 * size_t(i) + d] += v;
            wd[3 * j + d] += v;
          }
        } else {
          L[3 * size_t(p) + d] = off ? 0.0f : float(v);
        }
      }
    }
  const int* target = update_target_.data();
  for (int k = 0; k < n_; ++k) {
    for (int d = 0; d < 3; ++d) {
      const double akk = K.diag[3 * size_t(k) + size_t(d)];
      double piv = wd[3 * size_t(k) + size_t(d)];
      if (!(piv > 1e-12 * std::abs(akk))) {
        piv = std::abs(akk) > 0 ? std::abs(akk) : 1.0;
        ++repaired;
      }
      inv_diag_[3 * size_t(k) + size_t(d)] = 1.0 / std::sqrt(piv);
    }
    const int qb = up_start_[size_t(k)], qe = up_start_[size_t(k) + 1];
    for (int q = qb; q < qe; ++q) {
      const size_t p = size_t(up_src_[size_t(q)]);
      for (size_t d = 0; d < 3; ++d) L[3 * p + d] = float(L[3 * p + d] * inv_diag_[3 * size_t(k) + d]);
    }
    for (int q1 = qb; q1 < qe; ++q1) {
      const int i = up_col_[size_t(q1)];
      const float* li = &L[3 * size_t(up_src_[size_t(q1)])];
      for (size_t d = 0; d < 3; ++d) wd[3 * size_t(i) + d] -= double(li[d]) * li[d];
      for (int q2 = qb; q2 < q1; ++q2) {
        const int j = up_col_[size_t(q2)];  // j < i
        const float* lj = &L[3 * size_t(up_src_[size_t(q2)])];
        const int m = *target++;
        if (m >= 0) {
          for (size_t d = 0; d < 3; ++d) L[3 * size_t(m) + d] = float(L[3 * size_t(m) + d] - double(li[d]) * lj[d]);
        } else {
          for (size_t d = 0; d < 3; ++d) {
            const double drop = omega * li[d] * double(lj[d]);
            wd[3 * size_t(i) + d] -= drop;
            wd[3 * size_t(j) + d] -= drop;
          }
        }
      }
    }
  }
  copy_to_upper();
  std::copy(K.row_mask.begin(), K.row_mask.end(), mask_.begin());
  return repaired;
}

int AxisIncompleteCholesky::fit_to_mask(const AxisMatrices& K) {
  // The masks compared eight bytes at a time (a contact step changes a few entries); L and
  // its copy by rows of L^T changed together where an entry is newly constrained.
  int changed = 0;
  float* L = lo_val_.data();
  float* U = up_val_.data();
  const std::uint8_t* now_mask = K.row_mask.data();
  std::uint8_t* fit = mask_.data();
  const size_t entries = 3 * size_t(n_);
  for (size_t w = 0; w < entries; w += 8) {
    const size_t len = std::min<size_t>(8, entries - w);
    std::uint64_t a = 0, b = 0;
    std::memcpy(&a, now_mask + w, len);
    std::memcpy(&b, fit + w, len);
    if (a == b) continue;
    for (size_t e = w; e < w + len; ++e) {
      const std::uint8_t now = now_mask[e];
      if (now == fit[e]) continue;
      ++changed;
      fit[e] = now;
      const size_t i = e / 3, d = e % 3;
      if (now) {  // constrained since: row and column i of L^d zero, L_ii = 1 (K's row is e_i)
        for (int p = lo_start_[i]; p < lo_start_[i + 1]; ++p) {  // L_ik, k < i: entry (k, i) of L^T
          L[3 * size_t(p) + d] = 0.0f;
          const int k = lo_col_[size_t(p)];
          for (int q = up_start_[size_t(k)]; q < up_start_[size_t(k) + 1]; ++q)
            if (up_src_[size_t(q)] == p) {
              U[3 * size_t(q) + d] = 0.0f;
              break;
            }
        }
        for (int q = up_start_[i]; q < up_start_[i + 1]; ++q) {  // L_ji, j > i: row i of L^T
          L[3 * size_t(up_src_[size_t(q)]) + d] = 0.0f;
          U[3 * size_t(q) + d] = 0.0f;
        }
        inv_diag_[e] = 1.0;
      } else {  // freed since: its row and column are zero already
        const double kii = K.diag[e];
        inv_diag_[e] = kii > 0.0 ? 1.0 / std::sqrt(kii) : 1.0;
      }
    }
  }
  return changed;
}

void AxisIncompleteCholesky::copy_to_upper() {
  for (size_t q = 0; q < up_src_.size(); ++q)
    for (size_t d = 0; d < 3; ++d) up_val_[3 * q + d] = lo_val_[3 * size_t(up_src_[q]) + d];
}

void AxisIncompleteCholesky::save_values(std::vector<double>& out) const {
  const std::ptrdiff_t values = std::ptrdiff_t(3 * lo_col_.size());  // not the float to spare
  out.insert(out.end(), lo_val_.begin(), lo_val_.begin() + values);   // floats: exact as doubles
  out.insert(out.end(), inv_diag_.begin(), inv_diag_.end());
  out.insert(out.end(), mask_.begin(), mask_.end());
}

bool AxisIncompleteCholesky::load_values(const std::vector<double>& in, size_t& pos) {
  const size_t values = 3 * lo_col_.size();  // not the float to spare
  if (in.size() < pos || in.size() - pos < values + inv_diag_.size() + mask_.size()) return false;
  for (size_t k = 0; k < values; ++k) lo_val_[k] = float(in[pos++]);
  std::copy(in.begin() + std::ptrdiff_t(pos), in.begin() + std::ptrdiff_t(pos + inv_diag_.size()), inv_diag_.begin());
  pos += inv_diag_.size();
  for (std::uint8_t& m : mask_) m = in[pos++] != 0.0 ? 1 : 0;
  copy_to_upper();
  return true;
}

namespace {

typedef long long V2i __attribute__((vector_size(16)));
typedef long long V4i __attribute__((vector_size(32)));

// apply()'s `live` as bit masks, one per vector of the block: all ones for a vector whose r is
// read, zero for one whose r is taken as +0 (an AND of the loaded values: the same bits as
// zeroing those entries of r first).
template <int W>
struct LaneMasks {
  long long m[W];
  explicit LaneMasks(const double* live) {
    for (int c = 0; c < W; ++c) m[c] = !live || live[c] != 0.0 ? -1LL : 0LL;
  }
};

// v, or +0 when the mask is zero.
inline double masked(double v, long long mask) {
  long long bits;
  std::memcpy(&bits, &v, sizeof bits);
  bits &= mask;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

// apply<6> with AVX2 (simd4.hpp): a row of 6 as lanes 0-3 (a0 and a1 of the SSE2 sweeps) and
// 4-5 (a2), each lane with the same operations in the same order (so the same bits). An
// entry's three values are read as four floats (the arrays have one float to spare after the
// last entry) and spread over the lanes.
VDM_AVX2 void apply6_avx2(int n, const int* lo_start, const int* lo_col, const float* lo_val, const int* up_start,
                          const int* up_col, const float* up_val, const double* inv_diag, const double* r, double* z,
                          double* rz, const LaneMasks<6>& lanes) {
  using simd::V2;
  using simd::V4;
  using simd::load2;
  using simd::load4;
  const V4i m01 = {lanes.m[0], lanes.m[1], lanes.m[2], lanes.m[3]};
  const V2i m2 = {lanes.m[4], lanes.m[5]};
  // Forward: L y = r (y stored in z). Rows are written and read back in the same two parts
  // (4 + 2 doubles): a row loaded soon after its store is then forwarded from it. The row
  // just solved is not read back at all: it stays in registers (see apply_axis).
  V4 prev01 = {0, 0, 0, 0};
  V2 prev2 = {0, 0};
  for (int i = 0; i < n; ++i) {
    const double* ri = r + size_t(i) * 6;
    V4 a01 = V4(V4i(load4(ri)) & m01);
    V2 a2 = V2(V2i(load2(ri + 4)) & m2);
    const int pb = lo_start[i], pe = lo_start[i + 1];
    for (int p = pb; p < pe - 1; ++p) {
      const V4 v = simd::load4f(lo_val + 3 * size_t(p));
      const double* zj = block_row<6>(z, 6 * lo_col[p]);
      a01 -= simd::dup01(v) * load4(zj);
      a2 -= simd::dup2(v) * load2(zj + 4);
    }
    if (pe > pb) {
      const V4 v = simd::load4f(lo_val + 3 * size_t(pe - 1));
      if (lo_col[pe - 1] == i - 1) {
        a01 -= simd::dup01(v) * prev01;
        a2 -= simd::dup2(v) * prev2;
      } else {
        const double* zj = block_row<6>(z, 6 * lo_col[pe - 1]);
        a01 -= simd::dup01(v) * load4(zj);
        a2 -= simd::dup2(v) * load2(zj + 4);
      }
    }
    const double* id = inv_diag + 3 * size_t(i);
    double* zi = z + size_t(i) * 6;
    prev01 = a01 * simd::dup01(load2(id));
    prev2 = a2 * simd::splat(id[2]);
    simd::store4(zi, prev01);
    simd::store2(zi + 4, prev2);
  }
  // Backward: L^T z = y, by the rows of L^T.
  V4 d01 = {0, 0, 0, 0};
  V2 d2 = {0, 0};
  for (int i = n - 1; i >= 0; --i) {
    double* zi = z + size_t(i) * 6;
    V4 a01 = load4(zi);
    V2 a2 = load2(zi + 4);
    const int pb = up_start[i], pe = up_start[i + 1];
    if (pe > pb) {
      const V4 v = simd::load4f(up_val + 3 * size_t(pb));
      if (up_col[pb] == i + 1) {
        a01 -= simd::dup01(v) * prev01;
        a2 -= simd::dup2(v) * prev2;
      } else {
        const double* zj = block_row<6>(z, 6 * up_col[pb]);
        a01 -= simd::dup01(v) * load4(zj);
        a2 -= simd::dup2(v) * load2(zj + 4);
      }
    }
    for (int p = pb + 1; p < pe; ++p) {
      const V4 v = simd::load4f(up_val + 3 * size_t(p));
      const double* zj = block_row<6>(z, 6 * up_col[p]);
      a01 -= simd::dup01(v) * load4(zj);
      a2 -= simd::dup2(v) * load2(zj + 4);
    }
    const double* id = inv_diag + 3 * size_t(i);
    a01 *= simd::dup01(load2(id));
    a2 *= simd::splat(id[2]);
    prev01 = a01;
    prev2 = a2;
    simd::store4(zi, a01);
    simd::store2(zi + 4, a2);
    const double* ri = r + size_t(i) * 6;
    d01 += V4(V4i(load4(ri)) & m01) * a01;
    d2 += V2(V2i(load2(ri + 4)) & m2) * a2;
  }
  simd::store4(rz, d01);
  simd::store2(rz + 4, d2);
}

}  // namespace

template <int W>
void AxisIncompleteCholesky::apply(const double* r, double* z, double* rz, const double* live) const {
  static_assert(W == 3 || W == 6, "blocks of 3 or 6 vectors");
  const LaneMasks<W> lanes(live);
  // The variant chosen first (nothing live across the call: the SSE2 sweeps compile as alone).
  if (W == 6 && simd::avx2_enabled()) {
    if constexpr (W == 6)
      apply6_avx2(n_, lo_start_.data(), lo_col_.data(), lo_val_.data(), up_start_.data(), up_col_.data(),
                  up_val_.data(), inv_diag_.data(), r, z, rz, lanes);
    return;
  }
  using simd::V2;
  using simd::load2;
  using simd::splat;
  using simd::store2;
  using simd::load2f;
  using simd::splat_high;
  using simd::splat_low;
  const int* lo_start = lo_start_.data();
  const int* lo_col = lo_col_.data();
  const float* lo_val = lo_val_.data();
  const int* up_start = up_start_.data();
  const int* up_col = up_col_.data();
  const float* up_val = up_val_.data();
  const double* inv_diag = inv_diag_.data();
  if constexpr (W == 6) {
    // The three values of an entry as pairs (v0, v1) and (v1, v2), each in one conversion,
    // then spread over the lanes.
    // Lanes: the two vectors of an axis (axis_matrices.hpp) share the value of L^d.
    // Forward: L y = r (y stored in z).
    const V2i m0 = {lanes.m[0], lanes.m[1]}, m1 = {lanes.m[2], lanes.m[3]}, m2 = {lanes.m[4], lanes.m[5]};
    V2 prev0 = {0, 0}, prev1 = {0, 0}, prev2 = {0, 0};  // the row just solved (see apply_axis)
    for (int i = 0; i < n_; ++i) {
      const double* ri = r + size_t(i) * 6;
      V2 a0 = V2(V2i(load2(ri)) & m0), a1 = V2(V2i(load2(ri + 2)) & m1), a2 = V2(V2i(load2(ri + 4)) & m2);
      const int pb = lo_start[i], pe = lo_start[i + 1];
      for (int p = pb; p < pe; ++p) {
        const float* v = lo_val + 3 * size_t(p);
        const V2 v01 = load2f(v), v12 = load2f(v + 1);
        if (p == pe - 1 && lo_col[p] == i - 1) {  // the last entry
          a0 -= splat_low(v01) * prev0;
          a1 -= splat_high(v01) * prev1;
          a2 -= splat_high(v12) * prev2;
        } else {
          const double* zj = block_row<6>(z, 6 * lo_col[p]);
          a0 -= splat_low(v01) * load2(zj);
          a1 -= splat_high(v01) * load2(zj + 2);
          a2 -= splat_high(v12) * load2(zj + 4);
        }
      }
      const double* id = inv_diag + 3 * size_t(i);
      double* zi = z + size_t(i) * 6;
      prev0 = a0 * splat(id[0]);
      prev1 = a1 * splat(id[1]);
      prev2 = a2 * splat(id[2]);
      store2(zi, prev0);
      store2(zi + 2, prev1);
      store2(zi + 4, prev2);
    }
    // Backward: L^T z = y, by the rows of L^T (a gather like the forward solve).
    V2 d0 = {0, 0}, d1 = {0, 0}, d2 = {0, 0};
    for (int i = n_ - 1; i >= 0; --i) {
      double* zi = z + size_t(i) * 6;
      V2 a0 = load2(zi), a1 = load2(zi + 2), a2 = load2(zi + 4);
      const int pb = up_start[i], pe = up_start[i + 1];
      for (int p = pb; p < pe; ++p) {
        const float* v = up_val + 3 * size_t(p);
        const V2 v01 = load2f(v), v12 = load2f(v + 1);
        if (p == pb && up_col[p] == i + 1) {  // the first entry
          a0 -= splat_low(v01) * prev0;
          a1 -= splat_high(v01) * prev1;
          a2 -= splat_high(v12) * prev2;
        } else {
          const double* zj = block_row<6>(z, 6 * up_col[p]);
          a0 -= splat_low(v01) * load2(zj);
          a1 -= splat_high(v01) * load2(zj + 2);
          a2 -= splat_high(v12) * load2(zj + 4);
        }
      }
      const double* id = inv_diag + 3 * size_t(i);
      a0 *= splat(id[0]);
      a1 *= splat(id[1]);
      a2 *= splat(id[2]);
      prev0 = a0;
      prev1 = a1;
      prev2 = a2;
      store2(zi, a0);
      store2(zi + 2, a1);
      store2(zi + 4, a2);
      const double* ri = r + size_t(i) * 6;
      d0 += V2(V2i(load2(ri)) & m0) * a0;
      d1 += V2(V2i(load2(ri + 2)) & m1) * a1;
      d2 += V2(V2i(load2(ri + 4)) & m2) * a2;
    }
    store2(rz, d0);
    store2(rz + 2, d1);
    store2(rz + 4, d2);
  } else {
    // Lanes: x and y together (their values are adjacent), z alone.
    const V2i mxy = {lanes.m[0], lanes.m[1]};
    const long long mz = lanes.m[2];
    V2 prev_xy = {0, 0};  // the row just solved (see apply_axis)
    double prev_z = 0;
    for (int i = 0; i < n_; ++i) {
      const double* ri = r + size_t(i) * 3;
      V2 axy = V2(V2i(load2(ri)) & mxy);
      double az = masked(ri[2], mz);
      const int pb = lo_start[i], pe = lo_start[i + 1];
      for (int p = pb; p < pe; ++p) {
        const float* v = lo_val + 3 * size_t(p);
        if (p == pe - 1 && lo_col[p] == i - 1) {  // the last entry
          axy -= load2f(v) * prev_xy;
          az -= double(v[2]) * prev_z;
        } else {
          const double* zj = block_row<3>(z, 6 * lo_col[p]);
          axy -= load2f(v) * load2(zj);
          az -= double(v[2]) * zj[2];
        }
      }
      const double* id = inv_diag + 3 * size_t(i);
      double* zi = z + size_t(i) * 3;
      prev_xy = axy * load2(id);
      prev_z = az * id[2];
      store2(zi, prev_xy);
      zi[2] = prev_z;
    }
    V2 dxy = {0, 0};
    double dz = 0;
    for (int i = n_ - 1; i >= 0; --i) {
      double* zi = z + size_t(i) * 3;
      V2 axy = load2(zi);
      double az = zi[2];
      const int pb = up_start[i], pe = up_start[i + 1];
      for (int p = pb; p < pe; ++p) {
        const float* v = up_val + 3 * size_t(p);
        if (p == pb && up_col[p] == i + 1) {  // the first entry
          axy -= load2f(v) * prev_xy;
          az -= double(v[2]) * prev_z;
        } else {
          const double* zj = block_row<3>(z, 6 * up_col[p]);
          axy -= load2f(v) * load2(zj);
          az -= double(v[2]) * zj[2];
        }
      }
      const double* id = inv_diag + 3 * size_t(i);
      axy *= load2(id);
      az *= id[2];
      prev_xy = axy;
      prev_z = az;
      store2(zi, axy);
      zi[2] = az;
      const double* ri = r + size_t(i) * 3;
      dxy += V2(V2i(load2(ri)) & mxy) * axy;
      dz += masked(ri[2], mz) * az;
    }
    store2(rz, dxy);
    rz[2] = dz;
  }
}

double AxisIncompleteCholesky::apply_axis(int d, const double* r, double* z) const {
  const int* lo_start = lo_start_.data();
  const int* lo_col = lo_col_.data();
  const float* lo_val = lo_val_.data() + d;
  const int* up_start = up_start_.data();
  const int* up_col = up_col_.data();
  const float* up_val = up_val_.data() + d;
  const double* inv_diag = inv_diag_.data() + d;
  // Each sweep is a chain: a row's last term (forward) or first (backward) is nearly always
  // the row solved just before it (i - 1 or i + 1: 93 % of the rows at 2.5k nodes, 98 % at
  // 40k), and read back from z it waited for the store to be forwarded. That row is kept in
  // a register instead (the same value: the same bits); 40 % less time per row.
  double prev = 0.0;
  for (int i = 0; i < n_; ++i) {  // forward: L y = r
    double a = r[i];
    const int pb = lo_start[i], pe = lo_start[i + 1];
    for (int p = pb; p < pe - 1; ++p) a -= double(lo_val[3 * size_t(p)]) * z[lo_col[p]];
    if (pe > pb) a -= double(lo_val[3 * size_t(pe - 1)]) * (lo_col[pe - 1] == i - 1 ? prev : z[lo_col[pe - 1]]);
    prev = a * inv_diag[3 * size_t(i)];
    z[i] = prev;
  }
  double rz = 0.0;
  for (int i = n_ - 1; i >= 0; --i) {  // backward: L^T z = y
    double a = z[i];
    const int pb = up_start[i], pe = up_start[i + 1];
    if (pe > pb) a -= double(up_val[3 * size_t(pb)]) * (up_col[pb] == i + 1 ? prev : z[up_col[pb]]);
    for (int p = pb + 1; p < pe; ++p) a -= double(up_val[3 * size_t(p)]) * z[up_col[p]];
    a *= inv_diag[3 * size_t(i)];
    prev = a;
    z[i] = a;
    rz += r[i] * a;
  }
  return rz;
}

template void AxisIncompleteCholesky::apply<3>(const double*, double*, double*, const double*) const;
template void AxisIncompleteCholesky::apply<6>(const double*, double*, double*, const double*) const;

}  // namespace vdm
