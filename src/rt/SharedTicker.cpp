#include "projection_collision_avoidance/rt/SharedTicker.hpp"

#include <algorithm>
#include <map>
#include <mutex>
#include <stdexcept>
#include <utility>
#include <vector>

namespace projection_collision_avoidance {

/// The members of one period and the thread that calls them.
class SharedTickerGroup {
 public:
  void add(std::uint64_t id, SharedTicker::Callback callback) {
    const std::lock_guard<std::mutex> lock(mutex_);
    members_.emplace_back(id, std::move(callback));
  }
  void remove(std::uint64_t id) {
    const std::lock_guard<std::mutex> lock(mutex_);  // after a running round
    members_.erase(std::remove_if(members_.begin(), members_.end(),
                                  [id](const auto& member) { return member.first == id; }),
                   members_.end());
  }
  std::size_t size() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return members_.size();
  }
  void start(std::chrono::nanoseconds period, const std::string& name) {
    // On the grid k * period (phase 0): another thread of the process can keep clear of it.
    thread_.start(
        period, 0, [this](const PeriodicTick& tick) { round(tick); }, name,
        std::chrono::nanoseconds(0));
  }
  std::uint64_t missed() const { return thread_.missedPeriods(); }

 private:
  void round(const PeriodicTick& tick) {
    const std::lock_guard<std::mutex> lock(mutex_);
    PeriodicTick own = tick;
    for (const auto& member : members_) {
      own.actual = std::max(tick.actual, monotonicNanoseconds());
      member.second(own);
    }
  }

  std::mutex mutex_;  ///< members_: a round against joining and leaving
  std::vector<std::pair<std::uint64_t, SharedTicker::Callback>> members_;
  PeriodicThread thread_;  ///< destroyed first: no round after
};

namespace {

/// The groups by period (ns); a group lives as long as a member holds it.
struct Registry {
  std::mutex mutex;
  std::map<std::int64_t, std::weak_ptr<SharedTickerGroup>> groups;
  std::uint64_t next_id = 1;
};

Registry& registry() {
  static Registry instance;
  return instance;
}

}  // namespace

SharedTicker::SharedTicker(std::chrono::nanoseconds period, const std::string& thread_name,
                           Callback callback) {
  if (period.count() <= 0) {
    throw std::invalid_argument("SharedTicker: the period must be positive, got " +
                                std::to_string(period.count()) + " ns");
  }
  if (!callback) {
    throw std::invalid_argument("SharedTicker: no callback");
  }
  Registry& shared = registry();
  const std::lock_guard<std::mutex> lock(shared.mutex);
  id_ = shared.next_id++;
  group_ = shared.groups[period.count()].lock();
  if (group_) {
    group_->add(id_, std::move(callback));
    return;
  }
  group_ = std::make_shared<SharedTickerGroup>();
  group_->add(id_, std::move(callback));
  group_->start(period, thread_name);
  shared.groups[period.count()] = group_;
}

SharedTicker::~SharedTicker() {
  group_->remove(id_);
  const std::lock_guard<std::mutex> lock(registry().mutex);
  group_.reset();  // the last member's: the group's thread stops here
}

std::uint64_t SharedTicker::missedPeriods() const { return group_->missed(); }

std::size_t SharedTicker::groupSize() const { return group_->size(); }

}  // namespace projection_collision_avoidance
