#include "klt_contour_tracker/core/worker_threads.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <future>
#include <stdexcept>
#include <string>

namespace kct {

/// One function, run once by whoever claims it first: a worker, or the thread that waits for it.
struct WorkerThreads::Job {
  explicit Job(std::function<void()> f) : fn(std::move(f)), done(finished.get_future()) {}
  void run() {
    if (claimed.exchange(true)) return;
    try {
      fn();
      finished.set_value();
    } catch (...) {
      finished.set_exception(std::current_exception());
    }
  }
  std::function<void()> fn;
  std::atomic<bool> claimed{false};
  std::promise<void> finished;
  std::future<void> done;
};

WorkerThreads::Pending& WorkerThreads::Pending::operator=(Pending&& other) noexcept {
  if (this != &other) {
    settle();
    job_ = std::move(other.job_);
  }
  return *this;
}

WorkerThreads::Pending::~Pending() { settle(); }

void WorkerThreads::Pending::settle() noexcept {
  if (!job_) return;
  const std::shared_ptr<Job> job = std::move(job_);
  if (!job->claimed.exchange(true)) return;  // not begun: cancelled
  job->done.wait();
}

void WorkerThreads::Pending::wait() {
  if (!job_) return;
  const std::shared_ptr<Job> job = std::move(job_);
  job->run();
  job->done.get();
}

WorkerThreads::WorkerThreads(int threads) {
  if (threads < 1)
    throw std::invalid_argument("WorkerThreads: threads must be >= 1, got " +
                                std::to_string(threads));
  workers_.reserve(static_cast<std::size_t>(threads - 1));
  for (int t = 1; t < threads; ++t) workers_.emplace_back([this]() { work(); });
}

WorkerThreads::~WorkerThreads() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (auto& worker : workers_) worker.join();
}

void WorkerThreads::post(std::shared_ptr<Job> job) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.push_back(std::move(job));
  }
  wake_.notify_one();
}

void WorkerThreads::work() {
  for (;;) {
    std::shared_ptr<Job> job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this]() { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping
      job = std::move(queue_.front());
      queue_.pop_front();
    }
    job->run();
  }
}

void WorkerThreads::parallel_for(int n, const std::function<void(int)>& fn) {
  const int helpers = std::min(static_cast<int>(workers_.size()), n - 1);
  if (helpers <= 0) {
    for (int i = 0; i < n; ++i) fn(i);
    return;
  }
  // Every participant takes the next index until none is left; a helper that starts late (or
  // is claimed by the wait below) finds none and returns at once, so the caller never waits
  // for work that has not begun.
  std::atomic<int> next{0};
  auto body = [&next, n, &fn]() {
    for (int i = next++; i < n; i = next++) fn(i);
  };
  std::vector<Pending> pending;
  pending.reserve(static_cast<std::size_t>(helpers));
  for (int h = 0; h < helpers; ++h) {
    auto job = std::make_shared<Job>(body);
    post(job);
    pending.push_back(Pending(std::move(job)));
  }
  std::exception_ptr error;
  try {
    body();
  } catch (...) {
    error = std::current_exception();
  }
  for (Pending& p : pending) {
    try {
      p.wait();
    } catch (...) {
      if (!error) error = std::current_exception();
    }
  }
  if (error) std::rethrow_exception(error);
}

WorkerThreads::Pending WorkerThreads::start(std::function<void()> fn) {
  auto job = std::make_shared<Job>(std::move(fn));
  if (!workers_.empty()) post(job);
  return Pending(std::move(job));
}

}  // namespace kct
