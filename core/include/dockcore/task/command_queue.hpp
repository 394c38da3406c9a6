#pragma once
/// @file CommandQueue: host commands waiting for the control tick (one reaches the task manager per tick), and the
/// watchdog resume policy: a dock or undock that stale input interrupted is issued again once the input has been
/// fresh for a while (docs/dockd.md, "Watchdogs"). Fixed capacity, no heap, O(1) per call.

#include <cstddef>
#include <cstdint>

#include "dockcore/task/task_manager.hpp"

namespace dockcore {

/// A host command and the host's reference to it (dockd: which request to answer).
struct QueuedCommand {
  HostCommand command{};
  std::uint32_t token = 0;  ///< The host's; handed back with the command when it is taken. 0 for a resume.
  bool resume = false;      ///< Issued by the resume policy, not by a host.
};

/// What submit() did.
enum class SubmitResult : std::uint8_t {
  kQueued = 0,
  kFull = 1,  ///< Queue full: refused (counted in overflows()).
  kReplacedNewest =
      2,  ///< Queue full and the command is a cancel: it replaced the newest entry (a stop is never lost).
};

/// What the resume policy did on a tick.
enum class ResumeEvent : std::uint8_t {
  kNone = 0,
  kResumed = 1,  ///< The interrupted command was issued again (TickOutput::command).
  kGivenUp = 2,  ///< max_resumes reached this task: the fault stays.
};

/// The queue and the resume policy's bookkeeping.
class CommandQueue {
 public:
  static constexpr std::size_t kCapacity = 8;

  /// Appends `c`; a cancel that finds the queue full replaces the newest entry (`replaced`, if given, receives it).
  /// O(1).
  SubmitResult submit(const QueuedCommand& c, QueuedCommand* replaced = nullptr);
  /// The oldest queued command, or nullptr. O(1).
  const QueuedCommand* front() const { return size_ > 0 ? &items_[head_] : nullptr; }
  /// Removes the oldest. Precondition: front() != nullptr. O(1).
  void pop();
  std::size_t size() const { return size_; }
  std::uint32_t overflows() const { return overflows_; }

 private:
  QueuedCommand items_[kCapacity] = {};
  std::size_t head_ = 0;
  std::size_t size_ = 0;
  std::uint32_t overflows_ = 0;
};

}  // namespace dockcore
