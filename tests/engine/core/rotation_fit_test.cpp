// The core's rotation fit: the polar factor of F from any start, and four at a time (AVX2)
// exactly as one at a time.
#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <random>
#include <vector>

#include "engine/core/rotation_fit.hpp"
#include "support/simd_paths.hpp"

namespace vdm::core {
namespace {

Eigen::Quaterniond random_rotation(std::mt19937& rng, double max_angle) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Vector3d axis(u(rng), u(rng), u(rng));
  if (axis.norm() < 1e-3) axis = Eigen::Vector3d::UnitZ();
  return Eigen::Quaterniond(Eigen::AngleAxisd(max_angle * 0.5 * (u(rng) + 1.0), axis.normalized()));
}

// F = R0 S, S symmetric positive definite (stretches up to +-`stretch`).
Eigen::Matrix3d random_gradient(std::mt19937& rng, const Eigen::Quaterniond& R0, double stretch) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Matrix3d V = random_rotation(rng, 3.14).toRotationMatrix();
  const Eigen::Vector3d s(1 + stretch * u(rng), 1 + stretch * u(rng), 1 + stretch * u(rng));
  return R0.toRotationMatrix() * V * s.asDiagonal() * V.transpose();
}

Eigen::Matrix3d polar_factor(const Eigen::Matrix3d& F) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixU() * svd.matrixV().transpose();
}

TEST(RotationFit, FindsThePolarFactorFromNearAndFarStarts) {
  std::mt19937 rng(7);
  for (int k = 0; k < 200; ++k) {
    const Eigen::Quaterniond R0 = random_rotation(rng, 3.0);
    const Eigen::Matrix3d F = random_gradient(rng, R0, 0.4);
    // From a start near the answer (a warm start) and from the identity (up to 172 degrees off).
    for (const Eigen::Quaterniond& start : {R0 * random_rotation(rng, 0.05), Eigen::Quaterniond::Identity()}) {
      Eigen::Quaterniond q = start;
      // Fitted again from its own answer, as the core does at each iteration: the second fit
      // is within 1e-7 rad of the first (Newton's step stops at 3e-4 rad) and then exact.
      for (int again = 0; again < 3; ++again) (void)nearest_rotation(F, q);
      const Eigen::Matrix3d R = nearest_rotation(F, q);
      EXPECT_LT((R - polar_factor(F)).cwiseAbs().maxCoeff(), 1e-9) << "case " << k;
      EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-12);
      EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
      EXPECT_NEAR(q.norm(), 1.0, 1e-12);
    }
  }
}

TEST(RotationFit, FourAtATimeGiveTheSameBitsAsOneAtATime) {
  if (!simd::avx2_supported()) GTEST_SKIP() << "this CPU lacks AVX2: only the one-at-a-time fit runs here";
  std::mt19937 rng(11);
  // Lanes that need different numbers of passes side by side: warm starts, cold starts across
  // large turns (the sine and cosine lanes), strong stretches, an inverted gradient and F = 0.
  std::vector<Eigen::Matrix3d> F;
  std::vector<Eigen::Quaterniond> start;
  for (int k = 0; k < 400; ++k) {
    const Eigen::Quaterniond R0 = random_rotation(rng, 3.0);
    F.push_back(random_gradient(rng, R0, k % 3 == 0 ? 0.9 : 0.2));
    start.push_back(k % 4 == 1 ? Eigen::Quaterniond::Identity() : R0 * random_rotation(rng, k % 5 == 0 ? 0.5 : 1e-3));
  }
  F[5] = -F[5];
  F[10].setZero();
  for (int group = 0; group + 4 <= static_cast<int>(F.size()); group += 4) {
    Eigen::Matrix3d one[4], four[4];
    Eigen::Quaterniond q_one[4], q_four[4];
    simd_test::sse2_then_avx2([&](bool avx2) {
      Eigen::Quaterniond* q[4];
      for (int k = 0; k < 4; ++k) {
        (avx2 ? q_four : q_one)[k] = start[static_cast<size_t>(group + k)];
        q[k] = &(avx2 ? q_four : q_one)[k];
      }
      nearest_rotations4(&F[static_cast<size_t>(group)], q, avx2 ? four : one);
    });
    for (int k = 0; k < 4; ++k) {
      EXPECT_TRUE(one[k] == four[k]) << "gradient " << group + k;
      EXPECT_TRUE(q_one[k].coeffs() == q_four[k].coeffs()) << "gradient " << group + k;
      // and each lane as the one-at-a-time fit
      Eigen::Quaterniond q = start[static_cast<size_t>(group + k)];
      EXPECT_TRUE(nearest_rotation(F[static_cast<size_t>(group + k)], q) == four[k]) << "gradient " << group + k;
      EXPECT_TRUE(q.coeffs() == q_four[k].coeffs()) << "gradient " << group + k;
    }
  }
}

}  // namespace
}  // namespace vdm::core
