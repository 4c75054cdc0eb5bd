#include "engine/core/rotation_fit.hpp"

#include <cmath>

#include "engine/simd4.hpp"

// The lane templates below are instantiated for four lanes only inside fit4(), which is
// compiled for AVX2 and inlines them whole (always_inline): no four-lane value crosses a call,
// so GCC's note that such a call's ABI would differ without AVX does not apply.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace vdm::core {

namespace {

using simd::V4;
typedef decltype(V4{} < V4{}) M4;  // a lane-wise comparison's mask

// Lane helpers: a lane is a double (mask bool) or four (AVX2; mask M4).
inline double lane_sqrt(double a) { return std::sqrt(a); }
inline double lane_abs(double a) { return std::abs(a); }
inline double pick(bool m, double a, double b) { return m ? a : b; }
inline bool any(bool m) { return m; }
inline bool lane_not(bool m) { return !m; }
inline bool mask_at(bool m, int) { return m; }
inline double get(double a, int) { return a; }
inline double& lane_of(double& a, int) { return a; }

VDM_AVX2 inline V4 lane_sqrt(V4 a) { return _mm256_sqrt_pd(a); }
VDM_AVX2 inline V4 lane_abs(V4 a) { return _mm256_andnot_pd(_mm256_set1_pd(-0.0), a); }
VDM_AVX2 inline V4 pick(M4 m, V4 a, V4 b) { return _mm256_blendv_pd(b, a, reinterpret_cast<__m256d>(m)); }
VDM_AVX2 inline bool any(M4 m) { return _mm256_movemask_pd(reinterpret_cast<__m256d>(m)) != 0; }
VDM_AVX2 inline M4 lane_not(M4 m) { return ~m; }
VDM_AVX2 inline bool mask_at(M4 m, int k) { return m[k] != 0; }
VDM_AVX2 inline double get(V4 a, int k) { return a[k]; }
VDM_AVX2 inline double& lane_of(V4& a, int k) { return reinterpret_cast<double*>(&a)[k]; }

template <class L>
constexpr int kLanes = static_cast<int>(sizeof(L) / sizeof(double));

// Eigen's rotation matrix of a unit quaternion (w, x, y, z); R row-major.
template <class L>
[[gnu::always_inline]] inline void to_matrix(const L& w, const L& x, const L& y, const L& z, L* R) {
  const L tx = 2.0 * x, ty = 2.0 * y, tz = 2.0 * z;
  const L twx = tx * w, twy = ty * w, twz = tz * w;
  const L txx = tx * x, txy = ty * x, txz = tz * x;
  const L tyy = ty * y, tyz = tz * y, tzz = tz * z;
  R[0] = 1.0 - (tyy + tzz);
  R[1] = txy - twz;
  R[2] = txz + twy;
  R[3] = txy + twz;
  R[4] = 1.0 - (txx + tzz);
  R[5] = tyz - twx;
  R[6] = txz - twy;
  R[7] = tyz + twx;
  R[8] = 1.0 - (txx + tyy);
}

// F (row-major) and the start q (w, x, y, z) of each lane -> q turned to the fit, R (row-major).
template <class L>
[[gnu::always_inline]] inline void fit(const L* F, L* q, L* R) {
  to_matrix(q[0], q[1], q[2], q[3], R);
  auto active = L{} == L{};  // every lane
  for (int it = 0; it < 40; ++it) {
    L M[9];  // F R^T
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) M[3 * i + j] = F[3 * i] * R[3 * j] + F[3 * i + 1] * R[3 * j + 1] + F[3 * i + 2] * R[3 * j + 2];
    const L tau_x = M[7] - M[5], tau_y = M[2] - M[6], tau_z = M[3] - M[1];
    const L trace = M[0] + M[4] + M[8];
    // H (symmetric) by its six entries, its cofactors and determinant: the turn H^-1 tau is
    // the cofactors' product over the determinant.
    const L h00 = trace - M[0], h11 = trace - M[4], h22 = trace - M[8];
    const L h01 = -0.5 * (M[1] + M[3]), h02 = -0.5 * (M[2] + M[6]), h12 = -0.5 * (M[5] + M[7]);
    const L c00 = h11 * h22 - h12 * h12, c01 = h02 * h12 - h01 * h22, c02 = h01 * h12 - h02 * h11;
    const L c11 = h00 * h22 - h02 * h02, c12 = h01 * h02 - h00 * h12, minor = h00 * h11 - h01 * h01;
    const L det = h00 * c00 + h01 * c01 + h02 * c02;
    const auto newton = (h00 > 0.0) & (minor > 0.0) & (det > 1e-12 * lane_abs(trace * trace * trace));
    const L slow = lane_abs(trace) + 1e-12;
    const L ox = pick(newton, (c00 * tau_x + c01 * tau_y + c02 * tau_z) / det, tau_x / slow);
    const L oy = pick(newton, (c01 * tau_x + c11 * tau_y + c12 * tau_z) / det, tau_y / slow);
    const L oz = pick(newton, (c02 * tau_x + c12 * tau_y + minor * tau_z) / det, tau_z / slow);
    const L angle = lane_sqrt(ox * ox + oy * oy + oz * oz);
    // The rotation to 1e-10 rad: its load is then exact to far below the tolerance.
    const auto turning = active & lane_not(angle < 1e-10);
    if (!any(turning)) break;
    // Below 1e-3 rad the turn's quaternion to first order, normalised: off by angle^3 / 24,
    // which the next iteration takes up; it spares a sine and a cosine.
    L tw = L{} + 1.0, tx = 0.5 * ox, ty = 0.5 * oy, tz = 0.5 * oz;
    const auto large = turning & lane_not(angle < 1e-3);
    if (any(large))
      for (int k = 0; k < kLanes<L>; ++k) {
        if (!mask_at(large, k)) continue;
        const double a = get(angle, k), half = 0.5 * a, s = std::sin(half);
        lane_of(tw, k) = std::cos(half);
        lane_of(tx, k) = s * (get(ox, k) / a);
        lane_of(ty, k) = s * (get(oy, k) / a);
        lane_of(tz, k) = s * (get(oz, k) / a);
      }
    // q = turn q, normalised.
    L w = tw * q[0] - tx * q[1] - ty * q[2] - tz * q[3];
    L x = tw * q[1] + tx * q[0] + ty * q[3] - tz * q[2];
    L y = tw * q[2] + ty * q[0] + tz * q[1] - tx * q[3];
    L z = tw * q[3] + tz * q[0] + tx * q[2] - ty * q[1];
    const L norm = lane_sqrt(w * w + x * x + y * y + z * z);
    w = w / norm, x = x / norm, y = y / norm, z = z / norm;
    L Rn[9];
    to_matrix(w, x, y, z, Rn);
    q[0] = pick(turning, w, q[0]);
    q[1] = pick(turning, x, q[1]);
    q[2] = pick(turning, y, q[2]);
    q[3] = pick(turning, z, q[3]);
    for (int k = 0; k < 9; ++k) R[k] = pick(turning, Rn[k], R[k]);
    // Newton's step leaves an error of the order of its square: below 3e-4 rad, 1e-7 rad or
    // less, which the core's next iteration takes up (it fits again from here, with turns that
    // shrink as it converges, so its last fits are exact to 1e-10). A second pass to confirm
    // each such fit would be a third more passes on a press and two thirds more on a slide,
    // for the same iterations and forces. A looser bound lets a slowly converging bend stop
    // short (ElasticCore.LoadedBendingStopsNearItsFixedPoint, by 1.2 % at 1e-3 rad).
    active = turning & lane_not(newton & (angle < 3e-4));
    if (!any(active)) break;
  }
}

VDM_AVX2 void fit4(const Eigen::Matrix3d* F, Eigen::Quaterniond* const* q, Eigen::Matrix3d* R) {
  V4 f[9], qq[4], r[9];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) f[3 * i + j] = V4{F[0](i, j), F[1](i, j), F[2](i, j), F[3](i, j)};
  qq[0] = V4{q[0]->w(), q[1]->w(), q[2]->w(), q[3]->w()};
  qq[1] = V4{q[0]->x(), q[1]->x(), q[2]->x(), q[3]->x()};
  qq[2] = V4{q[0]->y(), q[1]->y(), q[2]->y(), q[3]->y()};
  qq[3] = V4{q[0]->z(), q[1]->z(), q[2]->z(), q[3]->z()};
  fit(f, qq, r);
  for (int k = 0; k < 4; ++k) {
    *q[k] = Eigen::Quaterniond(qq[0][k], qq[1][k], qq[2][k], qq[3][k]);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) R[k](i, j) = r[3 * i + j][k];
  }
}

}  // namespace

Eigen::Matrix3d nearest_rotation(const Eigen::Matrix3d& F, Eigen::Quaterniond& q) {
  double f[9], qq[4] = {q.w(), q.x(), q.y(), q.z()}, r[9];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) f[3 * i + j] = F(i, j);
  fit(f, qq, r);
  q = Eigen::Quaterniond(qq[0], qq[1], qq[2], qq[3]);
  Eigen::Matrix3d R;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R(i, j) = r[3 * i + j];
  return R;
}

void nearest_rotations4(const Eigen::Matrix3d* F, Eigen::Quaterniond* const* q, Eigen::Matrix3d* R) {
  if (simd::avx2_enabled()) {
    fit4(F, q, R);
    return;
  }
  for (int k = 0; k < 4; ++k) R[k] = nearest_rotation(F[k], *q[k]);
}

}  // namespace vdm::core
