#include "dockcore/task/command_queue.hpp"

namespace dockcore {

SubmitResult CommandQueue::submit(const QueuedCommand& c, QueuedCommand* replaced) {
  if (size_ < kCapacity) {
    items_[(head_ + size_) % kCapacity] = c;
    ++size_;
    return SubmitResult::kQueued;
  }
  ++overflows_;
  if (c.command.type != HostCommandType::kCancel) return SubmitResult::kFull;
  QueuedCommand& newest = items_[(head_ + size_ - 1) % kCapacity];
  if (replaced != nullptr) *replaced = newest;
  newest = c;
  return SubmitResult::kReplacedNewest;
}

void CommandQueue::pop() {
  head_ = (head_ + 1) % kCapacity;
  --size_;
}

}  // namespace dockcore
