#pragma once
// One helper thread that runs a job handed to it while the caller does its own share, then
// joins: the structured solver's two groups of axes (solver_structured.cpp). Started once;
// run() and wait() allocate nothing. The caller must wait() before handing the next job.
#include <condition_variable>
#include <mutex>
#include <thread>

namespace vdm {

class WorkerThread {
 public:
  WorkerThread();
  ~WorkerThread();
  WorkerThread(const WorkerThread&) = delete;
  WorkerThread& operator=(const WorkerThread&) = delete;

  // Starts job(context) on the helper thread.
  void run(void (*job)(void*), void* context);
  // Returns once the job given to run() has finished.
  void wait();

 private:
  void loop();
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  void (*job_)(void*) = nullptr;
  void* context_ = nullptr;
  bool pending_ = false, stop_ = false;
  std::thread thread_;
};

}  // namespace vdm
