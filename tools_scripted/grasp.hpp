#pragma once
// Grasping: when a grasper's jaws close, the surface nodes between them (within
// `grasp_width` of the closed jaw segment, from the pivot to the tip) attach to the jaw frame
// and follow it as prescribed motion; opening the jaws releases them.
#include <string>
#include <string_view>
#include <vector>

#include "engine/sim_state.hpp"
#include "tools_scripted/instrument.hpp"

namespace tools {

class Grasp {
 public:
  // Updates the grasp for the grasper at `pose`: on closing, selects nodes from the current
  // positions `x`; on opening, releases them. Returns true when the held set changed.
  bool update(const InstrumentDef& def, const InstrumentPose& pose, const vdm::NodeMat& x);
  // Adds the held nodes' positions (following the jaw frame) to `input` as prescribed motion.
  void apply(const InstrumentPose& pose, const vdm::NodeMat& rest, vdm::StepInput& input) const;
  const std::vector<int>& held() const { return held_; }
  // The grasp's state (held nodes, their jaw-frame positions, closed) for state snapshots:
  // appended to `out` / read from `in` at `pos` (false when it does not fit `nodes`).
  void save(std::string& out) const;
  bool load(std::string_view in, size_t& pos, int nodes);

 private:
  std::vector<int> held_;
  std::vector<vdm::Vec3> local_;  // held nodes in the jaw frame at the moment of grasping
  bool closed_ = false;
};

// The jaw frame: origin at the tip, z along the axis (rotation from the world).
Eigen::Isometry3d jaw_frame(const InstrumentPose& pose);

}  // namespace tools
