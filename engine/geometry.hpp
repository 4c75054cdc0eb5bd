#pragma once
// Surface geometry of the VDM model (vdm-model.md section 1, paper eqs 1-2).
#include <limits>
#include <vector>

#include "engine/types.hpp"

namespace vdm {

// Volume enclosed by a closed, outward-oriented surface (m^3): sum_k x_a.(x_b x x_c)/6,
// evaluated relative to `origin` for round-off (the result does not depend on it).
double enclosed_volume(const NodeMat& x, const TriMat& tris, const Vec3& origin);

// Total surface area (m^2).
double surface_area(const NodeMat& x, const TriMat& tris);

// Eq (1): distributed area vectors A_i = sum_{k containing i} S_k / 3, written into
// `area_vectors` (N x 3, must already have N rows). S_k = (x_b - x_a) x (x_c - x_a) / 2.
void distributed_area_vectors(const NodeMat& x, const TriMat& tris, NodeMat& area_vectors);

// Both of the above in one pass over the triangles (the same values): writes the area
// vectors and returns the enclosed volume. `packed` (6 N doubles once sized: no allocation
// after the first call) holds positions and sums row by row, so that a triangle's corner is
// one cache line, not three.
double area_vectors_and_volume(const NodeMat& x, const TriMat& tris, const Vec3& origin, NodeMat& area_vectors,
                               std::vector<double>& packed);
// The pass of area_vectors_and_volume() without its last step: `packed` gets x (3 N, row by
// row) and the sums of the cross products at each node (3 N, 6 A_i row by row); returns the
// enclosed volume, bit for bit that of area_vectors_and_volume() and enclosed_volume().
double packed_area_sums_and_volume(const NodeMat& x, const TriMat& tris, const Vec3& origin,
                                   std::vector<double>& packed);
// A_i from a `packed` of packed_area_sums_and_volume(): the area vectors it sums, N x 3.
void unpack_area_vectors(const std::vector<double>& packed, NodeMat& area_vectors);
// The sum of the lengths |A_i| and the smallest of them.
struct AreaNormSums {
  double total = 0.0;
  double smallest = std::numeric_limits<double>::infinity();
};
// unpack_area_vectors() and |A_i| (`area_norms`, N) in the same pass; returns their sum and
// smallest. The sum is finite only when every A_i is (a non-finite component makes its norm,
// and so the sum, inf or NaN).
AreaNormSums unpack_area_vectors_and_norms(const std::vector<double>& packed, NodeMat& area_vectors, Vec& area_norms);
// Whether `packed` holds exactly the positions x (bit for bit), as packed_area_sums_and_volume()
// wrote them.
bool packed_positions_equal(const NodeMat& x, const std::vector<double>& packed);

// How the V_i were made from the |A_i| (distributed_volumes_from_norms): V_i = scale max(|A_i|,
// floor_area), so V_i = scale |A_i| at every node whose |A_i| is not below floor_area
// (any_floored: some node's is). What lets the stiffness's edge weights go without a division
// (assemble_stiffness). The default describes volumes of no such form: every node floored.
struct VolumeScale {
  double scale = 0.0;
  double floor_area = std::numeric_limits<double>::infinity();
  bool any_floored = true;
  bool floored(double area_norm) const { return area_norm < floor_area; }
};
// Eq (2) with the normalisation choice of vdm-model.md: V_i = V |A_i| / sum_j |A_j|,
// so that sum_i V_i = V exactly. `volumes` must have N entries. A node whose distributed
// area is below `min_fraction` of the mean gets that floor (keeps V_i > 0). Returns how the
// V_i were made.
VolumeScale distributed_volumes(const NodeMat& area_vectors, double volume, Vec& volumes,
                                double min_fraction = 1e-9);
// The same from the lengths |A_i| (`area_norms`, N) of the area vectors, and from their sum
// and smallest when known (unpack_area_vectors_and_norms).
VolumeScale distributed_volumes_from_norms(const Vec& area_norms, double volume, Vec& volumes,
                                           double min_fraction = 1e-9);
VolumeScale distributed_volumes_from_norms(const Vec& area_norms, const AreaNormSums& sums, double volume,
                                           Vec& volumes, double min_fraction = 1e-9);

// Index of the node of x nearest to p (the first one on a tie).
int nearest_node(const NodeMat& x, const Vec3& p);

// The point of triangle (a, b, c) closest to p, as barycentric weights (w_a, w_b, w_c):
// the region of the triangle's plane p projects into (vertex, edge or face) decides.
Vec3 closest_barycentric(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

}  // namespace vdm
