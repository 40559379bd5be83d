// yolo_slam/OpenNI2Camera: Kinect / Xtion / Astra (or an .oni recording) through OpenNI2, with
// openni2_launch's topics, frame ids, parameters and camera_info handling (camera_info_manager),
// stamped from the device clock. libOpenNI2 is loaded at run time (dlopen of its C API) so the
// nodelet library loads and the rest of the graph runs on machines without OpenNI2; a missing
// library is a clear ROS error.
#include <dlfcn.h>

#include <openni2/OniCAPI.h>
#include <openni2/OniCEnums.h>
#include <openni2/OniCProperties.h>
#include <openni2/OniCTypes.h>
#include <openni2/OniVersion.h>
#include <camera_info_manager/camera_info_manager.h>
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/image_encodings.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "yolo_slam/common/device_clock.h"

namespace yolo_slam {
namespace ros1 {

namespace {

// The subset of the OpenNI2 C API the camera needs, resolved from libOpenNI2.so.0.
struct OniApi {
  void* handle = nullptr;
  decltype(&::oniInitialize) initialize = nullptr;
  decltype(&::oniShutdown) shutdown = nullptr;
  decltype(&::oniGetExtendedError) extendedError = nullptr;
  decltype(&::oniGetDeviceList) deviceList = nullptr;
  decltype(&::oniReleaseDeviceList) releaseDeviceList = nullptr;
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
    get(deviceList, "oniGetDeviceList");
    get(releaseDeviceList, "oniReleaseDeviceList");
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

constexpr int kWaitTimeoutMs = 200;         // one wait for a frame; silence is summed up
constexpr int kQueue = 5;                   // publisher queues: a live camera keeps no backlog
constexpr double kFallbackFocalPx = 525.0;  // Kinect / Xtion at 640x480, when no FOV is reported
constexpr float kMetresPerMm = 1e-3f;
constexpr uint16_t kTenthMmPerMm = 10;

namespace enc = sensor_msgs::image_encodings;

// One camera namespace of openni2_launch (camera/rgb, camera/depth_registered, camera/depth):
// image_raw, camera_info and, for depth, image (32FC1 metres, converted only when subscribed).
struct CameraTopics {
  ::ros::Publisher image_raw, image, info;

  void advertise(::ros::NodeHandle& nh, const std::string& ns, bool depth) {
    image_raw = nh.advertise<sensor_msgs::Image>(ns + "/image_raw", kQueue);
    info = nh.advertise<sensor_msgs::CameraInfo>(ns + "/camera_info", kQueue);
    if (depth) image = nh.advertise<sensor_msgs::Image>(ns + "/image", kQueue);
  }
};

// Intrinsics a stream reports (its field of view), used when no calibration file is loaded.
struct FieldOfView {
  float h = 0, v = 0;
};

sensor_msgs::ImagePtr newImage(int w, int h, const std::string& encoding, int bytes_per_pixel,
                               const std::string& frame_id, const ::ros::Time& stamp) {
  auto img = boost::make_shared<sensor_msgs::Image>();
  img->header.stamp = stamp;
  img->header.frame_id = frame_id;
  img->width = w;
  img->height = h;
  img->encoding = encoding;
  img->step = w * bytes_per_pixel;
  img->data.resize(static_cast<size_t>(img->step) * h);
  return img;
}

// The frame holds `height` rows of `stride` bytes, each with `width` pixels.
bool frameFits(const OniFrame& f, int bytes_per_pixel) {
  return f.stride >= f.width * bytes_per_pixel &&
         static_cast<size_t>(f.dataSize) >= static_cast<size_t>(f.stride) * f.height;
}

const uint8_t* frameRow(const OniFrame& f, int r) {
  return static_cast<const uint8_t*>(f.data) + static_cast<size_t>(r) * f.stride;
}

// REP 118 raw depth: 16UC1 millimetres, 0 = no measurement.
sensor_msgs::ImagePtr depthMillimetres(const OniFrame& f, const std::string& frame_id,
                                       const ::ros::Time& stamp) {
  auto img = newImage(f.width, f.height, enc::TYPE_16UC1, 2, frame_id, stamp);
  const bool tenth_mm = f.videoMode.pixelFormat == ONI_PIXEL_FORMAT_DEPTH_100_UM;
  for (int r = 0; r < f.height; ++r) {
    uint8_t* dst = &img->data[r * img->step];
    if (!tenth_mm) {
      std::memcpy(dst, frameRow(f, r), img->step);
      continue;
    }
    const auto* src = reinterpret_cast<const uint16_t*>(frameRow(f, r));
    for (int c = 0; c < f.width; ++c) {
      const uint16_t mm = src[c] / kTenthMmPerMm;
      std::memcpy(dst + 2 * c, &mm, 2);
    }
  }
  return img;
}

// REP 118 processed depth: 32FC1 metres, NaN = no measurement.
sensor_msgs::ImagePtr depthMetres(const sensor_msgs::Image& mm) {
  auto img = newImage(mm.width, mm.height, enc::TYPE_32FC1, 4, mm.header.frame_id, mm.header.stamp);
  const size_t n = static_cast<size_t>(mm.width) * mm.height;
  for (size_t i = 0; i < n; ++i) {
    uint16_t raw;
    std::memcpy(&raw, &mm.data[2 * i], 2);
    const float m = raw == 0 ? std::numeric_limits<float>::quiet_NaN() : raw * kMetresPerMm;
    std::memcpy(&img->data[4 * i], &m, 4);
  }
  return img;
}

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
    readParameters(getPrivateNodeHandle());
    rgb_.advertise(nh, "camera/rgb", false);
    depth_registered_.advertise(nh, "camera/depth_registered", true);
    depth_.advertise(nh, "camera/depth", true);
    // The set_camera_info services live beside each camera_info topic, as in openni2_camera.
    rgb_calibration_ = std::make_unique<camera_info_manager::CameraInfoManager>(
        ::ros::NodeHandle(nh, "camera/rgb"), "rgb_camera", rgb_info_url_);
    depth_calibration_ = std::make_unique<camera_info_manager::CameraInfoManager>(
        ::ros::NodeHandle(nh, "camera/depth"), "depth_camera", depth_info_url_);

    const std::string err = api_.load();
    if (!err.empty()) {
      NODELET_ERROR("OpenNI2Camera: %s. No images will be published.", err.c_str());
      return;
    }
    running_ = true;
    thread_ = std::thread([this] { run(); });
  }

  // openni2_camera's names (device_id, depth_registration, *_camera_info_url, use_device_time),
  // with the older device_uri and registration still read.
  void readParameters(::ros::NodeHandle& pnh) {
    std::string device_uri;
    pnh.param<std::string>("device_uri", device_uri, "");
    pnh.param<std::string>("device_id", device_id_, device_uri);
    pnh.param<std::string>("oni_file", oni_file_, "");
    pnh.param("width", width_, 640);
    pnh.param("height", height_, 480);
    pnh.param("fps", fps_, 30);
    bool registration = true;
    pnh.param("registration", registration, true);
    pnh.param("depth_registration", registration_, registration);
    pnh.param("retry_period", retry_period_, 2.0);
    pnh.param("playback_repeat", playback_repeat_, false);
    pnh.param("use_device_time", use_device_time_, true);
    pnh.param<std::string>("rgb_frame_id", rgb_frame_id_, "camera_rgb_optical_frame");
    pnh.param<std::string>("depth_frame_id", depth_frame_id_, "camera_depth_optical_frame");
    pnh.param<std::string>("rgb_camera_info_url", rgb_info_url_, "");
    pnh.param<std::string>("depth_camera_info_url", depth_info_url_, "");
    pnh.param("fx", fx_, 0.0);
    pnh.param("fy", fy_, 0.0);
    pnh.param("cx", cx_, 0.0);
    pnh.param("cy", cy_, 0.0);
    if (pnh.hasParam("depth_encoding"))
      NODELET_WARN("OpenNI2Camera: ~depth_encoding is no longer used: depth is published as 16UC1 "
                   "millimetres on .../image_raw and 32FC1 metres on .../image (REP 118)");
    if (retry_period_ <= 0) retry_period_ = 2.0;
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
      NODELET_INFO("OpenNI2Camera: streaming from %s (%dx%d @ %d Hz, depth %s, %s stamps)",
                   source_.c_str(), width_, height_, fps_,
                   registered_ ? "registered to colour" : "unregistered",
                   use_device_time_ ? "device" : "host");
      failed_opens_ = 0;
      stream();
      closeDevice();
      if (running_) sleepFor(retry_period_);
    }
  }

  // The URI to open: "" = OpenNI2's first device, "#N" = the N-th device (openni2_camera's
  // device_id), anything else is a device URI. False (with `why`) when there is no N-th device.
  bool deviceUri(std::string& uri, std::string& why) {
    uri = device_id_;
    if (device_id_.size() < 2 || device_id_[0] != '#') return true;
    const int wanted = std::atoi(device_id_.c_str() + 1);
    OniDeviceInfo* list = nullptr;
    int count = 0;
    if (api_.deviceList(&list, &count) != ONI_STATUS_OK) count = 0;
    if (wanted >= 1 && wanted <= count) uri = list[wanted - 1].uri;
    if (list) api_.releaseDeviceList(list);
    if (wanted >= 1 && wanted <= count) return true;
    why = "no OpenNI2 device " + device_id_ + " (" + std::to_string(count) +
          " connected); plug in a Kinect/Xtion or check ~device_id";
    return false;
  }

  bool openDevice(std::string& why) {
    const bool from_file = !oni_file_.empty();
    std::string uri = oni_file_;
    if (!from_file && !deviceUri(uri, why)) return false;
    source_ = from_file ? oni_file_ : (uri.empty() ? "the first OpenNI2 device" : uri);
    if (api_.deviceOpen(uri.empty() ? nullptr : uri.c_str(), &device_) != ONI_STATUS_OK) {
      device_ = nullptr;
      why = from_file ? "cannot open the recording '" + oni_file_ + "' (" + lastError() +
                            "); check ~oni_file"
                      : "no OpenNI2 device found" +
                            (uri.empty() ? std::string() : " at '" + uri + "'") + " (" +
                            lastError() + "); plug in a Kinect/Xtion or set ~oni_file to a recording";
      return false;
    }
    if (from_file) {
      OniBool repeat = playback_repeat_ ? 1 : 0;
      api_.deviceSetProperty(device_, ONI_DEVICE_PROPERTY_PLAYBACK_REPEAT_ENABLED, &repeat,
                             sizeof(repeat));
    }
    if (!createStream(ONI_SENSOR_COLOR, ONI_PIXEL_FORMAT_RGB888, color_, why) ||
        !createStream(ONI_SENSOR_DEPTH, ONI_PIXEL_FORMAT_DEPTH_1_MM, depth_stream_, why))
      return false;
    enableRegistration();
    api_.enableSync(device_);
    if (api_.streamStart(color_) != ONI_STATUS_OK || api_.streamStart(depth_stream_) != ONI_STATUS_OK) {
      why = "cannot start the streams of " + source_ + " (" + lastError() + ")";
      return false;
    }
    color_fov_ = fieldOfView(color_);
    depth_fov_ = fieldOfView(depth_stream_);
    clock_.reset();  // a reopened device starts its clock again
    return true;
  }

  void enableRegistration() {
    registered_ = false;
    if (!registration_) return;
    if (api_.registrationSupported(device_, ONI_IMAGE_REGISTRATION_DEPTH_TO_COLOR)) {
      OniImageRegistrationMode mode = ONI_IMAGE_REGISTRATION_DEPTH_TO_COLOR;
      registered_ = api_.deviceSetProperty(device_, ONI_DEVICE_PROPERTY_IMAGE_REGISTRATION, &mode,
                                           sizeof(mode)) == ONI_STATUS_OK;
    }
    if (!registered_)
      NODELET_WARN("OpenNI2Camera: %s does not support depth-to-colour registration; depth is "
                   "published unregistered on camera/depth/image_raw", source_.c_str());
  }

  FieldOfView fieldOfView(OniStreamHandle s) {
    FieldOfView fov;
    int size = sizeof(float);
    api_.streamGetProperty(s, ONI_STREAM_PROPERTY_HORIZONTAL_FOV, &fov.h, &size);
    size = sizeof(float);
    api_.streamGetProperty(s, ONI_STREAM_PROPERTY_VERTICAL_FOV, &fov.v, &size);
    return fov;
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
    for (OniStreamHandle* s : {&color_, &depth_stream_}) {
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
    OniStreamHandle streams[2] = {color_, depth_stream_};
    double silent = 0;
    while (running_ && ::ros::ok()) {
      int index = -1;
      OniStatus st = api_.waitForAnyStream(streams, 2, &index, kWaitTimeoutMs);
      if (st == ONI_STATUS_TIME_OUT) {
        silent += kWaitTimeoutMs / 1000.0;
        if (silent < retry_period_) continue;
        NODELET_ERROR("OpenNI2Camera: no frame from %s for %.1f s (unplugged or end of "
                      "recording); reopening", source_.c_str(), silent);
        return;
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
      const ::ros::Time stamp = stampOf(*frame);
      if (index == 0)
        publishColor(*frame, stamp);
      else
        publishDepth(*frame, stamp);
      api_.frameRelease(frame);
    }
  }

  // Device time: the frame's own stamp (microseconds, shared by the synchronised colour and
  // depth streams) on the ROS clock, so the spacing is the camera's, not this thread's.
  ::ros::Time stampOf(const OniFrame& f) {
    const ::ros::Time now = ::ros::Time::now();
    if (!use_device_time_) return now;
    return ::ros::Time(std::max(0.0, clock_.toHost(f.timestamp, now.toSec())));
  }

  // The calibration: camera_info_manager's (~*_camera_info_url) when it holds one for this image
  // size, else the device's intrinsics (~fx.. or its field of view) without distortion.
  sensor_msgs::CameraInfoPtr cameraInfo(camera_info_manager::CameraInfoManager& calibration,
                                        const FieldOfView& fov, int w, int h,
                                        const std::string& frame_id, const ::ros::Time& stamp) {
    auto info = boost::make_shared<sensor_msgs::CameraInfo>();
    const bool calibrated = calibration.isCalibrated();
    if (calibrated) *info = calibration.getCameraInfo();
    const bool usable = calibrated && info->width == static_cast<uint32_t>(w) &&
                        info->height == static_cast<uint32_t>(h);
    if (calibrated && !usable)
      NODELET_WARN_THROTTLE(10, "OpenNI2Camera: the calibration is for %ux%u images, the stream "
                            "delivers %dx%d; publishing the device's intrinsics", info->width,
                            info->height, w, h);
    if (!usable) *info = deviceInfo(fov, w, h);
    info->header.stamp = stamp;
    info->header.frame_id = frame_id;
    return info;
  }

  sensor_msgs::CameraInfo deviceInfo(const FieldOfView& fov, int w, int h) const {
    sensor_msgs::CameraInfo info;
    info.width = w;
    info.height = h;
    info.distortion_model = "plumb_bob";
    info.D.assign(5, 0.0);
    const double fx = fx_ > 0 ? fx_ : (fov.h > 0 ? w / (2.0 * std::tan(fov.h / 2.0)) : kFallbackFocalPx);
    const double fy = fy_ > 0 ? fy_ : (fov.v > 0 ? h / (2.0 * std::tan(fov.v / 2.0)) : fx);
    const double cx = cx_ > 0 ? cx_ : (w - 1) / 2.0;
    const double cy = cy_ > 0 ? cy_ : (h - 1) / 2.0;
    info.K = {fx, 0, cx, 0, fy, cy, 0, 0, 1};
    info.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    info.P = {fx, 0, cx, 0, 0, fy, cy, 0, 0, 0, 1, 0};
    return info;
  }

  void publishColor(const OniFrame& f, const ::ros::Time& stamp) {
    if (f.videoMode.pixelFormat != ONI_PIXEL_FORMAT_RGB888) {
      NODELET_ERROR_THROTTLE(5, "OpenNI2Camera: colour stream delivers pixel format %d, not "
                             "RGB888; frame skipped", static_cast<int>(f.videoMode.pixelFormat));
      return;
    }
    if (!frameFits(f, 3)) return;
    auto img = newImage(f.width, f.height, enc::RGB8, 3, rgb_frame_id_, stamp);
    for (int r = 0; r < f.height; ++r) std::memcpy(&img->data[r * img->step], frameRow(f, r), img->step);
    rgb_.image_raw.publish(img);
    rgb_.info.publish(cameraInfo(*rgb_calibration_, color_fov_, f.width, f.height, rgb_frame_id_, stamp));
  }

  // Registered depth is pixel-aligned with colour: colour's frame id and calibration
  // (openni2_launch's depth_registered namespace); unregistered depth keeps its own.
  void publishDepth(const OniFrame& f, const ::ros::Time& stamp) {
    if (!frameFits(f, 2)) return;
    CameraTopics& out = registered_ ? depth_registered_ : depth_;
    const std::string& frame_id = registered_ ? rgb_frame_id_ : depth_frame_id_;
    const sensor_msgs::ImagePtr mm = depthMillimetres(f, frame_id, stamp);
    out.image_raw.publish(mm);
    if (out.image.getNumSubscribers() > 0) out.image.publish(depthMetres(*mm));
    out.info.publish(registered_
                         ? cameraInfo(*rgb_calibration_, color_fov_, f.width, f.height, frame_id, stamp)
                         : cameraInfo(*depth_calibration_, depth_fov_, f.width, f.height, frame_id, stamp));
  }

  OniApi api_;
  bool initialized_ = false;  // oniInitialize succeeded (only touched by the capture thread)
  std::atomic<bool> running_{false};
  std::thread thread_;
  OniDeviceHandle device_ = nullptr;  // device, streams, clock, fov: capture thread only
  OniStreamHandle color_ = nullptr, depth_stream_ = nullptr;
  bool registered_ = false;
  FieldOfView color_fov_, depth_fov_;
  DeviceClock clock_;
  int failed_opens_ = 0;
  std::string source_;

  std::string device_id_, oni_file_, rgb_frame_id_, depth_frame_id_, rgb_info_url_, depth_info_url_;
  int width_ = 640, height_ = 480, fps_ = 30;
  bool registration_ = true, playback_repeat_ = false, use_device_time_ = true;
  double retry_period_ = 2.0, fx_ = 0, fy_ = 0, cx_ = 0, cy_ = 0;
  CameraTopics rgb_, depth_registered_, depth_;
  // Locked inside; onInit creates them, the capture thread and the services use them.
  std::unique_ptr<camera_info_manager::CameraInfoManager> rgb_calibration_, depth_calibration_;
};

}  // namespace ros1
}  // namespace yolo_slam

PLUGINLIB_EXPORT_CLASS(yolo_slam::ros1::OpenNI2Camera, nodelet::Nodelet)
