#include "dense_map_publisher.h"

#include <nav_msgs/OccupancyGrid.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <visualization_msgs/MarkerArray.h>

#include <map>
#include <vector>

namespace yolo_slam {
namespace ros1 {

namespace {

// Leaves in the map frame. Voxels stay cubes of the same size; with the default optical-to-
// base rotation (multiples of 90 degrees) they stay axis-aligned too.
std::vector<mapping::Voxel> inMapFrame(std::vector<mapping::Voxel> leaves, const Pose& T) {
  for (auto& v : leaves) v.centre = T * v.centre;
  return leaves;
}

// Height colour of a cube: blue low, red high over the grid's height band.
std_msgs::ColorRGBA heightColour(double z, double lo, double hi) {
  const double t = std::min(1.0, std::max(0.0, (z - lo) / std::max(1e-6, hi - lo)));
  std_msgs::ColorRGBA c;
  c.r = static_cast<float>(t);
  c.g = static_cast<float>(1.0 - std::abs(2 * t - 1));
  c.b = static_cast<float>(1.0 - t);
  c.a = 1.0f;
  return c;
}

sensor_msgs::PointCloud2Ptr xyzCloud(const std::vector<mapping::Voxel>& leaves, const std::string& frame,
                                     const ::ros::Time& stamp) {
  auto msg = boost::make_shared<sensor_msgs::PointCloud2>();
  msg->header.frame_id = frame;
  msg->header.stamp = stamp;
  sensor_msgs::PointCloud2Modifier mod(*msg);
  mod.setPointCloud2FieldsByString(1, "xyz");
  mod.resize(leaves.size());
  sensor_msgs::PointCloud2Iterator<float> x(*msg, "x"), y(*msg, "y"), z(*msg, "z");
  for (const auto& v : leaves) {
    *x = static_cast<float>(v.centre.x());
    *y = static_cast<float>(v.centre.y());
    *z = static_cast<float>(v.centre.z());
    ++x, ++y, ++z;
  }
  return msg;
}

visualization_msgs::MarkerArrayPtr cubes(const std::vector<mapping::Voxel>& leaves, const DenseMapTopicsOptions& o,
                                         const std::string& frame, const ::ros::Time& stamp) {
  // One CUBE_LIST per leaf size (pruned leaves are larger), id = the size's rank.
  std::map<double, visualization_msgs::Marker> by_size;
  for (const auto& v : leaves) {
    visualization_msgs::Marker& m = by_size[v.size];
    m.scale.x = m.scale.y = m.scale.z = v.size;
    geometry_msgs::Point p;
    p.x = v.centre.x();
    p.y = v.centre.y();
    p.z = v.centre.z();
    m.points.push_back(p);
    m.colors.push_back(heightColour(p.z, o.grid_min_height, o.grid_max_height));
  }
  auto msg = boost::make_shared<visualization_msgs::MarkerArray>();
  visualization_msgs::Marker clear;
  clear.action = visualization_msgs::Marker::DELETEALL;
  msg->markers.push_back(clear);
  int id = 0;
  for (auto& kv : by_size) {
    visualization_msgs::Marker& m = kv.second;
    m.header.frame_id = frame;
    m.header.stamp = stamp;
    m.ns = "occupied_voxels";
    m.id = id++;
    m.type = visualization_msgs::Marker::CUBE_LIST;
    m.action = visualization_msgs::Marker::ADD;
    m.pose.orientation.w = 1.0;
    m.color.a = 1.0f;
    msg->markers.push_back(m);
  }
  return msg;
}

sensor_msgs::PointCloud2Ptr colouredCloud(const std::vector<mapping::ColouredPoint>& points, const Pose& T,
                                          const std::string& frame, const ::ros::Time& stamp) {
  auto msg = boost::make_shared<sensor_msgs::PointCloud2>();
  msg->header.frame_id = frame;
  msg->header.stamp = stamp;
  sensor_msgs::PointCloud2Modifier mod(*msg);
  mod.setPointCloud2FieldsByString(2, "xyz", "rgb");
  mod.resize(points.size());
  sensor_msgs::PointCloud2Iterator<float> x(*msg, "x"), y(*msg, "y"), z(*msg, "z");
  sensor_msgs::PointCloud2Iterator<uint8_t> r(*msg, "r"), g(*msg, "g"), b(*msg, "b");
  for (const auto& p : points) {
    const Eigen::Vector3d q = T * p.p.cast<double>();
    *x = static_cast<float>(q.x());
    *y = static_cast<float>(q.y());
    *z = static_cast<float>(q.z());
    *r = p.rgb[0];
    *g = p.rgb[1];
    *b = p.rgb[2];
    ++x, ++y, ++z, ++r, ++g, ++b;
  }
  return msg;
}

nav_msgs::OccupancyGridPtr grid(const mapping::OccupancyGrid2D& g, const std::string& frame, const ::ros::Time& stamp) {
  auto msg = boost::make_shared<nav_msgs::OccupancyGrid>();
  msg->header.frame_id = frame;
  msg->header.stamp = stamp;
  msg->info.map_load_time = stamp;
  msg->info.resolution = static_cast<float>(g.resolution);
  msg->info.width = static_cast<uint32_t>(g.width);
  msg->info.height = static_cast<uint32_t>(g.height);
  msg->info.origin.position.x = g.origin_x;
  msg->info.origin.position.y = g.origin_y;
  msg->info.origin.orientation.w = 1.0;
  msg->data = g.cells;
  return msg;
}

}  // namespace

void DenseMapPublisher::advertise(::ros::NodeHandle& nh, const DenseMapTopicsOptions& options) {
  opt_ = options;
  occupied_pub_ = nh.advertise<sensor_msgs::PointCloud2>("yolo_slam/octomap_occupied", 1, true);
  markers_pub_ = nh.advertise<visualization_msgs::MarkerArray>("yolo_slam/octomap_markers", 1, true);
  cloud_pub_ = nh.advertise<sensor_msgs::PointCloud2>("yolo_slam/dense_cloud", 1, true);
  grid_pub_ = nh.advertise<nav_msgs::OccupancyGrid>("yolo_slam/grid_map", 1, true);
}

void DenseMapPublisher::publish(const mapping::DenseMapper& dense, const Pose& T_map_world,
                                const std::string& frame, const ::ros::Time& stamp) {
  const std::vector<mapping::Voxel> occupied = inMapFrame(dense.occupiedLeaves(), T_map_world);
  occupied_pub_.publish(xyzCloud(occupied, frame, stamp));
  markers_pub_.publish(cubes(occupied, opt_, frame, stamp));
  cloud_pub_.publish(colouredCloud(dense.cloud(), T_map_world, frame, stamp));
  const std::vector<mapping::Voxel> free = inMapFrame(dense.freeLeaves(), T_map_world);
  const mapping::OccupancyGrid2D g = mapping::projectToGrid(occupied, free, opt_.grid_min_height,
                                                            opt_.grid_max_height, dense.options().resolution_m);
  grid_pub_.publish(grid(g, frame, stamp));
}

}  // namespace ros1
}  // namespace yolo_slam
