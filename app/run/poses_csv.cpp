#include "app/run/poses_csv.hpp"

#include <cstdlib>
#include <iomanip>
#include <sstream>

#include "app/run/output_dir.hpp"

namespace vdmsim {

namespace fs = std::filesystem;

namespace {

const char* const kPosesHeader = "frame,object,px,py,pz,r00,r01,r02,r10,r11,r12,r20,r21,r22,jaw_deg\n";

// The earlier run's rows of the frames before `start`, checked to be `start` x `objects` rows
// with frames 0 to start - 1 in order.
bool kept_pose_rows(const fs::path& path, int start, int objects, std::string& kept, std::string& error) {
  std::ifstream old(path);
  std::string line;
  if (!std::getline(old, line) || line + '\n' != kPosesHeader) {
    error = path.string() + ": missing or not a poses file: cannot resume (run it afresh without --resume)";
    return false;
  }
  const long want = long(start) * objects;
  long rows = 0;
  while (rows < want && std::getline(old, line)) {
    if (std::atol(line.c_str()) != rows / objects) break;
    kept += line + '\n';
    ++rows;
  }
  if (rows < want) {
    error = path.string() + ": has " + std::to_string(rows) + " whole rows before frame " + std::to_string(start) +
            " where the checkpoint needs " + std::to_string(want) + ": cannot resume (run it afresh without --resume)";
    return false;
  }
  return true;
}

}  // namespace

int PosesCsv::open(const fs::path& dir, int start, int objects, std::string& error) {
  path_ = dir / "poses.csv";
  start_ = start;
  std::string body = kPosesHeader;
  if (start > 0 && !kept_pose_rows(path_, start, objects, body, error)) return 2;
  // The kept rows replace the file whole: an interruption now leaves it as it was.
  if (!write_file_atomically(path_, body, error)) return 1;
  file_.open(path_, std::ios::app);
  if (!file_) {
    error = path_.string() + ": cannot open for writing";
    return 1;
  }
  good_size_ = base_size_ = body.size();
  return -1;
}

bool PosesCsv::write(int f, const std::vector<ObjectPose>& poses, std::string& error) {
  std::ostringstream rows;
  rows << std::setprecision(9);
  for (const ObjectPose& o : poses) {
    const Eigen::Vector3d p = o.pose.translation();
    const Eigen::Matrix3d r = o.pose.linear();
    // (+ 0.0 writes a negative zero as 0)
    rows << f << ',' << o.object << ',' << p.x() + 0.0 << ',' << p.y() + 0.0 << ',' << p.z() + 0.0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) rows << ',' << r(i, j) + 0.0;
    rows << ',' << o.jaw_deg + 0.0 << '\n';
  }
  const std::string text = rows.str();
  file_ << text;
  file_.flush();
  if (!file_) {
    error = path_.string() + ": write failed at frame " + std::to_string(f) + " (disk full?)";
    file_.close();
    std::error_code ec;
    fs::resize_file(path_, good_size_, ec);
    return false;
  }
  good_size_ += text.size();
  frame_end_.push_back(good_size_);
  return true;
}

void PosesCsv::flush() {
  if (file_.is_open()) file_.flush();
}

void PosesCsv::keep_frames(int frames) {
  if (path_.empty()) return;
  if (file_.is_open()) file_.close();
  const int written = frames - start_;
  std::error_code ec;
  if (written <= 0) fs::resize_file(path_, base_size_, ec);
  else if (size_t(written) <= frame_end_.size()) fs::resize_file(path_, frame_end_[size_t(written - 1)], ec);
}

}  // namespace vdmsim
