#include "nidevo/odometry/pipeline.hpp"

#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>

namespace nidevo {

namespace {

// A small blocking queue: closing wakes every waiter; pop returns nullptr once closed and empty.
class StateQueue {
 public:
  void push(FrameState* s) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      items_.push_back(s);
    }
    cv_.notify_one();
  }
  FrameState* pop() {
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait(lock, [&] { return !items_.empty() || closed_; });
    if (items_.empty()) return nullptr;
    FrameState* s = items_.front();
    items_.pop_front();
    return s;
  }
  void close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    cv_.notify_all();
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<FrameState*> items_;
  bool closed_ = false;
};

}  // namespace

std::vector<PoseEstimate> runSequential(Odometry& odometry, size_t frames,
                                        const FrameSource& source) {
  std::vector<PoseEstimate> poses;
  poses.reserve(frames);
  for (size_t i = 0; i < frames; ++i) poses.push_back(odometry.track(source(i)));
  return poses;
}

std::vector<PoseEstimate> runPipelined(Odometry& odometry, size_t frames,
                                       const FrameSource& source) {
  constexpr size_t kInFlight = 4;
  std::vector<FrameState> states(kInFlight);
  StateQueue free_states, to_rotation, to_translation;
  for (auto& s : states) free_states.push(&s);
  std::vector<PoseEstimate> poses;
  poses.reserve(frames);
  std::exception_ptr error;
  std::mutex error_mutex;
  auto fail = [&](std::exception_ptr e) {
    std::lock_guard<std::mutex> lock(error_mutex);
    if (!error) error = e;
    free_states.close();
    to_rotation.close();
    to_translation.close();
  };

  std::thread normals([&] {
    try {
      for (size_t i = 0; i < frames; ++i) {
        FrameState* s = free_states.pop();
        if (!s) return;
        s->frame_index = i;
        odometry.computeNormals(source(i), s);
        to_rotation.push(s);
      }
      to_rotation.close();
    } catch (...) {
      fail(std::current_exception());
    }
  });
  std::thread rotation([&] {
    try {
      while (FrameState* s = to_rotation.pop()) {
        odometry.estimateRotation(s);
        to_translation.push(s);
      }
      to_translation.close();
    } catch (...) {
      fail(std::current_exception());
    }
  });
  try {
    while (FrameState* s = to_translation.pop()) {
      poses.push_back(odometry.estimateTranslation(s));
      free_states.push(s);
    }
  } catch (...) {
    fail(std::current_exception());
  }
  normals.join();
  rotation.join();
  if (error) std::rethrow_exception(error);
  return poses;
}

}  // namespace nidevo
