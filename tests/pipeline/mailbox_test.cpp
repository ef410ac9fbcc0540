// SPDX-License-Identifier: Apache-2.0
// Tests of the single-slot mailbox between pipeline threads.

#include "hrcsense/pipeline.hpp"

#include <gtest/gtest.h>

#include <thread>
#include <vector>

namespace hrcsense {
namespace {

TEST(Mailbox, PutNeverBlocksAndCountsDrops) {
  Mailbox<int> box;
  // A producer that nobody serves: if put() blocked on the full slot, join() would hang.
  std::thread producer([&] {
    for (int i = 1; i <= 100; ++i) {
      int value = i;
      box.put(value);
    }
  });
  producer.join();
  EXPECT_EQ(box.dropped(), 99);
  int out = 0;
  ASSERT_TRUE(box.take(out));
  EXPECT_EQ(out, 100);  // latest value wins
}

TEST(Mailbox, PutSwapsSoBuffersCirculate) {
  Mailbox<std::vector<int>> box;
  std::vector<int> a{1, 2, 3};
  box.put(a);
  EXPECT_TRUE(a.empty());  // got the slot's previous (empty) value back
  std::vector<int> out{9};
  ASSERT_TRUE(box.take(out));
  EXPECT_EQ(out, (std::vector<int>{1, 2, 3}));
}

TEST(Mailbox, TakeAndCloseSemantics) {
  Mailbox<int> box;
  int value = 7;
  box.put(value);
  box.close();
  EXPECT_FALSE(box.closed());  // closed but a value is still waiting
  int out = 0;
  EXPECT_TRUE(box.take(out));
  EXPECT_EQ(out, 7);
  EXPECT_TRUE(box.closed());
  EXPECT_FALSE(box.take(out));  // closed and empty: returns at once
  EXPECT_FALSE(box.take_for(out, 10.0));
}

TEST(Mailbox, TakeWaitsForAValueFromAnotherThread) {
  Mailbox<int> box;
  std::thread producer([&] {
    int value = 42;
    box.put(value);
  });
  int out = 0;
  EXPECT_TRUE(box.take(out));
  EXPECT_EQ(out, 42);
  producer.join();
}

TEST(Mailbox, CloseWakesAWaitingTaker) {
  Mailbox<int> box;
  std::thread closer([&] { box.close(); });
  int out = 0;
  EXPECT_FALSE(box.take(out));
  closer.join();
}

TEST(Mailbox, TakeForTimesOutWhenEmpty) {
  Mailbox<int> box;
  int out = 5;
  EXPECT_FALSE(box.take_for(out, 0.01));
  EXPECT_EQ(out, 5);
  EXPECT_FALSE(box.closed());
}

TEST(Mailbox, PutWaitDeliversEveryValueInOrder) {
  Mailbox<int> box;
  constexpr int kCount = 500;
  std::thread producer([&] {
    for (int i = 0; i < kCount; ++i) {
      int value = i;
      ASSERT_TRUE(box.put_wait(value));
    }
    box.close();
  });
  std::vector<int> received;
  int out = 0;
  while (box.take(out)) received.push_back(out);
  producer.join();
  ASSERT_EQ(received.size(), static_cast<size_t>(kCount));
  for (int i = 0; i < kCount; ++i) EXPECT_EQ(received[static_cast<size_t>(i)], i);
  EXPECT_EQ(box.dropped(), 0);
}

TEST(Mailbox, PutWaitGivesUpWhenClosed) {
  Mailbox<int> box;
  int first = 1;
  box.put(first);
  // The slot is full: this put_wait waits until close() releases it with false.
  std::thread producer([&] {
    int value = 2;
    EXPECT_FALSE(box.put_wait(value));
    EXPECT_EQ(value, 2);  // not stored
  });
  box.close();
  producer.join();
  int out = 0;
  EXPECT_TRUE(box.take(out));
  EXPECT_EQ(out, 1);
}

// A paced producer must learn that its consumer is gone (a failed sink ended the output), or
// it would go on reading the source into a mailbox nobody takes from.
TEST(Mailbox, PutFailsOnceClosed) {
  Mailbox<int> box;
  box.close();
  int value = 7;
  EXPECT_FALSE(box.put(value));
  EXPECT_EQ(value, 7);  // not stored
  EXPECT_EQ(box.dropped(), 0);
  int out = 0;
  EXPECT_FALSE(box.take(out));
}

}  // namespace
}  // namespace hrcsense
