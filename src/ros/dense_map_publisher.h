#pragma once
// ROS output of the dense static map (mapping::DenseMapper, owned by slam::System): occupied
// voxels as sensor_msgs/PointCloud2 and as visualization_msgs/MarkerArray cubes (Debian has no
// octomap_msgs), the coloured cloud, and a nav_msgs/OccupancyGrid projection of a height band.
// Used by the Slam nodelet's timer; the topics are latched.
#include "yolo_slam/common/geometry.h"
#include "yolo_slam/mapping/dense_mapper.h"

#include <ros/ros.h>

#include <string>

namespace yolo_slam {
namespace ros1 {

struct DenseMapTopicsOptions {
  static constexpr double kDefaultGridMinHeight = 0.1;  // metres above the map frame's origin
  static constexpr double kDefaultGridMaxHeight = 1.8;
  double grid_min_height = kDefaultGridMinHeight;  // ~grid_min_height
  double grid_max_height = kDefaultGridMaxHeight;  // ~grid_max_height
};

class DenseMapPublisher {
 public:
  // yolo_slam/octomap_occupied, yolo_slam/octomap_markers, yolo_slam/dense_cloud,
  // yolo_slam/grid_map.
  void advertise(::ros::NodeHandle& nh, const DenseMapTopicsOptions& options);
  // T_map_world: the SLAM world (first camera frame) in the map frame (z up).
  void publish(const mapping::DenseMapper& dense, const Pose& T_map_world, const std::string& frame,
               const ::ros::Time& stamp);

 private:
  DenseMapTopicsOptions opt_;
  ::ros::Publisher occupied_pub_, markers_pub_, cloud_pub_, grid_pub_;
};

}  // namespace ros1
}  // namespace yolo_slam
