#include "render/image_queue.hpp"

#include <pthread.h>

#include "engine/stopwatch.hpp"

namespace render {

ImageQueue::ImageQueue(int compression_level, int capacity)
    : level_(compression_level), capacity_(static_cast<size_t>(capacity < 1 ? 1 : capacity)), worker_([this] { run(); }) {}

ImageQueue::~ImageQueue() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  worker_.join();
}

bool ImageQueue::push(Image image, std::string path) {
  ViewImage v;
  v.image = std::move(image);
  return push(std::move(v), std::move(path));
}

bool ImageQueue::push(ViewImage image, std::string path) {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [&] { return pending_.size() < capacity_ || !error_.empty(); });
  if (!error_.empty()) return false;
  pending_.emplace_back(std::move(image), std::move(path));
  changed_.notify_all();
  return true;
}

bool ImageQueue::finish() {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [&] { return (pending_.empty() && !busy_) || !error_.empty(); });
  return error_.empty();
}

std::string ImageQueue::error() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return error_;
}

long ImageQueue::written() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return written_;
}

double ImageQueue::encode_ms() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return encode_ms_;
}

void ImageQueue::run() {
  pthread_setname_np(pthread_self(), "vdmsim-images");  // for profilers (perf, top -H)
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    changed_.wait(lock, [&] { return !pending_.empty() || stop_; });
    if (pending_.empty()) return;  // stop requested and nothing left
    auto job = std::move(pending_.front());
    pending_.pop_front();
    busy_ = true;
    const bool failed_before = !error_.empty();
    lock.unlock();
    changed_.notify_all();
    std::string err;
    const auto t0 = vdm::Clock::now();
    const bool ok = failed_before || write_view_image(job.second, job.first, level_, err);
    const double ms = vdm::ms_since(t0);
    lock.lock();
    busy_ = false;
    encode_ms_ += ms;
    if (!ok && error_.empty()) error_ = err;
    if (ok && !failed_before) ++written_;
    if (!error_.empty()) pending_.clear();  // after a failure nothing more is written
    changed_.notify_all();
  }
}

}  // namespace render
