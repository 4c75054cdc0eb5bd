#pragma once
// Basic array types shared by the engine. Every per-node array is N x 3 and column-major,
// so column d (0 = x, 1 = y, 2 = z) is one contiguous per-axis vector of length N.
#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace vdm {

using Vec = Eigen::VectorXd;
using NodeMat = Eigen::Matrix<double, Eigen::Dynamic, 3>;  // N x 3, metres / newtons / ...
using FlagMat = Eigen::Matrix<std::uint8_t, Eigen::Dynamic, 3>;  // N x 3 per-axis flags
using TriMat = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;  // T x 3 node indices
using Vec3 = Eigen::Vector3d;

// A closed triangle surface: the only geometry an organ has in VDM.
struct SurfaceMesh {
  NodeMat positions;   // N x 3 rest positions (m)
  TriMat triangles;    // T x 3, counter-clockwise seen from outside (outward normals)
  int node_count() const { return static_cast<int>(positions.rows()); }
  int triangle_count() const { return static_cast<int>(triangles.rows()); }
};

}  // namespace vdm
