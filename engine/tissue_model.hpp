#pragma once
// TissueModel: everything about an organ that does not change during a run (MuJoCo's
// mjModel): rest surface, moduli, constraints, settings and the fixed sparsity pattern.
// Built once from a TissueDef; read-only afterwards.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "engine/neighbour_lists.hpp"
#include "engine/settings.hpp"
#include "engine/sparse.hpp"
#include "engine/types.hpp"

namespace vdm {

// The capsule (skin) term of the model (docs/model.md, "the capsule").
enum class CapsuleForm {
  // A membrane under tension T = B_ij V_0 / A_0 (N/m): energy ½ T ∫ |∇u|² dA, discretised by
  // the cotangent weights of the rest surface (linear finite elements). Converges under mesh
  // refinement (the default).
  membrane,
  // The membrane with per-node rotations fitted to the neighbourhood (corotational, as-rigid-
  // as-possible): a rigid rotation of a patch costs nothing, so twists and large bends carry.
  corotational,
  // The paper's edge weights w_ij = B_ij a_ij² / V_ij at the current geometry (eq 4): a
  // stiffness per edge, not per metre, which fades against the bulk term as the mesh is
  // refined. Kept so that the paper's experiments run as published.
  paper,
};
const char* to_string(CapsuleForm c);
bool parse_capsule_form(const std::string& text, CapsuleForm& out);

struct TissueDef {
  SurfaceMesh mesh;                     // closed, outward; metres
  NodeMat bulk_modulus;                 // N x 3 per-node per-axis B_i^d (Pa); +inf allowed
                                        // (a constraint u_i^d = 0). Empty: use `bulk`.
  double bulk = 20000.0;                // uniform B (Pa) when bulk_modulus is empty
  double connectivity_modulus = 2000.0; // B_ij (Pa), eq (4)
  CapsuleForm capsule = CapsuleForm::membrane;
  // Membrane capsules: the cotangent weights of the mesh's own triangles (false: the P1 finite
  // element membrane, whose thin triangles resist being turned over; weights may be negative
  // on obtuse triangles, the matrix stays SPD) or of its intrinsic Delaunay triangulation
  // (true: every weight >= 0, but a sliver's nodes are then held only loosely in line).
  bool capsule_delaunay = false;
  // The capsule's thin-shell bending modulus D (N·m; membrane capsules; 0: none): energy
  // ½ D ∫ |Δ_S u|² dA over the rest surface (engine/capsule_bending.hpp).
  double bending_modulus = 0.0;
  // Floor of the per-axis bulk stiffness, as a fraction of the node's full-area stiffness:
  // k_i^d = B_i^d max((A_i^d)^2, floor |A_i|^2) / V_i. Without it a node whose area vector
  // has almost no component along d (a flat face, d in its plane) is held along d by the
  // connectivity term alone, and moves as 1 / A_i^d when that is weak. 0 = the paper's term.
  double axis_stiffness_floor = 0.0;
  double density = 1060.0;              // kg/m^3
  Vec3 gravity = Vec3(0, 0, -9.81);     // m/s^2, used when `use_gravity`
  bool use_gravity = false;             // hydrostatic load, eq (9)
  bool volume_constraint = true;        // eq (11): the uniform pressure unknown
  bool use_inertia = false;             // section 8: implicit Euler, lumped mass rho V_i
  bool compute_stress = true;           // section 7: strain and stress after each step
  double damping = 0.0;                 // mass-proportional damping (1/s), with inertia
  double dt = 1.0 / 30.0;               // step (s): used by inertia and for time stamps
  FlagMat fixed;                        // N x 3: 1 = u_i^d held at 0. Empty: none.
  SolverSettings solver;
};

// Returns a definition for `mesh` with uniform moduli and no constraints.
TissueDef default_tissue(SurfaceMesh mesh);

struct TissueModel {
  SurfaceMesh rest;                      // rest surface X (m)
  int n = 0;                             // nodes
  std::vector<std::array<int, 2>> edges; // unique edges (i < j): the mesh's (paper capsule) or
                                         // the intrinsic Delaunay triangulation's (membrane)
  Vec3 origin;                           // rest centroid, reference point for volumes
  double rest_volume = 0;                // V_0 (m^3)
  double rest_area = 0;                  // m^2
  double size = 0;                       // bounding-box diagonal (m), a length scale
  NodeMat bulk;                          // N x 3 B_i^d (Pa); entries that are inf are 0 here
  FlagMat infinite;                      // N x 3: B_i^d = inf, handled as u_i^d = 0
  std::vector<int> infinite_nodes;       // the nodes with an infinite B_i^d on some axis, in order
  FlagMat held;                          // N x 3: fixed or infinite: always constrained
  double connectivity_modulus = 0;
  CapsuleForm capsule = CapsuleForm::membrane;
  bool membrane_capsule() const { return capsule != CapsuleForm::paper; }
  // Membrane capsules only (empty for the paper's): the tension T = B_ij V_0 / A_0 (N/m), the
  // fixed edge weights w_e = T c_e (N/m; c_e the cotangent weights, on `edges`), with the
  // bending term's pair weights added when D > 0, and their sums per node (the diagonal, N/m).
  double capsule_tension = 0;
  double bending_modulus = 0;            // D (N·m); with it, `edges` also holds the pairs two edges apart
  Vec capsule_weight;                    // membrane + bending, on `edges`
  // With bending: the unit cotangent weights c_e on `edges` (0 on the two-ring pairs; the
  // membrane's part of a weight is T c_e) and the rest surface's Laplacian (C X)_i (m), for the
  // corotational capsule (capsule_rotations.hpp). Else empty.
  Vec bending_cot_weight;
  NodeMat bending_rest_laplacian;
  Vec capsule_diagonal;
  std::vector<double> membrane_frames;   // per rest triangle: its basis and D^-1 (membrane_frames.hpp)
  Vec membrane_inverse_areas;            // per node: 1 / its rest triangles' area (membrane_frames.hpp)
  double axis_stiffness_floor = 0;
  double density = 0;
  Vec3 gravity = Vec3::Zero();
  bool use_gravity = false;
  bool volume_constraint = true;
  bool use_inertia = false;
  bool compute_stress = true;
  double damping = 0;
  double dt = 0;
  SolverSettings solver;
  StiffnessPattern pattern;              // fixed sparsity of every K^d
  NeighbourLists neighbours;             // its rows without the diagonal, with each entry's edge
};

// Builds the model; on a bad definition returns false and explains why in `error`.
bool build_tissue_model(const TissueDef& def, TissueModel& model, std::string& error);

}  // namespace vdm
