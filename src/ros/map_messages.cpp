#include "map_messages.h"

#include <opencv2/imgproc.hpp>
#include <sensor_msgs/point_cloud2_iterator.h>

#include "yolo_slam/detection/draw.h"
#include "yolo_slam/ros/conversions.h"

namespace yolo_slam {
namespace ros1 {

namespace {

// Keyframe frustum: half-width, half-height and depth in metres (camera frame).
constexpr double kFrustumHalfWidth = 0.04, kFrustumHalfHeight = 0.03, kFrustumDepth = 0.05;
constexpr double kKeyframeLineWidth = 0.005, kEdgeLineWidth = 0.002;
const cv::Scalar kGreyBackground(64, 64, 64), kKeptColour(0, 255, 0), kDroppedColour(0, 0, 255);

geometry_msgs::Point toPoint(const Eigen::Vector3d& v) {
  geometry_msgs::Point p;
  p.x = v.x();
  p.y = v.y();
  p.z = v.z();
  return p;
}

visualization_msgs::Marker lineList(const std::string& ns, const std::string& frame, const ::ros::Time& stamp,
                                    double width) {
  visualization_msgs::Marker m;
  m.header.frame_id = frame;
  m.header.stamp = stamp;
  m.ns = ns;
  m.type = visualization_msgs::Marker::LINE_LIST;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.scale.x = width;
  return m;
}

// Apex to each image corner, and the image rectangle, at kFrustumDepth.
void addFrustum(const Pose& T, visualization_msgs::Marker& m) {
  const Eigen::Vector3d corners[4] = {{-kFrustumHalfWidth, -kFrustumHalfHeight, kFrustumDepth},
                                      {kFrustumHalfWidth, -kFrustumHalfHeight, kFrustumDepth},
                                      {kFrustumHalfWidth, kFrustumHalfHeight, kFrustumDepth},
                                      {-kFrustumHalfWidth, kFrustumHalfHeight, kFrustumDepth}};
  const Eigen::Vector3d o = T.translation();
  for (int i = 0; i < 4; ++i) {
    m.points.push_back(toPoint(o));
    m.points.push_back(toPoint(T * corners[i]));
    m.points.push_back(toPoint(T * corners[i]));
    m.points.push_back(toPoint(T * corners[(i + 1) % 4]));
  }
}

}  // namespace

sensor_msgs::PointCloud2Ptr mapPointCloud(const slam::MapSnapshot& snap, const Pose& T_map_world,
                                          const std::string& frame, const ::ros::Time& stamp) {
  sensor_msgs::PointCloud2Ptr cloud(new sensor_msgs::PointCloud2);
  cloud->header.frame_id = frame;
  cloud->header.stamp = stamp;
  sensor_msgs::PointCloud2Modifier mod(*cloud);
  mod.setPointCloud2FieldsByString(1, "xyz");
  mod.resize(snap.points.size());
  sensor_msgs::PointCloud2Iterator<float> x(*cloud, "x"), y(*cloud, "y"), z(*cloud, "z");
  for (const auto& p : snap.points) {
    const Eigen::Vector3d q = T_map_world * p;
    *x = static_cast<float>(q.x());
    *y = static_cast<float>(q.y());
    *z = static_cast<float>(q.z());
    ++x, ++y, ++z;
  }
  return cloud;
}

visualization_msgs::MarkerArrayPtr keyframeMarkers(const slam::MapSnapshot& snap, const Pose& T_map_world,
                                                   const std::string& frame, const ::ros::Time& stamp) {
  visualization_msgs::Marker kf = lineList("keyframes", frame, stamp, kKeyframeLineWidth);
  visualization_msgs::Marker edges = lineList("covisibility", frame, stamp, kEdgeLineWidth);
  kf.color.b = 1.0f;
  kf.color.a = 1.0f;
  edges.color.g = 0.8f;
  edges.color.a = 0.6f;
  std::vector<Eigen::Vector3d> centres;
  for (const auto& k : snap.keyframes) {
    const Pose T = T_map_world * k.T_wc;
    centres.push_back(T.translation());
    addFrustum(T, kf);
  }
  const int n = static_cast<int>(centres.size());
  for (const auto& e : snap.covisibility_edges) {
    if (e.first < 0 || e.second < 0 || e.first >= n || e.second >= n) continue;
    edges.points.push_back(toPoint(centres[e.first]));
    edges.points.push_back(toPoint(centres[e.second]));
  }
  if (kf.points.empty()) kf.action = visualization_msgs::Marker::DELETE;
  if (edges.points.empty()) edges.action = visualization_msgs::Marker::DELETE;
  visualization_msgs::MarkerArrayPtr markers(new visualization_msgs::MarkerArray);
  markers->markers.push_back(kf);
  markers->markers.push_back(edges);
  return markers;
}

cv::Mat drawDebugImage(cv::Mat img, const KeypointFrame& msg, const std::string& state, int inliers) {
  if (img.empty()) img = cv::Mat(msg.height, msg.width, CV_8UC3, kGreyBackground);
  detection::drawBoxes(img, boxesFromMsg(msg.boxes));
  int kept = 0, dropped = 0;
  for (size_t i = 0; i < msg.keypoints.size(); ++i) {
    const bool dyn = i < msg.dynamic.size() && msg.dynamic[i] != 0;
    (dyn ? dropped : kept)++;
    const cv::Point p(cvRound(msg.keypoints[i].x), cvRound(msg.keypoints[i].y));
    if (dyn)
      cv::drawMarker(img, p, kDroppedColour, cv::MARKER_TILTED_CROSS, 7, 1);
    else
      cv::circle(img, p, 3, kKeptColour, 1);
  }
  const std::string text = "tracking " + state + "  kept " + std::to_string(kept) + "  dropped " +
                           std::to_string(dropped) + "  inliers " + std::to_string(inliers);
  // Black outline under white text: readable on any background.
  cv::putText(img, text, cv::Point(8, 20), cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 3);
  cv::putText(img, text, cv::Point(8, 20), cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1);
  return img;
}

}  // namespace ros1
}  // namespace yolo_slam
