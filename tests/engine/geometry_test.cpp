#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <vector>

#include "app/scene/mesh_io.hpp"
#include "engine/geometry.hpp"
#include "engine/shapes.hpp"
#include "engine/simd4.hpp"
#include "support/simd_paths.hpp"

namespace vdm {
namespace {

TEST(Geometry, BoxVolumeAndAreaAreExact) {
  const SurfaceMesh box = make_box(Vec3(0.2, 0.3, 0.5), 3, 4, 5);
  EXPECT_NEAR(enclosed_volume(box.positions, box.triangles, Vec3(1, 2, 3)), 0.03, 1e-14);
  EXPECT_NEAR(surface_area(box.positions, box.triangles), 2 * (0.06 + 0.1 + 0.15), 1e-14);
}

TEST(Geometry, SphereVolumeConvergesToAnalytic) {
  const double r = 0.05, exact = 4.0 / 3.0 * M_PI * r * r * r;
  double prev_err = 1.0;
  for (int level = 1; level <= 4; ++level) {
    const SurfaceMesh s = make_icosphere(r, level);
    const double err = std::abs(enclosed_volume(s.positions, s.triangles, Vec3::Zero()) - exact) / exact;
    EXPECT_LT(err, prev_err / 3.0) << "level " << level;  // second order: ~4x per level
    prev_err = err;
  }
  EXPECT_LT(prev_err, 3e-3);
}

TEST(Geometry, AreaVectorsSumToZeroOnClosedSurface) {
  const SurfaceMesh s = make_uv_sphere(0.04, 9, 13);
  NodeMat A(s.node_count(), 3);
  distributed_area_vectors(s.positions, s.triangles, A);
  EXPECT_LT(A.colwise().sum().norm(), 1e-15);
  // Each A_i points outward on a sphere.
  for (int i = 0; i < s.node_count(); ++i) EXPECT_GT(A.row(i).dot(s.positions.row(i)), 0.0);
}

// The step's one-pass version gives the same bits as the two separate passes.
TEST(Geometry, OnePassAreaVectorsAndVolumeEqualTheSeparatePasses) {
  SurfaceMesh s = make_icosphere(0.05, 3);
  for (int i = 0; i < s.node_count(); ++i)  // deformed, off the origin
    s.positions.row(i) = Vec3(0.3 + 1.2 * s.positions(i, 0), -0.1 + s.positions(i, 1) * (1 + 3 * s.positions(i, 2)),
                              0.7 * s.positions(i, 2)).transpose();
  const Vec3 origin(0.31, -0.12, 0.01);
  NodeMat A(s.node_count(), 3), B(s.node_count(), 3);
  std::vector<double> packed;
  const double v = area_vectors_and_volume(s.positions, s.triangles, origin, A, packed);
  distributed_area_vectors(s.positions, s.triangles, B);
  EXPECT_EQ(v, enclosed_volume(s.positions, s.triangles, origin));
  EXPECT_EQ(A, B);
  EXPECT_EQ(packed.size(), 6u * size_t(s.node_count()));
}

// The step keeps a volume check's pass for the next refresh (packed_area_sums_and_volume,
// unpack_area_vectors) when the positions are still those bits (packed_positions_equal).
TEST(Geometry, PackedSumsAreTheOnePassResultAndKnowTheirPositions) {
  SurfaceMesh s = make_icosphere(0.05, 3);  // 642 nodes: more than one block of the comparison
  for (int i = 0; i < s.node_count(); ++i) s.positions.row(i) += Vec3(0.2, -0.1, 0.05 * s.positions(i, 0)).transpose();
  const Vec3 origin(0.2, -0.1, 0.0);
  NodeMat A(s.node_count(), 3), B(s.node_count(), 3);
  std::vector<double> packed, scratch;
  const double v = packed_area_sums_and_volume(s.positions, s.triangles, origin, packed);
  unpack_area_vectors(packed, A);
  EXPECT_EQ(v, area_vectors_and_volume(s.positions, s.triangles, origin, B, scratch));
  EXPECT_EQ(v, enclosed_volume(s.positions, s.triangles, origin));
  EXPECT_EQ(A, B);
  EXPECT_TRUE(packed_positions_equal(s.positions, packed));
  // Any one coordinate changed, on any axis, in the first, a middle or the last node.
  for (int node : {0, 300, s.node_count() - 1})
    for (int d = 0; d < 3; ++d) {
      NodeMat moved = s.positions;
      moved(node, d) = std::nextafter(moved(node, d), 1.0);
      EXPECT_FALSE(packed_positions_equal(moved, packed)) << "node " << node << " axis " << d;
    }
  // Bits, not values: -0 is not 0.
  NodeMat zero = s.positions;
  zero(5, 1) = 0.0;
  packed_area_sums_and_volume(zero, s.triangles, origin, packed);
  zero(5, 1) = -0.0;
  EXPECT_FALSE(packed_positions_equal(zero, packed));
  // Another node count.
  EXPECT_FALSE(packed_positions_equal(s.positions.topRows(s.node_count() - 1), packed));
}

// The pass as one triangle at a time in plain scalar code (the formula of the Eigen version it
// replaced): positions row by row, the cross products s = (b - a) x (c - a) summed at the
// corners a, b, c in triangle order, 6 V = sum_k ((a_x - o_x) s_x + (a_y - o_y) s_y) + (a_z - o_z) s_z.
double scalar_packed_area_sums_and_volume(const NodeMat& x, const TriMat& tris, const Vec3& o,
                                          std::vector<double>& packed) {
  const size_t n = size_t(x.rows());
  packed.assign(6 * n, 0.0);
  for (size_t i = 0; i < n; ++i)
    for (int d = 0; d < 3; ++d) packed[3 * i + size_t(d)] = x(Eigen::Index(i), d);
  double six_v = 0.0;
  for (Eigen::Index k = 0; k < tris.rows(); ++k) {
    const double* a = &packed[3 * size_t(tris(k, 0))];
    const double* b = &packed[3 * size_t(tris(k, 1))];
    const double* c = &packed[3 * size_t(tris(k, 2))];
    const double ux = b[0] - a[0], uy = b[1] - a[1], uz = b[2] - a[2];
    const double vx = c[0] - a[0], vy = c[1] - a[1], vz = c[2] - a[2];
    const double s[3] = {uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx};
    for (int corner = 0; corner < 3; ++corner)
      for (size_t d = 0; d < 3; ++d) packed[3 * n + 3 * size_t(tris(k, corner)) + d] += s[d];
    six_v += ((a[0] - o.x()) * s[0] + (a[1] - o.y()) * s[1]) + (a[2] - o.z()) * s[2];
  }
  return six_v / 6.0;
}

std::uint64_t bits(double v) {
  std::uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

// The two-triangles-at-a-time pass gives the scalar pass's bits: on the 2.5k and 10k livers
// (deformed, off the origin), with an odd triangle count, and with triangles that repeat a node
// (a node's sums then take two terms of one triangle, in corner order).
// Both variants of the pass (SSE2, two triangles at a time; AVX2, four), the AVX2 half skipped
// where the CPU lacks AVX2.
TEST(Geometry, PackedPassIsTheScalarPassBitForBit) {
  if (!simd::avx2_supported()) std::printf("[ SKIPPED  ] the AVX2 half: no AVX2 on this CPU\n");
  simd_test::sse2_then_avx2([](bool avx2) {
    if (avx2 && !simd::avx2_enabled()) return;
    SCOPED_TRACE(avx2 ? "AVX2" : "SSE2");
    for (const char* name : {"liver_L4.obj", "liver_L5.obj"}) {
      const auto path = std::filesystem::path(VDMSIM_SOURCE_DIR) / "assets/meshes" / name;
      const vdmsim::MeshLoadResult mesh = vdmsim::load_surface_mesh(path.string());
      ASSERT_TRUE(mesh.ok) << mesh.error;
      NodeMat x = mesh.mesh.positions;
      for (Eigen::Index i = 0; i < x.rows(); ++i)
        x.row(i) = Vec3(0.3 + 1.2 * x(i, 0), -0.1 + x(i, 1) * (1 + 3 * x(i, 2)), 0.7 * x(i, 2) - 0.02).transpose();
      const Vec3 origin(0.31, -0.12, 0.01);
      const TriMat& all = mesh.mesh.triangles;
      TriMat repeated(all.rows() + 3, 3);
      repeated.topRows(all.rows()) = all;
      repeated.row(all.rows()) << 7, 7, 12;
      repeated.row(all.rows() + 1) << 12, 7, 12;
      repeated.row(all.rows() + 2) << 3, 3, 3;
      const TriMat odd = all.topRows(all.rows() - 1);
      ASSERT_EQ(odd.rows() % 2, 1);
      // Every remainder of a division by four (the AVX2 pass's fours, then pairs, then one).
      const TriMat less2 = all.topRows(all.rows() - 2), less3 = all.topRows(all.rows() - 3);
      int case_index = 0;
      for (const TriMat* tris : {&all, static_cast<const TriMat*>(&odd), static_cast<const TriMat*>(&repeated),
                                 static_cast<const TriMat*>(&less2), static_cast<const TriMat*>(&less3)}) {
        std::vector<double> expected, packed(5, 1.0);  // a stale packed of another size
        const double v_expected = scalar_packed_area_sums_and_volume(x, *tris, origin, expected);
        const double v = packed_area_sums_and_volume(x, *tris, origin, packed);
        EXPECT_EQ(bits(v), bits(v_expected)) << name << " case " << case_index;
        ASSERT_EQ(packed.size(), expected.size());
        size_t differing = 0;
        for (size_t j = 0; j < packed.size(); ++j) differing += bits(packed[j]) != bits(expected[j]);
        EXPECT_EQ(differing, 0u) << name << " case " << case_index;
        // And again into the same packed (sums restarted from zero).
        EXPECT_EQ(bits(packed_area_sums_and_volume(x, *tris, origin, packed)), bits(v_expected));
        EXPECT_TRUE(packed == expected);
        ++case_index;
      }
      // An odd node count (the packing's and the comparison's last node alone).
      const NodeMat fewer = x.topRows(x.rows() - (x.rows() % 2 == 0 ? 1 : 0));
      ASSERT_EQ(fewer.rows() % 2, 1);
      TriMat kept(all.rows(), 3);
      Eigen::Index kept_count = 0;
      for (Eigen::Index k = 0; k < all.rows(); ++k)
        if (all.row(k).maxCoeff() < fewer.rows()) kept.row(kept_count++) = all.row(k);
      const TriMat some = kept.topRows(kept_count);
      std::vector<double> expected, packed;
      EXPECT_EQ(bits(packed_area_sums_and_volume(fewer, some, origin, packed)),
                bits(scalar_packed_area_sums_and_volume(fewer, some, origin, expected)));
      EXPECT_TRUE(packed == expected);
      EXPECT_TRUE(packed_positions_equal(fewer, packed));
      for (Eigen::Index node : {Eigen::Index(0), fewer.rows() - 2, fewer.rows() - 1})
        for (int d = 0; d < 3; ++d) {
          NodeMat moved = fewer;
          moved(node, d) = -moved(node, d);
          EXPECT_FALSE(packed_positions_equal(moved, packed)) << name << " node " << node << " axis " << d;
        }
    }
  });
}

TEST(Geometry, DistributedVolumesSumToVolume) {
  const SurfaceMesh s = make_box(Vec3(0.1, 0.2, 0.3), 2, 5, 3);
  NodeMat A(s.node_count(), 3);
  distributed_area_vectors(s.positions, s.triangles, A);
  Vec Vi(s.node_count());
  const double V = enclosed_volume(s.positions, s.triangles, Vec3::Zero());
  distributed_volumes(A, V, Vi);
  EXPECT_NEAR(Vi.sum(), V, 1e-15);
  EXPECT_GT(Vi.minCoeff(), 0.0);
  // Proportional to |A_i|.
  for (int i = 0; i < s.node_count(); ++i) EXPECT_NEAR(Vi[i] / A.row(i).norm(), V / A.rowwise().norm().sum(), 1e-12);
}

// The step's pass: A_i and |A_i| from the packed sums at once, their sum and smallest (pairs
// of nodes, and the last one alone when N is odd).
TEST(Geometry, UnpackedNormsAreTheAreaVectorsLengths) {
  int odd = 0;
  for (const SurfaceMesh& s : {make_icosphere(0.05, 3), make_uv_sphere(0.04, 9, 13), make_uv_sphere(0.04, 10, 13)}) {
    const int n = s.node_count();
    odd += n % 2;
    NodeMat A(n, 3), B(n, 3);
    Vec norms(n);
    std::vector<double> packed;
    area_vectors_and_volume(s.positions, s.triangles, Vec3::Zero(), A, packed);
    const AreaNormSums sums = unpack_area_vectors_and_norms(packed, B, norms);
    EXPECT_EQ(A, B);
    double total = 0.0;
    for (int i = 0; i < n; ++i) {
      EXPECT_NEAR(norms[i], A.row(i).norm(), 1e-15 * A.row(i).norm()) << "node " << i;
      total += norms[i];
    }
    EXPECT_NEAR(sums.total, total, 1e-14 * total);
    EXPECT_EQ(sums.smallest, norms.minCoeff());
    // A non-finite area sum leaves the total non-finite.
    packed[3 * size_t(n) + 3 * size_t(n - 1) + 1] = std::numeric_limits<double>::quiet_NaN();
    EXPECT_FALSE(std::isfinite(unpack_area_vectors_and_norms(packed, B, norms).total));
    packed[3 * size_t(n) + 4] = std::numeric_limits<double>::infinity();
    EXPECT_FALSE(std::isfinite(unpack_area_vectors_and_norms(packed, B, norms).total));
  }
  EXPECT_GE(odd, 1);  // both paths of the pass
}

// The AVX2 unpacking (four nodes at a time) gives the SSE2 one's bits: area vectors, lengths,
// their sum (summed in the same order) and smallest, for every remainder of a division by four
// of the node count.
TEST(Geometry, UnpackingWithAvx2IsTheSse2UnpackingBitForBit) {
  if (!simd::avx2_supported()) GTEST_SKIP() << "this CPU lacks AVX2: only the SSE2 unpacking runs here";
  const SurfaceMesh s = make_uv_sphere(0.04, 9, 13);
  for (int drop = 0; drop < 4; ++drop) {
    const Eigen::Index n = s.node_count() - drop;
    std::vector<double> packed(6 * size_t(n));
    for (size_t j = 0; j < packed.size(); ++j) packed[j] = std::sin(0.37 * double(j)) * (1.0 + double(j % 7));
    NodeMat a[2] = {NodeMat(n, 3), NodeMat(n, 3)};
    Vec norms[2] = {Vec(n), Vec(n)};
    AreaNormSums sums[2];
    simd_test::sse2_then_avx2(
        [&](bool avx2) { sums[avx2] = unpack_area_vectors_and_norms(packed, a[avx2], norms[avx2]); });
    EXPECT_EQ(0, std::memcmp(a[0].data(), a[1].data(), sizeof(double) * 3 * size_t(n))) << "drop " << drop;
    EXPECT_EQ(0, std::memcmp(norms[0].data(), norms[1].data(), sizeof(double) * size_t(n))) << "drop " << drop;
    EXPECT_EQ(bits(sums[0].total), bits(sums[1].total)) << "drop " << drop;
    EXPECT_EQ(bits(sums[0].smallest), bits(sums[1].smallest)) << "drop " << drop;
  }
}

// V_i = scale max(|A_i|, floor_area), as the returned VolumeScale says, floored or not.
TEST(Geometry, VolumeScaleDescribesTheDistributedVolumes) {
  const SurfaceMesh s = make_icosphere(0.05, 2);
  NodeMat A(s.node_count(), 3);
  distributed_area_vectors(s.positions, s.triangles, A);
  const Vec norms = A.rowwise().norm();
  const double V = enclosed_volume(s.positions, s.triangles, Vec3::Zero());
  for (double min_fraction : {1e-9, 1.0}) {  // 1: the floor is the mean area, some nodes below it
    Vec Vi(s.node_count());
    const VolumeScale how = distributed_volumes_from_norms(norms, V, Vi, min_fraction);
    EXPECT_NEAR(how.floor_area, min_fraction * norms.mean(), 1e-15 * norms.mean());
    int floored = 0;
    for (int i = 0; i < s.node_count(); ++i) {
      floored += how.floored(norms[i]);
      EXPECT_EQ(Vi[i], how.scale * std::max(norms[i], how.floor_area)) << "node " << i;
    }
    EXPECT_EQ(how.any_floored, floored > 0);
    EXPECT_EQ(how.any_floored, min_fraction == 1.0);
    EXPECT_NEAR(Vi.sum(), V, 1e-14 * V);
  }
}

TEST(Geometry, AreaVectorsAreTheVolumeGradient) {
  // sum_i A_i . dx_i is the first-order change of V (what makes the volume row exact).
  const SurfaceMesh s = make_icosphere(0.05, 2);
  NodeMat A(s.node_count(), 3);
  distributed_area_vectors(s.positions, s.triangles, A);
  const NodeMat dir = NodeMat::Random(s.node_count(), 3);
  const double h = 1e-6;
  const NodeMat xp = s.positions + h * dir, xm = s.positions - h * dir;
  const double fd = (enclosed_volume(xp, s.triangles, Vec3::Zero()) -
                     enclosed_volume(xm, s.triangles, Vec3::Zero())) / (2 * h);
  const double analytic = (A.array() * dir.array()).sum();
  EXPECT_NEAR(fd, analytic, 1e-8 * std::abs(analytic) + 1e-14);
}

TEST(Geometry, ClosestPointOnATriangleInEveryRegion) {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  // Above the face: the projection.
  Vec3 w = closest_barycentric(Vec3(0.25, 0.25, 3), a, b, c);
  EXPECT_NEAR(w[0], 0.5, 1e-12);
  EXPECT_NEAR(w[1], 0.25, 1e-12);
  EXPECT_NEAR(w[2], 0.25, 1e-12);
  // Beyond a vertex, beyond an edge.
  w = closest_barycentric(Vec3(2, -1, 0.5), a, b, c);
  EXPECT_NEAR(w[1], 1.0, 1e-12);
  w = closest_barycentric(Vec3(0.5, -2, 0), a, b, c);
  EXPECT_NEAR(w[0], 0.5, 1e-12);
  EXPECT_NEAR(w[1], 0.5, 1e-12);
  EXPECT_NEAR(w[2], 0.0, 1e-12);
  w = closest_barycentric(Vec3(1, 1, 0), a, b, c);  // beyond the hypotenuse
  EXPECT_NEAR(w[1], 0.5, 1e-12);
  EXPECT_NEAR(w[2], 0.5, 1e-12);
}

}  // namespace
}  // namespace vdm
