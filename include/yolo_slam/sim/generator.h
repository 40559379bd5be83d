#pragma once
// yolo_slam_synth as a library: deterministic TUM-format RGB-D sequences of people moving
// through a photo-textured room along real or built-in camera trajectories, with per-pixel
// dynamic masks and per-object boxes as extra ground truth. Tests and benchmarks of other
// modules generate short sequences with it into a temporary folder.
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/geometry.h"
#include "yolo_slam/sim/camera_path.h"
#include "yolo_slam/sim/people.h"
#include "yolo_slam/sim/renderer.h"
#include "yolo_slam/sim/sensor.h"

#include <memory>
#include <string>
#include <vector>

namespace yolo_slam {
namespace sim {

struct SynthOptions {
  std::string preset = "walking_xyz";  // walking_xyz|walking_static|walking_rpy|walking_half|
                                       // sitting_static|static_xyz|loop|crowd|moved_object
  unsigned seed = 1;                   // same seed, same bytes
  int frames = 0;                      // 0: the preset's length; N: the first N frames
  std::string textures_dir;            // "": defaultTextureDir() with defaultTextureFiles()
  std::string trajectory;              // "": the preset's; a built-in name or a TUM file
  std::string walker_video;            // "": defaultWalkerVideo()
  std::string tum_people_dir;          // "": defaultTumPeopleDir()
  double fps = 30.0;
  int threads = 2;                     // frames rendered in parallel by generate()
  // Gain of the fine pattern on every person (a seeded crop of a room photograph modulating
  // the luminance, moving with the person like a clothing pattern): the walker cut-outs are
  // upscaled low-resolution video and would otherwise carry far fewer keypoints than real
  // people. 0: the plain cut-outs.
  double people_detail = 0.6;
  bool objects = true;                 // false: the same sequence without the boxes
  SensorOptions sensor;
  CameraModel camera;                  // freiburg3 intrinsics, 640x480

  // Synth.preset, Synth.seed, Synth.frames, Synth.textures, Synth.trajectory, Synth.fps,
  // Synth.threads, Synth.peopleDetail, Synth.objects (0/1), plus SensorOptions keys; Camera.*
  // keys if present.
  static SynthOptions load(const Config& cfg);
};

// Values of the dynamic mask (masks/*.png): every value > 127 is dynamic, as in other masks;
// a person is told apart from another moving object (the carried box of walking_half), since
// dynamic recall is defined over the people a person detector is asked to find. A box is
// dynamic only while it moves: moved_object's box standing on the floor before it is picked up
// and after it is put down is static scene (mask 0, no boxes.txt row).
constexpr uint8_t kMaskPerson = 255;
constexpr uint8_t kMaskOtherObject = 200;

// Ground truth of one visible dynamic object in one frame.
struct ObjectTruth {
  int id = 0;
  std::string cls;            // "person" or "box"
  cv::Rect box;               // bounding box of its visible pixels (x2 = x + width, exclusive)
  int pixels = 0;             // visible pixels
  double visible_fraction = 0;  // visible pixels / pixels it would cover unoccluded, unclipped
};

struct SynthFrame {
  size_t index = 0;
  double rgb_stamp = 0, depth_stamp = 0;
  Pose T_wc = Pose::Identity();
  cv::Mat bgr;          // CV_8UC3 with sensor noise (as written)
  cv::Mat depth;        // CV_32F metres after the sensor model (as written, before 16-bit)
  cv::Mat depth_exact;  // CV_32F metres, exact geometry, 0 = nothing
  cv::Mat ids;          // CV_16U object id per pixel
  cv::Mat mask;         // CV_8U kMaskPerson, kMaskOtherObject (both dynamic) or 0 (static)
  std::vector<ObjectTruth> objects;
};

// A walker's beat: it walks from (ax, ay) to (bx, by) on the floor and back (metres, room frame;
// the camera starts at the origin looking along +y).
struct FloorSegment {
  double ax, ay, bx, by;
};

// A stop of a scheduled walk: the walker is at (x, y) on the floor at time t (seconds) and
// walks in a straight line to the next stop; two stops at one place make it stand; it stays
// at the last stop.
struct Waypoint {
  double t, x, y;
};

// What a scheduled walker does with the box: it rests on the floor in front of the walker until
// pick_up (s), is lifted, carried and lowered back onto the floor until put_down (s) and rests
// there afterwards. The walker should stand still while lifting and lowering (kBoxLiftTime).
struct BoxMove {
  double pick_up, put_down;
};
constexpr double kBoxLiftTime = 1.0;  // seconds to lift the box from the floor or put it down

struct PresetInfo {
  std::string name, motion, description;
  int frames, walkers, sitters;
  bool carried_box;                        // the last walker carries a box (id 100)
  std::vector<FloorSegment> walker_paths;  // walker k takes path k modulo the count
  std::vector<Waypoint> schedule = {};     // non-empty: the walkers follow it instead (one walker)
  BoxMove box_move = {};                   // with a schedule: when the carried box moves
};
// Analogues of TUM's fr3 walking and sitting sequences, static_xyz (no people), loop, crowd
// (seven walkers crossing and occluding each other, one carrying a box, the real
// fr3_walking_xyz motion), close (people within a metre of the camera) and moved_object (a box
// picked up from the floor, carried and put down again: static, dynamic, static).
const std::vector<PresetInfo>& presets();

class SequenceGenerator {
 public:
  // Loads textures and people and builds the room. Throws yolo_slam::Error for an unknown
  // preset, a missing texture folder, video or trajectory file.
  explicit SequenceGenerator(const SynthOptions& opt);
  ~SequenceGenerator();

  size_t size() const { return rgb_stamps_.size(); }
  const CameraModel& camera() const { return opt_.camera; }
  const SynthOptions& options() const { return opt_; }
  const std::vector<std::string>& textureFiles() const { return texture_files_; }

  // Renders frame i (thread-safe, independent of the order frames are rendered in).
  SynthFrame frame(size_t i) const;

  // Writes the sequence into out_dir (created if needed): rgb/, depth/, masks/, rgb.txt,
  // depth.txt, groundtruth.txt, associations.txt, boxes.txt, camera.yaml. Returns seconds spent.
  double generate(const std::string& out_dir, bool progress = false) const;

 private:
  // generate()'s phases: every frame's images (in parallel) with its objects and pose, then
  // the lists, the boxes, camera.yaml and synth_info.txt. `src` is the command that made them.
  void renderFrames(const std::string& out_dir, bool progress, std::vector<std::vector<ObjectTruth>>& objects,
                    Trajectory& gt) const;
  void writeLists(const std::string& out_dir, const std::string& src) const;
  void writeBoxes(const std::string& out_dir, const std::string& src,
                  const std::vector<std::vector<ObjectTruth>>& objects) const;
  void writeCameraAndInfo(const std::string& out_dir, const std::string& src) const;
  struct Person;
  struct PersonState;
  void addWalkers(cv::RNG& rng, int& next_id);
  void addSitters(cv::RNG& rng, int& next_id);
  void addDetail(Person& p) const;
  PersonState personAt(const Person& p, double t) const;
  Quad personQuad(const Person& p, const PersonState& st, double t) const;
  void addBoxQuads(const Person& p, const PersonState& st, double t, std::vector<Quad>& out) const;
  std::vector<Quad> dynamicQuads(double t, const Pose& T_wc) const;

  SynthOptions opt_;
  PresetInfo preset_;
  std::vector<Texture> textures_;
  std::vector<std::string> texture_files_;
  std::vector<Quad> room_;
  std::unique_ptr<CameraPath> path_;
  std::unique_ptr<Renderer> renderer_;
  std::shared_ptr<const std::vector<SpriteTrack>> walkers_, sitters_;
  std::vector<Person> people_;
  int box_texture_ = 0;
  std::vector<double> rgb_stamps_, depth_stamps_;
  double t0_ = 0;
};

}  // namespace sim
}  // namespace yolo_slam
