#pragma once
/// \file worker_threads.h
/// A fixed set of threads that live as long as their owner, for the per-frame parallel work:
/// the Tracker's image preparation alongside KLT and ContourCost's pyramid levels.
///
/// Why not a thread per call (std::async, std::thread): OpenCV 4.6 keeps about 0.8 kB of
/// per-thread data (its trace TLS, held for terminated threads too) for every thread that ever
/// called it, until the process ends: a thread per frame grew the nodelet by ~0.5 kB a frame
/// (15 MB over a 30,000-frame soak). Why hand-written: std::async starts a thread per call,
/// cv::parallel_for_ has one process-wide thread count and runs nested calls serially, and the
/// core links no other threading library.

#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace kct {

class WorkerThreads {
  struct Job;

 public:
  /// A function given to start(). wait() returns when it has run (it runs it on the calling
  /// thread when no worker has begun it yet, so waiting never deadlocks) and rethrows its
  /// exception. Destroyed without wait(), it cancels the function if it has not begun and
  /// otherwise waits for it (as std::async's future does), so that nothing it uses goes away
  /// under it. A default-constructed Pending is not valid(); wait() then does nothing.
  class Pending {
   public:
    Pending() = default;
    Pending(Pending&& other) noexcept = default;
    Pending& operator=(Pending&& other) noexcept;
    ~Pending();
    bool valid() const { return job_ != nullptr; }
    void wait();

   private:
    friend class WorkerThreads;
    explicit Pending(std::shared_ptr<Job> job) : job_(std::move(job)) {}
    void settle() noexcept;  ///< what the destructor does
    std::shared_ptr<Job> job_;
  };

  /// `threads` (>= 1) threads in all, the caller's included: threads - 1 workers start now and
  /// are joined by the destructor. Throws std::invalid_argument for threads < 1.
  explicit WorkerThreads(int threads);
  ~WorkerThreads();
  WorkerThreads(const WorkerThreads&) = delete;
  WorkerThreads& operator=(const WorkerThreads&) = delete;

  /// Threads in all, the caller's included.
  int threads() const { return static_cast<int>(workers_.size()) + 1; }

  /// Runs fn(i) once for every i in [0, n) on the caller and the workers and returns when all
  /// are done; each i must write only its own outputs (the split of i over threads varies).
  /// The first exception thrown is rethrown after every call has returned. May be called from
  /// one of this object's own tasks.
  void parallel_for(int n, const std::function<void(int)>& fn);

  /// Starts fn on a worker (with no worker, it runs when waited for) and returns its handle.
  Pending start(std::function<void()> fn);

 private:
  void post(std::shared_ptr<Job> job);
  void work();

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::shared_ptr<Job>> queue_;
  bool stopping_ = false;
};

}  // namespace kct
