#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include <visualization_msgs/MarkerArray.h>

#include "projection_collision_avoidance/ros/InputAdmission.hpp"
#include "projection_collision_avoidance/ros/MessageConversions.hpp"

#include "follower/FollowerOutputs.hpp"

namespace projection_collision_avoidance {
namespace {

/// A neighbour's perimeter by what its half-space did: yellow kept, orange binding (it acts on the
/// command), magenta dropped (it could not be met); blue sensed (not drawn).
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
  // The perimeter of each agent whose half-space is given to the command, as a ring around it
  // coloured by what the half-space does (N3), and a line to the one that acts. Sensed agents
  // that constrain nothing are not drawn. Each lasts two marker periods: an agent that no longer
  // constrains disappears.
  const ros::Duration lifetime(2.0 / std::max(options_.marker_rate, 1e-3));
  for (int j = 0; neighbours.configured && j < neighbours.count; ++j) {
    const NeighbourMark& mark = neighbours.marks[static_cast<std::size_t>(j)];
    if (mark.role == NeighbourRole::kSensed) {
      continue;
    }
    const bool binding = mark.role == NeighbourRole::kBinding;
    visualization_msgs::Marker ring = toMarker(
        frame, now, "neighbours", member_.index * NeighbourSample::kCapacity + j, Marker::SPHERE,
        centre + mark.position, 2.0 * mark.perimeter, roleColor(mark.role));
    if (axes < 3) {  // a ring on the ground plane
      ring.type = Marker::LINE_STRIP;
      ring.scale.x = binding ? 0.12 : 0.05;
      ring.scale.y = ring.scale.z = 0.0;
      ring.color.a = 0.9F;
      constexpr int kSegments = 48;
      for (int k = 0; k <= kSegments; ++k) {
        const double angle = 2.0 * M_PI * k / kSegments;
        geometry_msgs::Point point;
        point.x = mark.perimeter * std::cos(angle);
        point.y = mark.perimeter * std::sin(angle);
        ring.points.push_back(point);
      }
    }
    ring.lifetime = lifetime;
    markers.markers.push_back(ring);
    if (binding) {
      visualization_msgs::Marker line =
          toMarker(frame, now, "neighbour_binding", member_.index * NeighbourSample::kCapacity + j,
                   Marker::LINE_LIST, Eigen::Vector3d::Zero(), 0.06, roleColor(mark.role));
      line.scale.y = line.scale.z = 0.0;
      line.color.a = 0.9F;
      geometry_msgs::Point from;
      from.x = centre.x();
      from.y = centre.y();
      from.z = centre.z();
      geometry_msgs::Point to;
      to.x = from.x + mark.position.x();
      to.y = from.y + mark.position.y();
      to.z = from.z + mark.position.z();
      line.points = {from, to};
      line.lifetime = lifetime;
      markers.markers.push_back(line);
    }
  }
  marker_publisher_.publish(markers);
}

}  // namespace projection_collision_avoidance
