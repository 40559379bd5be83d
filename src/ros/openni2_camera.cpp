// yolo_slam/OpenNI2Camera: Kinect / Xtion / Astra (or an .oni recording) through OpenNI2.
// libOpenNI2 is loaded at run time (dlopen of its C API) so the nodelet library loads and the
// rest of the graph runs on machines without OpenNI2; a missing library is a clear ROS error.
#include <dlfcn.h>

#include <openni2/OniCAPI.h>
#include <openni2/OniCEnums.h>
#include <openni2/OniCProperties.h>
#include <openni2/OniCTypes.h>
#include <openni2/OniVersion.h>
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/image_encodings.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <string>
#include <thread>

namespace yolo_slam {
namespace ros1 {

namespace {

// The subset of the OpenNI2 C API the camera needs, resolved from libOpenNI2.so.0.
struct OniApi {
  void* handle = nullptr;
  decltype(&::oniInitialize) initialize = nullptr;
  decltype(&::oniShutdown) shutdown = nullptr;
  decltype(&::oniGetExtendedError) extendedError = nullptr;
  decltype(&::oniDeviceOpen) deviceOpen = nullptr;
  decltype(&::oniDeviceClose) deviceClose = nullptr;
  decltype(&::oniDeviceCreateStream) createStream = nullptr;
  decltype(&::oniDeviceSetProperty) deviceSetProperty = nullptr;
  decltype(&::oniDeviceIsImageRegistrationModeSupported) registrationSupported = nullptr;
  decltype(&::oniDeviceEnableDepthColorSync) enableSync = nullptr;
  decltype(&::oniStreamDestroy) streamDestroy = nullptr;
  decltype(&::oniStreamStart) streamStart = nullptr;
  decltype(&::oniStreamStop) streamStop = nullptr;
  decltype(&::oniStreamSetProperty) streamSetProperty = nullptr;
  decltype(&::oniStreamGetProperty) streamGetProperty = nullptr;
  decltype(&::oniStreamReadFrame) readFrame = nullptr;
  decltype(&::oniFrameRelease) frameRelease = nullptr;
  decltype(&::oniWaitForAnyStream) waitForAnyStream = nullptr;

  // Returns an empty string on success, else why it failed.
  std::string load() {
    for (const char* name : {"libOpenNI2.so.0", "libOpenNI2.so"}) {
      handle = dlopen(name, RTLD_NOW | RTLD_LOCAL);
      if (handle) break;
    }
    if (!handle)
      return std::string("cannot load libOpenNI2.so.0 (") + dlerror() +
             "); install it with: apt-get install libopenni2-0";
    std::string missing;
    auto get = [&](auto& fn, const char* sym) {
      fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(dlsym(handle, sym));
      if (!fn) missing += std::string(" ") + sym;
    };
    get(initialize, "oniInitialize");
    get(shutdown, "oniShutdown");
    get(extendedError, "oniGetExtendedError");
    get(deviceOpen, "oniDeviceOpen");
    get(deviceClose, "oniDeviceClose");
    get(createStream, "oniDeviceCreateStream");
    get(deviceSetProperty, "oniDeviceSetProperty");
    get(registrationSupported, "oniDeviceIsImageRegistrationModeSupported");
    get(enableSync, "oniDeviceEnableDepthColorSync");
    get(streamDestroy, "oniStreamDestroy");
    get(streamStart, "oniStreamStart");
    get(streamStop, "oniStreamStop");
    get(streamSetProperty, "oniStreamSetProperty");
    get(streamGetProperty, "oniStreamGetProperty");
    get(readFrame, "oniStreamReadFrame");
    get(frameRelease, "oniFrameRelease");
    get(waitForAnyStream, "oniWaitForAnyStream");
    if (!missing.empty()) return "libOpenNI2 lacks symbols:" + missing;
    return "";
  }
};

}  // namespace

class OpenNI2Camera : public nodelet::Nodelet {
 public:
  ~OpenNI2Camera() override {
    running_ = false;
    if (thread_.joinable()) thread_.join();
    closeDevice();
    if (initialized_) api_.shutdown();
    if (api_.handle) dlclose(api_.handle);
  }

 private:
  void onInit() override {
    ::ros::NodeHandle& nh = getNodeHandle();
    ::ros::NodeHandle& pnh = getPrivateNodeHandle();
    pnh.param<std::string>("device_uri", device_uri_, "");
    pnh.param<std::string>("oni_file", oni_file_, "");
    pnh.param<std::string>("depth_encoding", depth_encoding_, "32FC1");
    pnh.param("width", width_, 640);
    pnh.param("height", height_, 480);
    pnh.param("fps", fps_, 30);
    pnh.param("registration", registration_, true);
    pnh.param("retry_period", retry_period_, 2.0);
    pnh.param("playback_repeat", playback_repeat_, false);
    pnh.param<std::string>("rgb_frame_id", rgb_frame_id_, "camera_rgb_optical_frame");
    pnh.param<std::string>("depth_frame_id", depth_frame_id_, "camera_depth_optical_frame");
    pnh.param("fx", fx_, 0.0);
    pnh.param("fy", fy_, 0.0);
    pnh.param("cx", cx_, 0.0);
    pnh.param("cy", cy_, 0.0);
    if (depth_encoding_ != "32FC1" && depth_encoding_ != "16UC1") {
      NODELET_ERROR("OpenNI2Camera: parameter ~depth_encoding is '%s'; use 32FC1 (metres) or "
                    "16UC1 (millimetres). Using 32FC1.", depth_encoding_.c_str());
      depth_encoding_ = "32FC1";
    }
    if (retry_period_ <= 0) retry_period_ = 2.0;
    rgb_pub_ = nh.advertise<sensor_msgs::Image>("camera/rgb/image_color", 5);
    depth_pub_ = nh.advertise<sensor_msgs::Image>("camera/depth/image", 5);
    rgb_info_pub_ = nh.advertise<sensor_msgs::CameraInfo>("camera/rgb/camera_info", 5);
    depth_info_pub_ = nh.advertise<sensor_msgs::CameraInfo>("camera/depth/camera_info", 5);

    const std::string err = api_.load();
    if (!err.empty()) {
      NODELET_ERROR("OpenNI2Camera: %s. No images will be published.", err.c_str());
      return;
    }
    running_ = true;
    thread_ = std::thread([this] { run(); });
  }

  std::string lastError() const {
    const char* e = api_.extendedError ? api_.extendedError() : nullptr;
    // OpenNI2's messages carry tabs and newlines; keep the ROS error on one line.
    std::string s;
    for (const char* p = e; p && *p; ++p) {
      const bool space = *p == '\n' || *p == '\t' || *p == '\r' || *p == ' ';
      if (space && (s.empty() || s.back() == ' ')) continue;
      s += space ? ' ' : *p;
    }
    while (!s.empty() && s.back() == ' ') s.pop_back();
    return s.empty() ? std::string("no details") : s;
  }

  // Sleeps up to `seconds`, returning early when the nodelet is unloaded.
  void sleepFor(double seconds) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (running_ && std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }

  void run() {
    while (running_ && ::ros::ok()) {
      if (!initialized_) {
        if (api_.initialize(ONI_API_VERSION) != ONI_STATUS_OK) {
          NODELET_ERROR("OpenNI2Camera: OpenNI2 initialisation failed (%s); retrying in %.1f s",
                        lastError().c_str(), retry_period_);
          sleepFor(retry_period_);
          continue;
        }
        initialized_ = true;
      }
      std::string why;
      if (!openDevice(why)) {
        ++failed_opens_;
        NODELET_ERROR("OpenNI2Camera: %s; retrying in %.1f s (attempt %d)", why.c_str(),
                      retry_period_, failed_opens_);
        closeDevice();
        sleepFor(retry_period_);
        continue;
      }
      NODELET_INFO("OpenNI2Camera: streaming from %s (%dx%d @ %d Hz, depth %s%s)",
                   source_.c_str(), width_, height_, fps_, depth_encoding_.c_str(),
                   registered_ ? ", registered to colour" : "");
      failed_opens_ = 0;
      stream();
      closeDevice();
      if (running_) sleepFor(retry_period_);
    }
  }

  bool openDevice(std::string& why) {
    const bool from_file = !oni_file_.empty();
    source_ = from_file ? oni_file_ : (device_uri_.empty() ? "the first OpenNI2 device" : device_uri_);
    const char* uri = from_file ? oni_file_.c_str()
                                : (device_uri_.empty() ? nullptr : device_uri_.c_str());
    if (api_.deviceOpen(uri, &device_) != ONI_STATUS_OK) {
      device_ = nullptr;
      why = from_file ? "cannot open the recording '" + oni_file_ + "' (" + lastError() +
                            "); check ~oni_file"
                      : "no OpenNI2 device found" +
                            (device_uri_.empty() ? std::string() : " at '" + device_uri_ + "'") +
                            " (" + lastError() +
                            "); plug in a Kinect/Xtion or set ~oni_file to a recording";
      return false;
    }
    if (from_file) {
      OniBool repeat = playback_repeat_ ? 1 : 0;
      api_.deviceSetProperty(device_, ONI_DEVICE_PROPERTY_PLAYBACK_REPEAT_ENABLED, &repeat,
                             sizeof(repeat));
    }
    if (!createStream(ONI_SENSOR_COLOR, ONI_PIXEL_FORMAT_RGB888, color_, why) ||
        !createStream(ONI_SENSOR_DEPTH, ONI_PIXEL_FORMAT_DEPTH_1_MM, depth_, why))
      return false;
    registered_ = false;
    if (registration_) {
      if (api_.registrationSupported(device_, ONI_IMAGE_REGISTRATION_DEPTH_TO_COLOR)) {
        OniImageRegistrationMode mode = ONI_IMAGE_REGISTRATION_DEPTH_TO_COLOR;
        registered_ = api_.deviceSetProperty(device_, ONI_DEVICE_PROPERTY_IMAGE_REGISTRATION,
                                             &mode, sizeof(mode)) == ONI_STATUS_OK;
      }
      if (!registered_)
        NODELET_WARN("OpenNI2Camera: %s does not support depth-to-colour registration; depth "
                     "is published unregistered", source_.c_str());
    }
    api_.enableSync(device_);
    if (api_.streamStart(color_) != ONI_STATUS_OK || api_.streamStart(depth_) != ONI_STATUS_OK) {
      why = "cannot start the streams of " + source_ + " (" + lastError() + ")";
      return false;
    }
    float hfov = 0, vfov = 0;
    int size = sizeof(float);
    api_.streamGetProperty(color_, ONI_STREAM_PROPERTY_HORIZONTAL_FOV, &hfov, &size);
    size = sizeof(float);
    api_.streamGetProperty(color_, ONI_STREAM_PROPERTY_VERTICAL_FOV, &vfov, &size);
    hfov_ = hfov;
    vfov_ = vfov;
    return true;
  }

  bool createStream(OniSensorType type, OniPixelFormat format, OniStreamHandle& s,
                    std::string& why) {
    if (api_.createStream(device_, type, &s) != ONI_STATUS_OK) {
      s = nullptr;
      why = std::string("cannot create the ") + (type == ONI_SENSOR_COLOR ? "colour" : "depth") +
            " stream of " + source_ + " (" + lastError() + ")";
      return false;
    }
    OniVideoMode mode{format, width_, height_, fps_};
    if (oni_file_.empty() &&
        api_.streamSetProperty(s, ONI_STREAM_PROPERTY_VIDEO_MODE, &mode, sizeof(mode)) !=
            ONI_STATUS_OK)
      NODELET_WARN("OpenNI2Camera: %s does not support %dx%d @ %d Hz for the %s stream (%s); "
                   "using its default mode", source_.c_str(), width_, height_, fps_,
                   type == ONI_SENSOR_COLOR ? "colour" : "depth", lastError().c_str());
    return true;
  }

  void closeDevice() {
    for (OniStreamHandle* s : {&color_, &depth_}) {
      if (*s) {
        api_.streamStop(*s);
        api_.streamDestroy(*s);
        *s = nullptr;
      }
    }
    if (device_) {
      api_.deviceClose(device_);
      device_ = nullptr;
    }
  }

  // Reads frames until the device stops delivering (unplugged, end of recording) or unload.
  void stream() {
    OniStreamHandle streams[2] = {color_, depth_};
    double silent = 0;
    while (running_ && ::ros::ok()) {
      int index = -1;
      const int timeout_ms = 200;
      OniStatus st = api_.waitForAnyStream(streams, 2, &index, timeout_ms);
      if (st == ONI_STATUS_TIME_OUT) {
        silent += timeout_ms / 1000.0;
        if (silent >= retry_period_) {
          NODELET_ERROR("OpenNI2Camera: no frame from %s for %.1f s (unplugged or end of "
                        "recording); reopening", source_.c_str(), silent);
          return;
        }
        continue;
      }
      if (st != ONI_STATUS_OK || index < 0 || index > 1) {
        NODELET_ERROR("OpenNI2Camera: waiting for frames from %s failed (%s); reopening",
                      source_.c_str(), lastError().c_str());
        return;
      }
      OniFrame* frame = nullptr;
      if (api_.readFrame(streams[index], &frame) != ONI_STATUS_OK || !frame) {
        NODELET_ERROR("OpenNI2Camera: reading a frame from %s failed (%s); reopening",
                      source_.c_str(), lastError().c_str());
        return;
      }
      silent = 0;
      const ::ros::Time stamp = ::ros::Time::now();
      if (index == 0)
        publishColor(*frame, stamp);
      else
        publishDepth(*frame, stamp);
      api_.frameRelease(frame);
    }
  }

  sensor_msgs::CameraInfoPtr cameraInfo(int w, int h, const std::string& frame_id,
                                        const ::ros::Time& stamp) const {
    auto info = boost::make_shared<sensor_msgs::CameraInfo>();
    info->header.stamp = stamp;
    info->header.frame_id = frame_id;
    info->width = w;
    info->height = h;
    info->distortion_model = "plumb_bob";
    info->D.assign(5, 0.0);
    // Focal length from the driver's field of view unless given explicitly.
    const double fx = fx_ > 0 ? fx_ : (hfov_ > 0 ? w / (2.0 * std::tan(hfov_ / 2.0)) : 525.0);
    const double fy = fy_ > 0 ? fy_ : (vfov_ > 0 ? h / (2.0 * std::tan(vfov_ / 2.0)) : fx);
    const double cx = cx_ > 0 ? cx_ : (w - 1) / 2.0;
    const double cy = cy_ > 0 ? cy_ : (h - 1) / 2.0;
    info->K = {fx, 0, cx, 0, fy, cy, 0, 0, 1};
    info->R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    info->P = {fx, 0, cx, 0, 0, fy, cy, 0, 0, 0, 1, 0};
    return info;
  }

  void publishColor(const OniFrame& f, const ::ros::Time& stamp) {
    if (f.videoMode.pixelFormat != ONI_PIXEL_FORMAT_RGB888) {
      NODELET_ERROR_THROTTLE(5, "OpenNI2Camera: colour stream delivers pixel format %d, not "
                             "RGB888; frame skipped", static_cast<int>(f.videoMode.pixelFormat));
      return;
    }
    auto img = boost::make_shared<sensor_msgs::Image>();
    img->header.stamp = stamp;
    img->header.frame_id = rgb_frame_id_;
    img->width = f.width;
    img->height = f.height;
    img->encoding = sensor_msgs::image_encodings::RGB8;
    img->step = f.width * 3;
    const size_t bytes = static_cast<size_t>(img->step) * f.height;
    if (static_cast<size_t>(f.dataSize) < bytes) return;
    img->data.resize(bytes);
    for (int r = 0; r < f.height; ++r)
      std::memcpy(&img->data[r * img->step],
                  static_cast<const uint8_t*>(f.data) + static_cast<size_t>(r) * f.stride,
                  img->step);
    rgb_pub_.publish(img);
    rgb_info_pub_.publish(cameraInfo(f.width, f.height, rgb_frame_id_, stamp));
  }

  void publishDepth(const OniFrame& f, const ::ros::Time& stamp) {
    const std::string frame_id = registered_ ? rgb_frame_id_ : depth_frame_id_;
    auto img = boost::make_shared<sensor_msgs::Image>();
    img->header.stamp = stamp;
    img->header.frame_id = frame_id;
    img->width = f.width;
    img->height = f.height;
    const bool metres = depth_encoding_ == "32FC1";
    img->encoding = metres ? sensor_msgs::image_encodings::TYPE_32FC1
                           : sensor_msgs::image_encodings::TYPE_16UC1;
    img->step = f.width * (metres ? 4 : 2);
    img->data.resize(static_cast<size_t>(img->step) * f.height);
    const bool tenth_mm = f.videoMode.pixelFormat == ONI_PIXEL_FORMAT_DEPTH_100_UM;
    for (int r = 0; r < f.height; ++r) {
      const auto* src = reinterpret_cast<const uint16_t*>(static_cast<const uint8_t*>(f.data) +
                                                          static_cast<size_t>(r) * f.stride);
      uint8_t* dst = &img->data[r * img->step];
      for (int c = 0; c < f.width; ++c) {
        const uint16_t raw = src[c];
        if (metres) {
          // REP 118: invalid depth is NaN in 32FC1.
          const float m = raw == 0 ? std::numeric_limits<float>::quiet_NaN()
                                   : raw * (tenth_mm ? 1e-4f : 1e-3f);
          std::memcpy(dst + 4 * c, &m, 4);
        } else {
          const uint16_t mm = tenth_mm ? static_cast<uint16_t>(raw / 10) : raw;
          std::memcpy(dst + 2 * c, &mm, 2);
        }
      }
    }
    depth_pub_.publish(img);
    depth_info_pub_.publish(cameraInfo(f.width, f.height, frame_id, stamp));
  }

  OniApi api_;
  bool initialized_ = false;  // oniInitialize succeeded (only touched by the capture thread)
  std::atomic<bool> running_{false};
  std::thread thread_;
  OniDeviceHandle device_ = nullptr;  // device and streams: capture thread only
  OniStreamHandle color_ = nullptr, depth_ = nullptr;
  bool registered_ = false;
  float hfov_ = 0, vfov_ = 0;
  int failed_opens_ = 0;
  std::string source_;

  std::string device_uri_, oni_file_, depth_encoding_, rgb_frame_id_, depth_frame_id_;
  int width_ = 640, height_ = 480, fps_ = 30;
  bool registration_ = true, playback_repeat_ = false;
  double retry_period_ = 2.0, fx_ = 0, fy_ = 0, cx_ = 0, cy_ = 0;
  ::ros::Publisher rgb_pub_, depth_pub_, rgb_info_pub_, depth_info_pub_;
};

}  // namespace ros1
}  // namespace yolo_slam

PLUGINLIB_EXPORT_CLASS(yolo_slam::ros1::OpenNI2Camera, nodelet::Nodelet)
