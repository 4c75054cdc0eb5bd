#include "tools_scripted/grasp.hpp"

#include <Eigen/Geometry>

#include <cstdint>
#include <cstring>

namespace tools {

Eigen::Isometry3d jaw_frame(const InstrumentPose& pose) { return instrument_frame(pose); }

bool Grasp::update(const InstrumentDef& def, const InstrumentPose& pose, const vdm::NodeMat& x) {
  if (pose.jaw_closed == closed_) return false;
  closed_ = pose.jaw_closed;
  held_.clear();
  local_.clear();
  if (!closed_) return true;  // opened: everything released
  // Closed: take the nodes near the jaw segment, pivot (tip - jaw_length axis) to tip.
  const vdm::Vec3 tip = pose.tip, pivot = pose.tip - def.jaw_length * pose.axis.normalized();
  const Eigen::Isometry3d inv = jaw_frame(pose).inverse();
  for (int i = 0; i < x.rows(); ++i) {
    const vdm::Vec3 p = x.row(i).transpose();
    const vdm::Vec3 d = tip - pivot;
    const double t = std::clamp((p - pivot).dot(d) / d.squaredNorm(), 0.0, 1.0);
    if ((p - (pivot + t * d)).norm() <= def.grasp_width) {
      held_.push_back(i);
      local_.push_back(inv * p);
    }
  }
  return true;
}

void Grasp::apply(const InstrumentPose& pose, const vdm::NodeMat& rest, vdm::StepInput& input) const {
  const Eigen::Isometry3d f = jaw_frame(pose);
  for (size_t k = 0; k < held_.size(); ++k) {
    const int i = held_[k];
    input.prescribed.row(i).setOnes();
    input.prescribed_u.row(i) = (f * local_[k] - rest.row(i).transpose()).transpose();
  }
}

void Grasp::save(std::string& out) const {
  auto put = [&out](const void* p, size_t n) { out.append(static_cast<const char*>(p), n); };
  const std::int64_t count = static_cast<std::int64_t>(held_.size()), closed = closed_;
  put(&closed, sizeof closed);
  put(&count, sizeof count);
  for (size_t k = 0; k < held_.size(); ++k) {
    const std::int64_t i = held_[k];
    put(&i, sizeof i);
    put(local_[k].data(), 3 * sizeof(double));
  }
}

bool Grasp::load(std::string_view in, size_t& pos, int nodes) {
  auto take = [&](void* p, size_t n) {
    if (in.size() - pos < n) return false;
    std::memcpy(p, in.data() + pos, n);
    pos += n;
    return true;
  };
  std::int64_t closed = 0, count = 0;
  if (!take(&closed, sizeof closed) || !take(&count, sizeof count) || count < 0 || count > nodes) return false;
  held_.assign(static_cast<size_t>(count), 0);
  local_.assign(static_cast<size_t>(count), vdm::Vec3::Zero());
  for (size_t k = 0; k < held_.size(); ++k) {
    std::int64_t i = 0;
    if (!take(&i, sizeof i) || i < 0 || i >= nodes || !take(local_[k].data(), 3 * sizeof(double))) return false;
    held_[k] = static_cast<int>(i);
  }
  closed_ = closed != 0;
  return true;
}

}  // namespace tools
