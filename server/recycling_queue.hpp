#pragma once
// A FIFO whose elements outlive their turn: popping keeps the element in the ring, and the next
// push hands it out again, so the buffers it owns (a frame's image bytes) are reused instead of
// freed and allocated for every frame. It grows, by doubling, only past its largest size so far.
#include <cstddef>
#include <utility>
#include <vector>

namespace nidevo::server {

template <typename T>
class RecyclingQueue {
 public:
  explicit RecyclingQueue(size_t initial_capacity = 4)
      : ring_(initial_capacity ? initial_capacity : 1) {}

  bool empty() const { return size_ == 0; }
  size_t size() const { return size_; }
  T& front() { return ring_[head_]; }
  const T& front() const { return ring_[head_]; }
  T& back() { return ring_[(head_ + size_ - 1) % ring_.size()]; }

  // Appends an element and returns it: a recycled one, holding whatever it held last time (the
  // caller overwrites or swaps in what it needs).
  T& pushBack() {
    if (size_ == ring_.size()) grow();
    ++size_;
    return back();
  }
  void popFront() {
    head_ = (head_ + 1) % ring_.size();
    --size_;
  }
  void popBack() { --size_; }
  void clear() { size_ = 0; }

 private:
  void grow() {
    std::vector<T> bigger(2 * ring_.size());
    for (size_t i = 0; i < ring_.size(); ++i)
      std::swap(bigger[i], ring_[(head_ + i) % ring_.size()]);
    ring_.swap(bigger);
    head_ = 0;
  }

  std::vector<T> ring_;
  size_t head_ = 0;
  size_t size_ = 0;
};

}  // namespace nidevo::server
