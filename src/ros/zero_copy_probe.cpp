// Test helpers for the zero-copy rostest: ZeroCopyProbeSource publishes KeypointFrames as
// shared pointers and records each object's address; ZeroCopyProbeSink, loaded into the same
// manager, reports on yolo_slam/zero_copy_report whether the object it received is the one
// published (same address) and whether its contents are intact.
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <std_msgs/String.h>

#include <map>
#include <mutex>

#include "yolo_slam/KeypointFrame.h"

namespace yolo_slam {
namespace ros1 {

namespace {
std::mutex g_probe_mutex;  // guards g_published (source publish vs sink callback)
std::map<uint32_t, const KeypointFrame*> g_published;  // seq -> address of the published object
}  // namespace

class ZeroCopyProbeSource : public nodelet::Nodelet {
 private:
  void onInit() override {
    ::ros::NodeHandle& nh = getNodeHandle();
    pub_ = nh.advertise<KeypointFrame>("yolo_slam/zero_copy_probe", 100);
    timer_ = nh.createWallTimer(::ros::WallDuration(0.05), &ZeroCopyProbeSource::tick, this);
  }
  void tick(const ::ros::WallTimerEvent&) {
    if (pub_.getNumSubscribers() == 0) return;
    auto msg = boost::make_shared<KeypointFrame>();
    msg->header.seq = ++seq_;
    msg->header.stamp = ::ros::Time::now();
    msg->width = 640;
    msg->height = 480;
    const size_t n = 1000;  // the size of a real frame: a copy would be noticeable
    msg->keypoints.resize(n);
    msg->descriptors.assign(n * 32, static_cast<uint8_t>(seq_));
    msg->depth.assign(n, 1.5f);
    msg->dynamic.assign(n, 0);
    {
      std::lock_guard<std::mutex> lock(g_probe_mutex);
      g_published[seq_] = msg.get();
    }
    pub_.publish(msg);
  }
  ::ros::Publisher pub_;
  ::ros::WallTimer timer_;
  uint32_t seq_ = 0;
};

class ZeroCopyProbeSink : public nodelet::Nodelet {
 private:
  void onInit() override {
    ::ros::NodeHandle& nh = getNodeHandle();
    report_ = nh.advertise<std_msgs::String>("yolo_slam/zero_copy_report", 100);
    sub_ = nh.subscribe("yolo_slam/zero_copy_probe", 100, &ZeroCopyProbeSink::onFrame, this);
  }
  void onFrame(const KeypointFrame::ConstPtr& msg) {
    const KeypointFrame* published = nullptr;
    {
      std::lock_guard<std::mutex> lock(g_probe_mutex);
      auto it = g_published.find(msg->header.seq);
      if (it != g_published.end()) published = it->second;
    }
    const bool intact = msg->descriptors.size() == 32000 &&
                        msg->descriptors.front() == static_cast<uint8_t>(msg->header.seq);
    std_msgs::String r;
    r.data = std::string(published == msg.get() ? "same" : "copy") + " " +
             std::to_string(msg->header.seq) + (intact ? " intact" : " corrupt");
    report_.publish(r);
  }
  ::ros::Publisher report_;
  ::ros::Subscriber sub_;
};

}  // namespace ros1
}  // namespace yolo_slam

PLUGINLIB_EXPORT_CLASS(yolo_slam::ros1::ZeroCopyProbeSource, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(yolo_slam::ros1::ZeroCopyProbeSink, nodelet::Nodelet)
