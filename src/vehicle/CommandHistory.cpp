#include "projection_collision_avoidance/vehicle/CommandHistory.hpp"

#include <cmath>
#include <string>

#include "projection_collision_avoidance/core/ParameterError.hpp"

namespace projection_collision_avoidance {

CommandHistory::CommandHistory(std::size_t capacity, int axes) : axes_(axes) {
  if (capacity < 1) {
    throw ParameterError("vehicle.velocity.history", "must keep at least one command");
  }
  if (axes < 1 || axes > 3) {
    throw ParameterError("vehicle.velocity.axes", "must be 1, 2 or 3, got " + std::to_string(axes));
  }
  SentCommand empty;
  empty.velocity = AxisVector::Zero(axes);
  empty.increment = AxisVector::Zero(axes);
  ring_.assign(capacity, empty);
}

void CommandHistory::push(double time, const AxisVector& velocity, const AxisVector& increment) {
  if (!std::isfinite(time) || velocity.size() != axes_ || increment.size() != axes_ ||
      !velocity.allFinite() || !increment.allFinite()) {
    return;
  }
  if (size_ > 0 && time < at(size_ - 1).time) {
    clear();
  }
  std::size_t slot = (head_ + size_) % ring_.size();
  if (size_ == ring_.size()) {  // full: the newest takes the oldest's place
    slot = head_;
    head_ = (head_ + 1) % ring_.size();
  } else {
    ++size_;
  }
  ring_[slot].time = time;
  ring_[slot].velocity = velocity;
  ring_[slot].increment = increment;
}

void CommandHistory::replaceNewest(const AxisVector& velocity, double scale) {
  if (size_ == 0 || velocity.size() != axes_ || !velocity.allFinite() || !std::isfinite(scale)) {
    return;
  }
  SentCommand& newest = ring_[(head_ + size_ - 1) % ring_.size()];
  newest.increment += (velocity - newest.velocity) * scale;
  newest.velocity = velocity;
}

bool CommandHistory::commandBefore(double time, AxisVector* velocity) const {
  for (std::size_t i = size_; i-- > 0;) {
    if (at(i).time < time) {
      *velocity = at(i).velocity;
      return true;
    }
  }
  return false;
}

AxisVector CommandHistory::incrementBetween(double from, double before) const {
  AxisVector sum = AxisVector::Zero(axes_);
  for (std::size_t i = size_; i-- > 0;) {
    const SentCommand& command = at(i);
    if (command.time < from) {
      break;  // times are non-decreasing: every older one is earlier still
    }
    if (command.time < before) {
      sum += command.increment;
    }
  }
  return sum;
}

void CommandHistory::clear() {
  head_ = 0;
  size_ = 0;
}

}  // namespace projection_collision_avoidance
