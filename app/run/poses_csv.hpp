#pragma once
// DIR/poses.csv, written with the ground-truth views: one row per frame and object, the camera
// first and then instruments[i] in order:
//   frame,object,px,py,pz,r00,r01,r02,r10,r11,r12,r20,r21,r22,jaw_deg
// p is the camera's optical centre or the instrument's tip (m); R (row-major, r<row><column>)
// turns the object's axes into the world's: the camera's columns are its x (right), y (down)
// and z (forward, the optical axis); an instrument's z runs along its shaft from the handle
// toward the tip. jaw_deg: a grasper's jaws' angle, each from the closed position (0 for the
// camera and probes). Each frame's rows are on disk before the frame counts as done; a resumed
// run keeps the rows of the frames before it; a failed write is cut back to the last whole
// frame.
#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace vdmsim {

struct ObjectPose {
  std::string object;  // "camera", "instruments[0]", ...
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // world from object
  double jaw_deg = 0;
};

class PosesCsv {
 public:
  // Writes the header; resuming at frame `start` > 0, keeps the earlier run's rows of the frames
  // before it (`objects` rows each) and drops the rest. -1 when the file is ready, otherwise the
  // exit code (2: the earlier file is damaged, 1: it cannot be written), with `error`.
  int open(const std::filesystem::path& dir, int start, int objects, std::string& error);
  // Frame f's rows. False when they could not be written, with `error`; the file is then cut
  // back to its last whole frame and closed.
  bool write(int f, const std::vector<ObjectPose>& poses, std::string& error);
  void flush();
  // Keeps the rows of the frames before `frames` (the frames whose images all reached the disk
  // after an image write failure).
  void keep_frames(int frames);
  bool is_open() const { return file_.is_open(); }

 private:
  std::filesystem::path path_;
  std::ofstream file_;
  int start_ = 0;
  std::uintmax_t good_size_ = 0;           // the file's size after its last whole frame
  std::uintmax_t base_size_ = 0;           // its size before this run's first frame
  std::vector<std::uintmax_t> frame_end_;  // its size after each frame of this run
};

}  // namespace vdmsim
