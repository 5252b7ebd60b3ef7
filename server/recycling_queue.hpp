#pragma once
// A FIFO whose elements outlive their turn: popping keeps the element, and a later push hands it
// out again, so the buffers it owns (a frame's image bytes) are reused instead of freed and
// allocated for every frame. A push takes the element popped last: a queue that holds at most
// n elements at once only ever fills n of them, however many it has (a ring would fill them all
// in turn, and a session would keep a frame's 1.5 MB per entry it never needed at once).
#include <cstddef>
#include <cstdint>
#include <deque>
#include <vector>

namespace nidevo::server {

template <typename T>
class RecyclingQueue {
 public:
  explicit RecyclingQueue(size_t initial_capacity = 4) {
    const size_t n = initial_capacity ? initial_capacity : 1;
    for (size_t i = 0; i < n; ++i) addElement();
    order_.resize(n);
  }

  bool empty() const { return size_ == 0; }
  size_t size() const { return size_; }
  T& front() { return elements_[order_[head_]]; }
  const T& front() const { return elements_[order_[head_]]; }
  T& back() { return elements_[order_[(head_ + size_ - 1) % order_.size()]]; }

  // Appends an element and returns it: a recycled one, holding whatever it held last time (the
  // caller overwrites or swaps in what it needs). Its address stays until it is popped.
  T& pushBack() {
    if (size_ == order_.size()) grow();
    const size_t element = free_.back();
    free_.pop_back();
    order_[(head_ + size_) % order_.size()] = element;
    last_push_[element] = ++pushes_;
    ++size_;
    return back();
  }
  void popFront() {
    free_.push_back(order_[head_]);
    head_ = (head_ + 1) % order_.size();
    --size_;
  }
  void popBack() {
    free_.push_back(order_[(head_ + size_ - 1) % order_.size()]);
    --size_;
  }
  void clear() {
    while (size_ > 0) popBack();
  }
  // release(element) for every element not queued that has held something and was last pushed
  // more than `idle_pushes` pushes ago: what a burst filled and the steady state has not needed
  // since gives its buffers back, while the elements in use keep theirs.
  template <class Release>
  void releaseIdle(uint64_t idle_pushes, Release&& release) {
    for (size_t element : free_) {
      if (last_push_[element] != 0 && pushes_ - last_push_[element] > idle_pushes) {
        release(elements_[element]);
        last_push_[element] = 0;
      }
    }
  }

 private:
  void addElement() {
    free_.push_back(elements_.size());
    elements_.emplace_back();  // a deque: the other elements stay where they are
    last_push_.push_back(0);
  }
  void grow() {
    std::vector<size_t> bigger(2 * order_.size());
    for (size_t i = 0; i < size_; ++i) bigger[i] = order_[(head_ + i) % order_.size()];
    for (size_t i = order_.size(); i < bigger.size(); ++i) addElement();
    order_.swap(bigger);
    head_ = 0;
  }

  std::deque<T> elements_;
  std::vector<size_t> order_;        // indices into elements_, a ring from head_
  std::vector<size_t> free_;         // indices not queued, the last popped at the back
  std::vector<uint64_t> last_push_;  // per element: pushes_ when last pushed, 0: holds nothing
  uint64_t pushes_ = 0;
  size_t head_ = 0;
  size_t size_ = 0;
};

}  // namespace nidevo::server
