#pragma once
// Contact's broad phase: which surface triangles may meet a tool. An FCL BVHModel (AABB) of
// the organ, walked against each tool's oriented bounding box (or, with
// ContactSettings::fcl_shape_queries, queried by FCL against the tool's FCL shape: capsule,
// cylinder, box, convex). The walk refits the tree lazily (ContactSettings::lazy_refit): a
// box is updated only where a node left its box by more than a slack, and the walk inflates
// the boxes by that slack, then keeps exactly the triangles that FCL's refit would give, in
// the same order. Once warmed up (the same number and kinds of tools), a query allocates
// nothing.
#include <memory>
#include <vector>

#include "engine/tissue_model.hpp"
#include "engine/tool_shape.hpp"
#include "engine/types.hpp"

namespace vdm {

struct ContactSettings;

class ContactBroadPhase {
 public:
  ContactBroadPhase(const TissueModel& model, const ContactSettings& settings);
  ~ContactBroadPhase();
  // Refits the organ's tree to positions x (nothing to do when they are those of the last refit).
  void refit(const NodeMat& x);
  // Appends to `found` what the triangles overlapping tool `slot` (inflated by `pad`, m) hold
  // and `seen` has not flagged yet, flagging it: with `triangles`, the triangles; without,
  // their corner nodes. (The caller clears the flags of what it reads.) Walks the tree as
  // last refitted.
  void query(const ToolShape& t, size_t slot, double pad, bool triangles, std::vector<char>& seen,
             std::vector<int>& found);
  // Boxes of the tree refitted so far.
  long box_updates() const;

 private:
  // The lazy refit: node boxes that x left by more than the slack are reset, their triangles'
  // leaves and those leaves' ancestors updated (all of them the first time).
  void refit_lazy(const NodeMat& x);
  bool lazy() const { return lazy_; }

  struct Fcl;
  std::unique_ptr<Fcl> fcl_;
  const TriMat* triangles_ = nullptr;
  bool lazy_ = true, fcl_shape_queries_ = false;
  bool refitted_ = false;
  std::vector<int> stack_;  // the tree walk's
};

}  // namespace vdm
