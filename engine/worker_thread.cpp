#include "engine/worker_thread.hpp"

#include <pthread.h>
#include <signal.h>

namespace vdm {

WorkerThread::WorkerThread() {
  // The helper takes no signals (SIGINT/SIGTERM stay with the threads that handle them).
  sigset_t all, old;
  sigfillset(&all);
  pthread_sigmask(SIG_SETMASK, &all, &old);
  thread_ = std::thread([this] { loop(); });
  pthread_sigmask(SIG_SETMASK, &old, nullptr);
  pthread_setname_np(thread_.native_handle(), "vdm-solver");
}

WorkerThread::~WorkerThread() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

void WorkerThread::run(void (*job)(void*), void* context) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    job_ = job;
    context_ = context;
    pending_ = true;
  }
  wake_.notify_one();
}

void WorkerThread::wait() {
  std::unique_lock<std::mutex> lock(mutex_);
  done_.wait(lock, [this] { return !pending_; });
}

void WorkerThread::loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return pending_ || stop_; });
    if (stop_) return;
    void (*job)(void*) = job_;
    void* context = context_;
    lock.unlock();
    job(context);
    lock.lock();
    pending_ = false;
    done_.notify_one();
  }
}

}  // namespace vdm
