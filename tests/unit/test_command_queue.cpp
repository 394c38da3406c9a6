// core command queue: order, capacity, the full queue's refusal and a cancel that is never lost.
#include <cstdint>

#include "dockcore/task/command_queue.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;

namespace {

QueuedCommand cmd(HostCommandType type, std::uint32_t token) {
  QueuedCommand c;
  c.command = HostCommand{type, 0};
  c.token = token;
  return c;
}

}  // namespace

TEST_GROUP(CommandQueue){};

TEST(CommandQueue, OldestFirstAndAFullQueueRefusesAllButACancel) {
  CommandQueue q;
  CHECK(q.front() == nullptr);
  for (std::uint32_t i = 1; i <= CommandQueue::kCapacity; ++i) {
    CHECK(q.submit(cmd(HostCommandType::kDock, i)) == SubmitResult::kQueued);
  }
  LONGS_EQUAL(CommandQueue::kCapacity, q.size());
  CHECK(q.submit(cmd(HostCommandType::kUndock, 99)) == SubmitResult::kFull);
  LONGS_EQUAL(1, static_cast<long>(q.overflows()));
  // A cancel takes the newest entry's place; the caller learns which request it displaced.
  QueuedCommand displaced;
  CHECK(q.submit(cmd(HostCommandType::kCancel, 100), &displaced) == SubmitResult::kReplacedNewest);
  LONGS_EQUAL(CommandQueue::kCapacity, static_cast<long>(displaced.token));
  LONGS_EQUAL(2, static_cast<long>(q.overflows()));
  for (std::uint32_t i = 1; i < CommandQueue::kCapacity; ++i) {
    LONGS_EQUAL(i, static_cast<long>(q.front()->token));
    q.pop();
  }
  CHECK(q.front()->command.type == HostCommandType::kCancel);
  LONGS_EQUAL(100, static_cast<long>(q.front()->token));
  q.pop();
  CHECK(q.front() == nullptr);
  // The ring wraps: room again for a full queue.
  for (std::uint32_t i = 1; i <= CommandQueue::kCapacity; ++i) {
    CHECK(q.submit(cmd(HostCommandType::kTestMode, i)) == SubmitResult::kQueued);
  }
  LONGS_EQUAL(1, static_cast<long>(q.front()->token));
}
