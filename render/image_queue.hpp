#pragma once
// Writes image files (the views' PNG and .npy files: render/view_image.hpp) on a worker
// thread so that encoding does not hold up the simulation. The queue is bounded: push() waits
// while `capacity` images are pending, so memory stays flat when encoding is slower than
// rendering. Files are written in push order.
#include <condition_variable>
#include <deque>
#include <mutex>
#include <string>
#include <thread>

#include "render/image.hpp"
#include "render/view_image.hpp"

namespace render {

class ImageQueue {
 public:
  ImageQueue(int compression_level, int capacity = 6);
  ~ImageQueue();  // finishes the pending writes
  ImageQueue(const ImageQueue&) = delete;
  ImageQueue& operator=(const ImageQueue&) = delete;

  // Queues `image` for `path`. Returns false (and queues nothing) once a write has failed;
  // error() then says which file and why.
  bool push(ViewImage image, std::string path);
  bool push(Image image, std::string path);  // an RGB PNG
  // Waits until every queued image is written. Returns false if any write failed.
  bool finish();
  std::string error() const;
  long written() const;
  double encode_ms() const;  // total time spent encoding and writing, on the worker

 private:
  void run();
  const int level_;
  const size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<std::pair<ViewImage, std::string>> pending_;
  bool busy_ = false, stop_ = false;
  std::string error_;
  long written_ = 0;
  double encode_ms_ = 0;
  std::thread worker_;
};

}  // namespace render
