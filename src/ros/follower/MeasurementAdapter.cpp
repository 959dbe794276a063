#include "follower/MeasurementAdapter.hpp"

#include <utility>

#include "follower/OdometryInput.hpp"
#include "follower/PositionInput.hpp"

namespace projection_collision_avoidance {

std::unique_ptr<MeasurementAdapter> makeMeasurementAdapter(const std::string& node_name,
                                                           const FollowerNodeOptions& options,
                                                           int axes,
                                                           MeasurementAdapter::Sink sink) {
  switch (options.input) {
    case MeasurementInput::kOdometry:
      return std::make_unique<OdometryInput>(node_name, options, axes, std::move(sink));
    case MeasurementInput::kPosition:
    case MeasurementInput::kTf:
      return std::make_unique<PositionInput>(node_name, options, axes, std::move(sink));
    case MeasurementInput::kRelativeMeasurement:
    default:
      return nullptr;
  }
}

}  // namespace projection_collision_avoidance
