#include <iomanip>
#include <sstream>

#include <visualization_msgs/MarkerArray.h>

#include "projection_collision_avoidance/ros/InputAdmission.hpp"
#include "projection_collision_avoidance/ros/MessageConversions.hpp"

#include "follower/FollowerOutputs.hpp"

namespace projection_collision_avoidance {

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
  if (fallback) {
    label << "\nMEASUREMENT LOST: braking";
  } else if (out.mode == FollowerMode::kLeaderLost) {
    label << "\nleader broadcast lost";
  }
  text.text = label.str();
  markers.markers.push_back(text);
  marker_publisher_.publish(markers);
}

}  // namespace projection_collision_avoidance
