// The plant's agent_markers: each agent, its name, its heading (vehicle kinds), and who looks at
// whom.

#include <string>

#include <tf2_eigen/tf2_eigen.h>
#include <visualization_msgs/MarkerArray.h>

#include "projection_collision_avoidance/ros/MessageConversions.hpp"

#include "plant/PlantWorld.hpp"

namespace projection_collision_avoidance {
namespace {

visualization_msgs::Marker labelMarker(const std::string& frame, const ros::Time& stamp, int id,
                                       const std::string& text, double height) {
  visualization_msgs::Marker marker =
      toMarker(frame, stamp, "labels", id, visualization_msgs::Marker::TEXT_VIEW_FACING,
               Eigen::Vector3d(0.0, 0.0, height), 0.3, MarkerColor{});
  marker.scale.x = marker.scale.y = 0.0;
  marker.text = text;
  return marker;
}

/// An arrow along the x axis of @p frame: a vehicle's heading.
visualization_msgs::Marker headingMarker(const std::string& frame, const ros::Time& stamp, int id) {
  visualization_msgs::Marker marker =
      toMarker(frame, stamp, "headings", id, visualization_msgs::Marker::ARROW,
               Eigen::Vector3d::Zero(), 1.0, {0.1F, 0.8F, 0.2F, 1.0F});
  marker.scale.y = 0.08;  // shaft diameter (m); scale.x is the length
  marker.scale.z = 0.16;  // head diameter (m)
  return marker;
}

}  // namespace

void PlantWorld::publishMarkers(const ros::Time& stamp) {
  using visualization_msgs::Marker;
  visualization_msgs::MarkerArray markers;
  markers.markers.push_back(toMarker(leader_.frame, stamp, "agents", 0, Marker::CUBE,
                                     Eigen::Vector3d::Zero(), 0.6, {0.1F, 0.3F, 1.0F, 1.0F}));
  markers.markers.push_back(labelMarker(leader_.frame, stamp, 0, leader_.name, 0.7));
  if (leader_.vehicle) {
    markers.markers.push_back(headingMarker(leader_.frame, stamp, 0));
  }
  // Who looks at whom: a thin grey line from each follower to its target, in the world frame.
  Marker links = toMarker(options_.world_frame, stamp, "links", 0, Marker::LINE_LIST,
                          Eigen::Vector3d::Zero(), 0.04, {0.6F, 0.6F, 0.6F, 0.8F});
  int id = 1;
  for (const Follower& follower : followers_) {
    markers.markers.push_back(toMarker(follower.agent.frame, stamp, "agents", id, Marker::SPHERE,
                                       Eigen::Vector3d::Zero(), 0.5, {1.0F, 0.55F, 0.0F, 1.0F}));
    markers.markers.push_back(
        labelMarker(follower.agent.frame, stamp, id, follower.agent.name, 0.6));
    if (follower.agent.vehicle) {
      markers.markers.push_back(headingMarker(follower.agent.frame, stamp, id));
    }
    for (const Agent* end : {&follower.agent, &targetOf(follower)}) {
      links.points.push_back(tf2::toMsg(toVector3(end->state().head(axes_))));
    }
    ++id;
  }
  markers.markers.push_back(links);
  marker_publisher_.publish(markers);
}

}  // namespace projection_collision_avoidance
