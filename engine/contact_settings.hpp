#pragma once
// How contact is computed (engine/contact.hpp's ContactSolver): the method, its tolerances and
// iteration caps. Plain data in a header of its own, so that a scene's definition and the broad
// phase need not include the contact solver.

namespace vdm {

struct ContactSettings {
  double activation = 1e-4;   // a node within this fraction of the tool's size of the surface counts as touching
  double tolerance = 0.02;    // after the step, penetration must be below this fraction of the tool's size
  int max_active_set_iterations = 8;
  // Broad phase: false (default) walks the organ's FCL BVH against each tool's oriented
  // bounding box (no allocation); true asks FCL for the triangles overlapping the tool's FCL
  // shape (capsule, cylinder, box, convex: tighter, but FCL's GJK allocates per triangle
  // pair). The narrow phase is exact either way, so both give the same contacts.
  bool fcl_shape_queries = false;
  // The tree walk's refit (without fcl_shape_queries). true (default): lazy, only the boxes of
  // nodes that moved more than `refit_slack` (a fraction of the mean edge length of the rest
  // surface) since their box was last set are updated, and the walk inflates every box by the
  // slack; the triangles kept are exactly those whose boxes FCL's refit would give (the
  // corners at this and the previous refit's positions: tested one by one), in the same
  // order, so the contacts and results are the same bit for bit as with false: FCL refits
  // the whole tree at every query whose positions changed (the behaviour before; slower).
  // The slack trades box updates against a wider walk (measured flat from 0.2 to 1 edge).
  bool lazy_refit = true;
  double refit_slack = 0.5;
  // constraint: non-penetration as unilateral constraints along the tool's normal at surface
  // contact points, with Coulomb friction (engine/contact_constraint.cpp); kinematic: nodes
  // held on the tool (sticking); penalty: frictionless springs. The reference models (fem,
  // mass_spring) take kinematic and constraint contact; penalty contact needs vdm.
  enum class Method { constraint, kinematic, penalty } method = Method::constraint;
  // constraint: the Coulomb friction coefficient (0: frictionless sliding). The default, 0.2,
  // is a moderate value for moist tissue on a smooth metal instrument.
  double friction = 0.2;
  // constraint: solves of the organ per step at most (a press of a sharp blade on the 10k liver
  // needed up to about 40; most steps take two to four).
  int max_constraint_iterations = 60;
  // constraint: the step's contact solve has converged when no contact point is off the tool's
  // surface (inside it, or apart from it while pushed) by more than this fraction of the
  // smallest tool's size, no sticking point slipped by more, and the forces the last
  // Gauss-Seidel pass found would move none by more.
  double constraint_tolerance = 0.005;
  // constraint: the solves that only move the forces toward the laws stop at a relative
  // residual of 5 % of constraint_tolerance (2.5e-4 at the default; when the model's tolerance
  // is tighter, and with a solver that takes it: VDM's structured solver); once the forces
  // meet the laws they are solved again to the model's tolerance and checked again. A step is
  // solved loosely only while each iteration brings it closer to the laws, and always ends on
  // a solve to the model's tolerance. false: every solve to the model's tolerance.
  bool loose_solves = true;
  // constraint: the rings of neighbours around the contact nodes on which their compliance
  // is computed (engine/contact_compliance.hpp).
  int compliance_rings = 6;
  double penalty_stiffness = 1e8;  // k_c: contact pressure per metre of penetration (Pa/m)
  int max_penalty_iterations = 40;
  // The penalty iteration ends when no node moved more than this fraction of the smallest
  // tool's size in the last solve.
  double penalty_tolerance = 1e-3;
  bool anderson = true;  // accelerate the penalty iteration (Anderson mixing of the last 5 solves)
};

}  // namespace vdm
