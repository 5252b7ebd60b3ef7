#pragma once
// A session's answers waiting to be written, one write in flight. The messages are kept and
// reused: push() swaps an answer in and hands back a used message, whose submessages and strings
// the next answer fills again, so steady state allocates nothing per frame.
#include <cstddef>
#include <memory>

#include "nidevo/v1/odometry.pb.h"
#include "recycling_queue.hpp"

namespace nidevo::server {

class ResponseQueue {
 public:
  // Takes `response`'s contents; `response` is left holding an earlier answer's (stale) contents.
  void push(v1::TrackResponse* response) {
    std::unique_ptr<v1::TrackResponse>& slot = ring_.pushBack();
    if (!slot) slot = std::make_unique<v1::TrackResponse>();
    slot->Swap(response);
  }
  bool empty() const { return ring_.empty(); }
  size_t size() const { return ring_.size(); }
  // Stays at its address until popFront(), whatever is pushed meanwhile (the write in flight).
  v1::TrackResponse& front() { return *ring_.front(); }
  void popFront() { ring_.popFront(); }
  // Drops every answer but the first (being written).
  void keepFront() {
    while (ring_.size() > 1) ring_.popBack();
  }
  void clear() { ring_.clear(); }

 private:
  RecyclingQueue<std::unique_ptr<v1::TrackResponse>> ring_;
};

}  // namespace nidevo::server
