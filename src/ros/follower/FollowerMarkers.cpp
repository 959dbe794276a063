#include <algorithm>
#include <iomanip>
#include <sstream>

#include <visualization_msgs/MarkerArray.h>

#include "projection_collision_avoidance/ros/InputAdmission.hpp"
#include "projection_collision_avoidance/ros/MessageConversions.hpp"

#include "follower/FollowerOutputs.hpp"

namespace projection_collision_avoidance {
namespace {

/// A neighbour's perimeter by what its half-space did: blue sensed, yellow kept, orange binding
/// (it acts on the command), magenta dropped (it could not be met).
MarkerColor roleColor(NeighbourRole role) {
  switch (role) {
    case NeighbourRole::kSensed:
      return {0.3F, 0.5F, 1.0F, 0.2F};
    case NeighbourRole::kKept:
      return {0.9F, 0.9F, 0.2F, 0.3F};
    case NeighbourRole::kBinding:
      return {1.0F, 0.45F, 0.0F, 0.55F};
    case NeighbourRole::kDropped:
      return {0.9F, 0.1F, 0.9F, 0.55F};
  }
  return {1.0F, 1.0F, 1.0F, 0.2F};
}

}  // namespace

void FollowerOutputs::publishMarkers(const FollowerCycleOutput& out) {
  using visualization_msgs::Marker;
  const DynamicFollowerStatus& s = out.status;
  std::string frame = options_.follower_frame;
  // The controlled point: the follower frame's origin, or where the input says it is (the
  // look-ahead point of ~input odometry, in the world frame).
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  if (marker_origin_ && !marker_origin_(&frame, &centre)) {
    return;
  }
  const ros::Time now = rosTimeOf(out.stamp_ns);
  const Eigen::Index axes = separation_.size() / 2;
  const GenericDimensions::StateVector& xi = out.xi;
  const bool inside_perimeter = out.distance < out.perimeter;
  visualization_msgs::MarkerArray markers;
  // Safety perimeter alpha ||d|| around it: green, red once the target is inside.
  // A flat disc on the ground plane (a sphere in 3-D), so the markers above it stay visible.
  visualization_msgs::Marker perimeter =
      toMarker(frame, now, "perimeter", member_.index, Marker::SPHERE, centre, 2.0 * out.perimeter,
               {inside_perimeter ? 1.0F : 0.1F, inside_perimeter ? 0.1F : 0.8F, 0.1F, 0.35F});
  if (axes < 3) {
    perimeter.type = Marker::CYLINDER;
    perimeter.scale.z = 0.02;
  }
  markers.markers.push_back(perimeter);
  // The slot x_1 - d, relative to the follower: (p_1 - p_2) - d_p.
  const Eigen::VectorXd slot = xi.head(axes);
  visualization_msgs::Marker slot_marker =
      toMarker(frame, now, "slot", member_.index, Marker::CUBE, centre + toVector3(slot), 0.3,
               {0.8F, 0.8F, 0.8F, 0.9F});
  markers.markers.push_back(slot_marker);
  // The follower where the CF estimate puts it: p_2 + (xi - xi_hat)_p. Grey in the fallback,
  // where xi is the last measured one and xi_hat a prediction.
  const bool fallback = out.mode == FollowerMode::kMeasurementLost;
  const Eigen::VectorXd ghost = (xi - s.estimate).head(axes);
  const MarkerColor ghost_color =
      fallback ? MarkerColor{0.5F, 0.5F, 0.5F, 0.45F} : MarkerColor{1.0F, 0.55F, 0.0F, 0.45F};
  markers.markers.push_back(toMarker(frame, now, "cf_estimate", member_.index, Marker::SPHERE,
                                     centre + toVector3(ghost), 0.5, ghost_color));
  // ||xi|| against xi_max, as text above the follower; the mode unless tracking.
  const float shade = xi.norm() > out.xi_max || fallback ? 0.2F : 1.0F;  // red: trouble
  visualization_msgs::Marker text =
      toMarker(frame, now, "bound", member_.index, Marker::TEXT_VIEW_FACING,
               centre + Eigen::Vector3d(0.0, 0.0, 1.2), 0.35, {1.0F, shade, shade, 1.0F});
  std::ostringstream label;
  label << std::fixed << std::setprecision(2) << "|xi| " << xi.norm() << " / xi_max " << out.xi_max
        << " m";
  const NeighbourReport& neighbours = out.neighbours;
  if (neighbours.configured && !neighbours.fresh) {
    label << "\nNEIGHBOURS STALE: braking";
  } else if (fallback) {
    label << "\nMEASUREMENT LOST: braking";
  } else if (out.mode == FollowerMode::kLeaderLost) {
    label << "\nleader broadcast lost";
  }
  if (neighbours.binding >= 0) {
    label << "\nkeeping out of " << neighbours.binding_id.data();
  }
  text.text = label.str();
  markers.markers.push_back(text);
  // Each sensed agent's perimeter, around it, coloured by what its half-space did (N3). They
  // last two marker periods: an agent no longer sensed disappears.
  const ros::Duration lifetime(2.0 / std::max(options_.marker_rate, 1e-3));
  for (int j = 0; neighbours.configured && j < neighbours.count; ++j) {
    const NeighbourMark& mark = neighbours.marks[static_cast<std::size_t>(j)];
    visualization_msgs::Marker ring = toMarker(
        frame, now, "neighbours", member_.index * NeighbourSample::kCapacity + j, Marker::SPHERE,
        centre + mark.position, 2.0 * mark.perimeter, roleColor(mark.role));
    if (axes < 3) {
      ring.type = Marker::CYLINDER;
      ring.scale.z = 0.01;
    }
    ring.lifetime = lifetime;
    markers.markers.push_back(ring);
  }
  marker_publisher_.publish(markers);
}

}  // namespace projection_collision_avoidance
