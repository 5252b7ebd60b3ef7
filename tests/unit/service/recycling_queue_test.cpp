// The recycling FIFO under the pipeline's frame queue and the session's answers.
#include "recycling_queue.hpp"

#include <gtest/gtest.h>

#include <deque>
#include <string>

#include "response_queue.hpp"

namespace nidevo::server {
namespace {

TEST(RecyclingQueue, KeepsFifoOrderThroughWrapAroundAndGrowth) {
  RecyclingQueue<int> q(2);
  std::deque<int> expected;
  int next = 0;
  for (int round = 0; round < 50; ++round) {  // a mix of pushes and pops, sizes 0 to 9
    const int pushes = round % 4, pops = (round + 1) % 3;
    for (int i = 0; i < pushes; ++i) {
      q.pushBack() = next;
      expected.push_back(next++);
    }
    for (int i = 0; i < pops && !expected.empty(); ++i) {
      ASSERT_EQ(q.front(), expected.front()) << "round " << round;
      q.popFront();
      expected.pop_front();
    }
    ASSERT_EQ(q.size(), expected.size());
    if (!expected.empty()) {
      ASSERT_EQ(q.back(), expected.back());
    }
  }
}

TEST(RecyclingQueue, APoppedElementComesBackWithWhatItHeld) {
  RecyclingQueue<std::string> q(1);
  q.pushBack().assign(1000, 'x');
  const char* buffer = q.front().data();
  q.popFront();
  std::string& again = q.pushBack();
  EXPECT_EQ(again.size(), 1000u);  // the caller overwrites it; its buffer is the same
  EXPECT_EQ(again.data(), buffer);
}

TEST(RecyclingQueue, APushTakesTheElementPoppedLast) {
  RecyclingQueue<std::string> q(4);
  for (int frame = 0; frame < 20; ++frame) {  // at most two queued at once, 20 times round
    for (int i = 0; i < 2; ++i) {
      std::string& entry = q.pushBack();
      if (entry.empty()) entry.assign(1000, 'x');  // a new buffer, as a parse into it would be
    }
    q.popFront();
    q.popFront();
  }
  // A ring would have filled all four; the last-popped-first order filled two.
  int holding = 0;
  for (int i = 0; i < 4; ++i) holding += q.pushBack().empty() ? 0 : 1;
  EXPECT_EQ(holding, 2);
}

TEST(RecyclingQueue, ElementsABurstFilledGiveTheirBuffersBackWhenIdle) {
  RecyclingQueue<std::string> q(4);
  auto push = [&] {
    std::string& entry = q.pushBack();
    if (entry.empty()) entry.assign(1000, 'x');
  };
  auto release = [](std::string& s) { std::string().swap(s); };
  for (int i = 0; i < 4; ++i) push();  // a burst: all four hold a buffer
  for (int i = 0; i < 4; ++i) q.popFront();
  for (int frame = 0; frame < 10; ++frame) {  // then one at a time
    push();
    q.popFront();
    q.releaseIdle(20, release);
  }
  int holding = 0;
  for (int i = 0; i < 4; ++i) holding += q.pushBack().empty() ? 0 : 1;
  EXPECT_EQ(holding, 4) << "not idle for 20 pushes yet";
  for (int i = 0; i < 4; ++i) q.popFront();
  for (int frame = 0; frame < 30; ++frame) {
    push();
    q.popFront();
    q.releaseIdle(20, release);
  }
  holding = 0;
  for (int i = 0; i < 4; ++i) holding += q.pushBack().empty() ? 0 : 1;
  EXPECT_EQ(holding, 1) << "the element in use keeps its buffer, the idle ones gave theirs back";
}

TEST(RecyclingQueue, ElementsStayPutWhileTheQueueGrows) {
  RecyclingQueue<int> q(1);
  int* first = &q.pushBack();
  *first = 7;
  for (int i = 0; i < 40; ++i) q.pushBack() = i;
  EXPECT_EQ(&q.front(), first);
  EXPECT_EQ(q.front(), 7);
}

TEST(ResponseQueue, TheFrontStaysPutWhilePushesGrowTheQueue) {
  ResponseQueue q;
  v1::TrackResponse r;
  r.set_sequence(0);
  q.push(&r);
  const v1::TrackResponse* writing = &q.front();
  for (uint64_t i = 1; i < 40; ++i) {  // past several doublings
    r.set_sequence(i);
    q.push(&r);
  }
  EXPECT_EQ(&q.front(), writing);
  EXPECT_EQ(q.front().sequence(), 0u);
  q.keepFront();
  EXPECT_EQ(q.size(), 1u);
  q.popFront();
  EXPECT_TRUE(q.empty());
}

TEST(ResponseQueue, UsedMessagesComeBackWithTheirSubmessages) {
  ResponseQueue q;
  for (int i = 0; i < 8; ++i) {  // every entry of the ring written once, as a session does
    v1::TrackResponse answer;
    answer.mutable_pose()->set_tx(1.5);
    q.push(&answer);
    q.popFront();
  }
  v1::TrackResponse next;
  q.push(&next);
  EXPECT_TRUE(next.has_pose());        // the next answer fills it: no new Pose
  EXPECT_FALSE(q.front().has_pose());  // what was pushed: `next` as it was
}

}  // namespace
}  // namespace nidevo::server
