#include "yolo_slam/sim/generator.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/common/progress.h"
#include "yolo_slam/common/timing.h"
#include "yolo_slam/io/trajectory.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <exception>
#include <fstream>
#include <limits>
#include <mutex>
#include <sys/stat.h>
#include <thread>

namespace yolo_slam {
namespace sim {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kBaseStamp = 1700000000.0;  // first rgb stamp (any epoch-like value works)

// World frame of the room: x right, y forward (away from the start view), z up; floor at z = 0.
const Eigen::Vector3d kUp = Eigen::Vector3d::UnitZ();

std::string realGroundTruth() {
  return joinPath(sharedDir(), "data/tum/rgbd_dataset_freiburg3_walking_xyz/groundtruth.txt");
}

uint64_t mix(uint64_t a, uint64_t b) {
  uint64_t x = a * 0x9E3779B97F4A7C15ull ^ (b + 0x7F4A7C159E3779B9ull + (a << 6) + (a >> 2));
  x ^= x >> 31;
  x *= 0xBF58476D1CE4E5B9ull;
  x ^= x >> 27;
  return x ? x : 1;
}

double round6(double s) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6f", s);
  return std::strtod(buf, nullptr);
}
std::string stampStr(double s) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6f", s);
  return buf;
}

void makeDir(const std::string& d) {
  if (dirExists(d)) return;
  if (::mkdir(d.c_str(), 0755) != 0 && !dirExists(d))
    throw Error("cannot create folder " + d + ": check the parent exists and is writable");
}

// Builds the textured room. Textures are assigned round robin with a stride so that
// neighbouring surfaces get different photographs; each surface shows a crop of its photo with
// the surface's aspect ratio (no stretching).
class RoomBuilder {
 public:
  RoomBuilder(const std::vector<Texture>& tex, std::vector<Quad>& out) : tex_(tex), out_(out) {}

  int nextTexture() {
    int t = (int)((counter_ * 7 + 3) % tex_.size());
    ++counter_;
    return t;
  }
  // Colour grading of the next surfaces: walls pale, floor dark and warm, furniture natural.
  void grade(float saturation, cv::Vec3f tint) {
    saturation_ = saturation;
    tint_ = tint;
  }
  void panel(const Eigen::Vector3d& o, const Eigen::Vector3d& eu, const Eigen::Vector3d& ev,
             float bright, int tex = -1, bool two_sided = true) {
    Quad q;
    q.saturation = saturation_;
    q.tint = tint_;
    q.origin = o;
    q.edge_u = eu;
    q.edge_v = ev;
    q.texture = tex >= 0 ? tex : nextTexture();
    q.brightness = bright;
    q.two_sided = two_sided;
    const Texture& t = tex_[q.texture];
    double aspect = eu.norm() / ev.norm();
    double tw = t.width(), th = t.height();
    if (tw / th > aspect) tw = th * aspect; else th = tw / aspect;
    q.tex_rect = cv::Rect2f((float)(0.5 * (t.width() - tw)), (float)(0.5 * (t.height() - th)), (float)tw, (float)th);
    out_.push_back(q);
  }
  // A wall or floor split into a grid of panels of at most `cell` metres.
  void grid(const Eigen::Vector3d& o, const Eigen::Vector3d& eu, const Eigen::Vector3d& ev,
            double cell, float bright, float bright_var) {
    int nu = std::max(1, (int)std::ceil(eu.norm() / cell - 1e-9));
    int nv = std::max(1, (int)std::ceil(ev.norm() / cell - 1e-9));
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < nv; ++j) {
        float b = bright * (1.f - bright_var * (float)(((i * 5 + j * 3) % 4) / 3.0));
        panel(o + eu * ((double)i / nu) + ev * ((double)j / nv), eu / nu, ev / nv, b);
      }
  }
  // Axis-aligned box [lo, hi]: outward faces (the bottom is never seen).
  void box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, float bright, double cell = 2.0) {
    Eigen::Vector3d d = hi - lo;
    Eigen::Vector3d X(d.x(), 0, 0), Y(0, d.y(), 0), Z(0, 0, d.z());
    auto face = [&](const Eigen::Vector3d& o, const Eigen::Vector3d& eu, const Eigen::Vector3d& ev, float b) {
      if (eu.norm() > cell || ev.norm() > cell) grid(o, eu, ev, cell, b, 0.f);
      else panel(o, eu, ev, b, -1, false);
    };
    face(lo, X, Z, bright);                        // -y face (normal X x Z = -y)
    face(lo + Y + X, -X, Z, bright);               // +y face
    face(lo + Y, -Y, Z, bright * 0.9f);            // -x face
    face(lo + X, Y, Z, bright * 0.9f);             // +x face
    face(lo + Z, X, Y, bright * 1.05f);            // top (normal +z)
  }

 private:
  const std::vector<Texture>& tex_;
  std::vector<Quad>& out_;
  size_t counter_ = 0;
  float saturation_ = 1.f;
  cv::Vec3f tint_{1.f, 1.f, 1.f};
};

void buildRoom(const std::vector<Texture>& tex, std::vector<Quad>& q) {
  RoomBuilder b(tex, q);
  using V = Eigen::Vector3d;
  const double x0 = -3.5, x1 = 3.5, y0 = -2.5, y1 = 5.2, h = 2.8;
  // Floor: dark warm carpet tiles; ceiling: pale panels; walls: pale, low-saturation panels
  // (photographs graded like painted or papered walls); furniture keeps natural colours.
  b.grade(0.12f, cv::Vec3f(0.42f, 0.52f, 0.62f));
  b.grid(V(x0, y0, 0), V(x1 - x0, 0, 0), V(0, y1 - y0, 0), 1.9, 1.0f, 0.1f);
  b.grade(0.05f, cv::Vec3f(1.1f, 1.1f, 1.1f));
  b.grid(V(x0, y1, h), V(x1 - x0, 0, 0), V(0, y0 - y1, 0), 2.6, 1.0f, 0.05f);
  b.grade(0.2f, cv::Vec3f(1.0f, 1.1f, 1.18f));
  b.grid(V(x0, y1, 0), V(x1 - x0, 0, 0), V(0, 0, h), 1.4, 1.0f, 0.1f);   // front
  b.grid(V(x1, y0, 0), V(x0 - x1, 0, 0), V(0, 0, h), 1.4, 0.95f, 0.1f);  // back
  b.grade(0.2f, cv::Vec3f(1.15f, 1.1f, 1.0f));
  b.grid(V(x0, y0, 0), V(0, y1 - y0, 0), V(0, 0, h), 1.4, 0.9f, 0.1f);   // left
  b.grid(V(x1, y1, 0), V(0, y0 - y1, 0), V(0, 0, h), 1.4, 0.9f, 0.1f);   // right
  // Two desks in front: top slab, modesty panel and side panels (light wood-like grading).
  b.grade(0.25f, cv::Vec3f(0.7f, 0.88f, 1.05f));
  for (double cx : {-0.85, 0.85}) {
    b.box(V(cx - 0.8, 3.0, 0.71), V(cx + 0.8, 3.8, 0.75), 1.0f);
    b.box(V(cx - 0.78, 3.02, 0.25), V(cx + 0.78, 3.06, 0.71), 0.8f);
    b.box(V(cx - 0.8, 3.0, 0), V(cx - 0.76, 3.8, 0.71), 0.8f);
    b.box(V(cx + 0.76, 3.0, 0), V(cx + 0.8, 3.8, 0.71), 0.8f);
  }
  // Monitors, posters on the partition and the cabinets show their photographs as they are.
  b.grade(1.0f, cv::Vec3f(1, 1, 1));
  for (double cx : {-0.85, 0.85}) {
    b.box(V(cx - 0.3, 3.5, 0.9), V(cx + 0.3, 3.55, 1.25), 0.9f);
    b.box(V(cx - 0.04, 3.53, 0.75), V(cx + 0.04, 3.57, 0.9), 0.6f);
  }
  // Partition behind the desks, three panels.
  for (int i = 0; i < 3; ++i) b.box(V(-2.1 + 1.4 * i, 3.95, 0), V(-0.7 + 1.4 * i, 4.0, 1.55), 0.95f);
  // Cabinets and a shelf at the sides, a low cabinet and a side desk behind the start.
  b.box(V(2.5, 1.2, 0), V(3.4, 2.4, 1.1), 0.9f);
  b.box(V(-3.45, 0.4, 0), V(-2.95, 2.6, 1.9), 0.9f);
  b.box(V(-1.0, -2.45, 0), V(1.0, -2.0, 1.0), 0.9f);
  b.box(V(1.6, -2.45, 0.71), V(3.2, -1.65, 0.75), 1.0f);
  b.box(V(-2.3, -1.6, 0), V(-2.25, 0.0, 1.4), 0.9f);
  b.box(V(2.9, 3.0, 0), V(3.45, 4.8, 1.6), 0.9f);
}

Pose startPose() { return lookAt(Eigen::Vector3d(0, 0, 1.35), Eigen::Vector3d(0, 3.5, 0.8)); }

}  // namespace

// A person: a walker (ping-pong along a floor segment, or following a schedule) or a sitter
// (slight sway).
struct SequenceGenerator::Person {
  int id = 0;
  const SpriteTrack* track = nullptr;
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();  // floor points (sitter: a only)
  std::vector<Waypoint> schedule;  // non-empty: followed instead of the a-b beat
  double speed = 1.0, phase = 0, height = 1.75, anim_phase = 0;
  bool sitting = false, mirror = false;
  int box_id = 0;  // > 0: carries a box with this id
  BoxMove box_move{-std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  SurfaceDetail detail;              // texture, gain, mean; tex_rect is set per frame
  double detail_tpm = 0;             // detail texels per metre of the person
  cv::Point2f detail_anchor;         // texel under the person's feet (bottom centre)
};

// Where a person is at one instant.
struct SequenceGenerator::PersonState {
  Eigen::Vector3d pos = Eigen::Vector3d::Zero(), vel = Eigen::Vector3d::Zero();  // floor, m/s
  Eigen::Vector3d heading = Eigen::Vector3d::Zero();  // unit: walking (or last walked) direction
  Eigen::Vector3d right = Eigen::Vector3d::Zero();    // unit: image right of its camera-facing billboard
  double anim_t = 0;                                   // animation clock (s)
};

// Walkers 1.6 to 3.5 m from the camera's start, in front of the desks.
const std::vector<FloorSegment> kMidRoomPaths = {{-2.2, 2.0, 2.2, 2.7}, {2.0, 2.8, -1.4, 1.6}};
// walking_static: the walkers pass 1.1 to 2.2 m in front of the tripod. The real frame of
// fr3_walking_xyz in ../shared (same office, same two people) shows a person standing 1.37 m
// from the camera and covering 22 % of the image; the mid-room paths kept walking_static's
// walkers at a median 2.2 m and never above 27 % of the image together, and plain SLAM lost only
// 3.5 cm there against ORB-SLAM2's 39 cm on the real sequence (docs/ablation.md,
// "walking_static with the walkers near the tripod").
const std::vector<FloorSegment> kNearTripodPaths = {{-1.9, 1.3, 1.9, 1.7}, {1.7, 2.2, -1.3, 1.1}};
// The loop's walker keeps to the left side so the circling camera never walks into it.
const std::vector<FloorSegment> kLoopPath = {{-2.4, -1.0, -1.9, 2.6}};

// crowd: seven crossing beats 1.2 to 3.7 m from the camera's start, two of them entering and
// leaving through the image borders, one walking towards the camera and back.
const std::vector<FloorSegment> kCrowdPaths = {{-2.2, 1.2, 2.2, 2.8},  {2.2, 1.3, -2.2, 2.9},
                                               {-1.7, 1.2, 1.7, 1.2},  {-0.6, 1.3, 0.5, 2.9},
                                               {-1.9, 1.0, -1.3, 2.9}, {1.5, 0.9, 1.2, 2.9},
                                               {-2.4, 2.5, 2.4, 2.0}};
// close: people near the camera, as hidden real sequences have them. One crosses 0.8 to
// 0.9 m in front of the camera's start (a full-height person there covers most of the image,
// cut by its top and bottom borders), one walks straight at the camera from 2.9 m to 0.75 m
// and back, one crosses mid-room behind them.
const std::vector<FloorSegment> kClosePaths = {{-1.7, 0.8, 1.7, 0.9}, {0.2, 2.9, 0.05, 0.75},
                                               {2.2, 2.4, -2.2, 2.1}};
// moved_object: the walker stands, fetches the box standing on the floor 2.7 m ahead, carries
// it 2.2 m to the right, puts it down and leaves behind the camera. The floor comes into view
// only beyond about 2.1 m, so both resting places lie farther.
const std::vector<Waypoint> kMoveBoxWalk = {{0.0, -2.8, 2.2}, {3.0, -2.8, 2.2},  {4.5, -1.4, 2.7},
                                            {5.5, -1.4, 2.7}, {8.0, 0.8, 2.5},   {9.0, 0.8, 2.5},
                                            {11.0, 2.2, 1.0}, {13.5, 1.8, -1.2}};
const BoxMove kMoveBoxTimes = {4.5, 9.0};

const std::vector<PresetInfo>& presets() {
  static const std::vector<PresetInfo> p = {
      {"walking_xyz", "replay", "two people walking; the real fr3_walking_xyz camera motion", 827, 2, 0, false, kMidRoomPaths},
      {"walking_static", "static", "two people walking near the camera; camera on a tripod", 743, 2, 0, false, kNearTripodPaths},
      {"walking_rpy", "rpy", "two people walking; camera rotating about its axes", 910, 2, 0, false, kMidRoomPaths},
      {"walking_half", "halfsphere", "two people walking, one carrying a box; camera on a half sphere", 1067, 2, 0, true, kMidRoomPaths},
      {"sitting_static", "static", "two people sitting at the desks, moving slightly", 707, 0, 2, false, {}},
      {"static_xyz", "xyz", "no people; camera translating along its axes", 900, 0, 0, false, {}},
      {"loop", "loop", "one walker; the camera circles the room, returns to its start and goes on a sixth of the way round", 1400, 1, 0, false, kLoopPath},
      {"crowd", "replay", "seven people crossing and occluding each other, one carrying a box; the real fr3_walking_xyz camera motion", 860, 7, 0, true, kCrowdPaths},
      {"close", "replay", "three people, two of them close to the camera (one crossing 0.8 m in front of it, one walking up to 0.75 m); the real fr3_walking_xyz camera motion", 827, 3, 0, false, kClosePaths},
      {"moved_object", "xyz", "a person picks up a box standing on the floor, carries it and puts it down; camera translating along its axes", 600, 1, 0, true, {}, kMoveBoxWalk, kMoveBoxTimes},
  };
  return p;
}

SynthOptions SynthOptions::load(const Config& cfg) {
  SynthOptions o;
  o.preset = cfg.getString("Synth.preset", o.preset);
  int seed = cfg.getInt("Synth.seed", (int)o.seed);
  if (seed < 0) throw Error(cfg.path() + ": Synth.seed must be >= 0");
  o.seed = (unsigned)seed;
  o.frames = cfg.getInt("Synth.frames", o.frames);
  o.textures_dir = cfg.getString("Synth.textures", o.textures_dir);
  o.trajectory = cfg.getString("Synth.trajectory", o.trajectory);
  o.fps = cfg.getDouble("Synth.fps", o.fps);
  o.threads = cfg.getInt("Synth.threads", o.threads);
  o.people_detail = cfg.getDouble("Synth.peopleDetail", o.people_detail);
  o.objects = cfg.getBool("Synth.objects", o.objects);
  if (o.frames < 0 || o.fps <= 0 || o.threads < 1 || o.people_detail < 0)
    throw Error(cfg.path() +
                ": Synth.frames must be >= 0, Synth.fps > 0, Synth.threads >= 1, Synth.peopleDetail >= 0");
  o.sensor = SensorOptions::load(cfg);
  if (cfg.has("Camera.fx")) o.camera = CameraModel::load(cfg);
  return o;
}

SequenceGenerator::~SequenceGenerator() = default;

SequenceGenerator::SequenceGenerator(const SynthOptions& opt) : opt_(opt) {
  auto it = std::find_if(presets().begin(), presets().end(),
                         [&](const PresetInfo& p) { return p.name == opt.preset; });
  if (it == presets().end()) {
    std::string names;
    for (const auto& p : presets()) names += (names.empty() ? "" : "|") + p.name;
    throw Error("unknown preset '" + opt.preset + "': use one of " + names);
  }
  preset_ = *it;
  if (opt_.frames < 0 || opt_.fps <= 0) throw Error("frames must be >= 0 and fps > 0");
  if (opt_.threads < 1) opt_.threads = 1;

  const std::string tex_dir = opt_.textures_dir.empty() ? defaultTextureDir() : opt_.textures_dir;
  textures_ = loadTextures(tex_dir);
  for (const auto& t : textures_) texture_files_.push_back(t.name);
  buildRoom(textures_, room_);
  renderer_ = std::make_unique<Renderer>(opt_.camera, textures_);

  // Camera motion.
  std::string traj = opt_.trajectory.empty() ? preset_.motion : opt_.trajectory;
  if (traj == "replay") traj = realGroundTruth();
  const auto& names = CameraPath::builtInNames();
  if (std::find(names.begin(), names.end(), traj) != names.end())
    path_ = std::make_unique<CameraPath>(CameraPath::builtIn(traj, startPose()));
  else
    path_ = std::make_unique<CameraPath>(CameraPath::replay(io::readTrajectory(traj), startPose(), traj));

  // Frame stamps: 30 Hz with sub-millisecond jitter; depth a few ms after rgb, as in TUM.
  int n = opt_.frames > 0 ? opt_.frames : preset_.frames;
  cv::RNG rng(mix(opt_.seed, 0x57A3));
  for (int i = 0; i < n; ++i) {
    double s = round6(kBaseStamp + i / opt_.fps + rng.uniform(-0.0008, 0.0008));
    rgb_stamps_.push_back(s);
    depth_stamps_.push_back(round6(s + rng.uniform(0.0005, 0.006)));
  }
  t0_ = kBaseStamp;

  // People.
  cv::RNG prng(mix(opt_.seed, 0xBEEF));
  int next_id = 1;
  addWalkers(prng, next_id);
  addSitters(prng, next_id);
  for (Person& p : people_) addDetail(p);
  for (size_t i = 0; i < texture_files_.size(); ++i)
    if (texture_files_[i] == "box_in_scene.png" || texture_files_[i] == "board.jpg") box_texture_ = (int)i;
}

namespace {

constexpr double kBoxCarryHeight = 1.0;   // m: centre of a carried box (hip height)
constexpr double kBoxRestHeight = 0.15;   // m: centre of the box standing on the floor
constexpr double kBoxReach = 0.3;         // m: box centre ahead of the body
constexpr double kWalkSpeed = 1.0;        // m/s of the walker videos' gait (schedule animation)
constexpr double kDetailTexelsPerMetre = 420;  // clothing pattern scale, capped by the crop
constexpr double kMaxGaitStretch = 1.15;  // head room of the detail crop for the gait bob
constexpr uint64_t kDetailSeed = 0xD37A11;

// 0 on the floor, 1 carried: lifted over kBoxLiftTime after pick_up, lowered before put_down.
double liftFraction(const BoxMove& m, double t) {
  const double up = (t - m.pick_up) / kBoxLiftTime, down = (m.put_down - t) / kBoxLiftTime;
  return std::min(1.0, std::max(0.0, std::min(up, down)));
}

Eigen::Vector3d floorPoint(const Waypoint& w) { return Eigen::Vector3d(w.x, w.y, 0); }

// Direction of the first leg of a schedule that moves (zero when it never moves).
Eigen::Vector3d firstHeading(const std::vector<Waypoint>& w) {
  for (size_t i = 0; i + 1 < w.size(); ++i) {
    const Eigen::Vector3d d = floorPoint(w[i + 1]) - floorPoint(w[i]);
    if (d.norm() > 1e-9) return d.normalized();
  }
  return Eigen::Vector3d::Zero();
}

// Position, velocity and heading of a scheduled walk at t; the gait advances with the distance
// walked, so a standing walker holds its pose.
void scheduleState(const std::vector<Waypoint>& w, double t, Eigen::Vector3d& pos, Eigen::Vector3d& vel,
                          Eigen::Vector3d& heading, double& walked) {
  heading = firstHeading(w);
  walked = 0;
  pos = floorPoint(w.back());
  for (size_t i = 0; i + 1 < w.size(); ++i) {
    const Eigen::Vector3d p0 = floorPoint(w[i]), d = floorPoint(w[i + 1]) - p0;
    const double len = d.norm(), dt = w[i + 1].t - w[i].t;
    if (t < w[i + 1].t) {
      const double f = dt > 0 ? std::min(1.0, std::max(0.0, (t - w[i].t) / dt)) : 1.0;
      pos = p0 + d * f;
      walked += len * f;
      if (len > 1e-9 && t >= w[i].t) vel = d / dt, heading = d / len;
      return;
    }
    walked += len;
    if (len > 1e-9) heading = d / len;
  }
}

}  // namespace

void SequenceGenerator::addWalkers(cv::RNG& prng, int& next_id) {
  if (preset_.walkers <= 0) return;
  walkers_ = cachedWalkers(opt_.walker_video.empty() ? defaultWalkerVideo() : opt_.walker_video);
  const std::vector<FloorSegment>& segs = preset_.walker_paths;
  if (segs.empty() && preset_.schedule.empty())
    throw Error("preset '" + preset_.name + "' has walkers but no walker paths");
  size_t first = (size_t)prng.uniform(0, (int)walkers_->size());
  for (int k = 0; k < preset_.walkers; ++k) {
    Person p;
    p.id = next_id++;
    p.track = &(*walkers_)[(first + 3 * k) % walkers_->size()];
    if (!preset_.schedule.empty()) {
      p.schedule = preset_.schedule;
    } else {
      const FloorSegment& seg = segs[k % segs.size()];
      p.a = Eigen::Vector3d(seg.ax, seg.ay, 0);
      p.b = Eigen::Vector3d(seg.bx, seg.by, 0);
    }
    p.speed = prng.uniform(0.8, 1.2);
    p.phase = prng.uniform(0.0, 1.0);
    p.height = prng.uniform(1.65, 1.85);
    p.anim_phase = prng.uniform(0.0, 10.0);
    people_.push_back(p);
  }
  if (preset_.carried_box && !people_.empty()) {
    people_.back().box_id = 100;
    if (!preset_.schedule.empty()) people_.back().box_move = preset_.box_move;
  }
}

void SequenceGenerator::addSitters(cv::RNG& prng, int& next_id) {
  if (preset_.sitters <= 0) return;
  sitters_ = cachedTumPeople(opt_.tum_people_dir.empty() ? defaultTumPeopleDir() : opt_.tum_people_dir);
  const Eigen::Vector3d seats[2] = {Eigen::Vector3d(-0.75, 2.6, 0), Eigen::Vector3d(0.8, 2.5, 0)};
  for (int k = 0; k < preset_.sitters; ++k) {
    Person p;
    p.id = next_id++;
    p.track = &(*sitters_)[k % sitters_->size()];
    p.a = seats[k % 2];
    p.sitting = true;
    p.mirror = k % 2 == 1;
    p.height = p.track->height_m;
    p.phase = prng.uniform(0.0, 2 * kPi);
    people_.push_back(p);
  }
}

// The person's clothing pattern: a crop of a random photograph (its own random generator, so
// the other random choices stay those of sequences without detail), kDetailTexelsPerMetre
// unless the photograph is too small for the person's tallest and widest frame.
void SequenceGenerator::addDetail(Person& p) const {
  if (opt_.people_detail <= 0) return;
  cv::RNG rng(mix(opt_.seed, kDetailSeed + (uint64_t)p.id));
  const int ti = rng.uniform(0, (int)textures_.size());
  const Texture& tx = textures_[ti];
  double aspect = 0;
  for (const Sprite& sp : p.track->frames) aspect = std::max(aspect, (double)sp.bgra.cols / sp.bgra.rows);
  const double h_m = p.height * kMaxGaitStretch, w_m = h_m * aspect;
  const double tpm = std::min({kDetailTexelsPerMetre, tx.height() / h_m, tx.width() / w_m});
  const float w = (float)(w_m * tpm), h = (float)(h_m * tpm);
  p.detail_anchor = cv::Point2f(rng.uniform(0.5f * w, std::max(0.5f * w + 1e-3f, tx.width() - 0.5f * w)),
                                rng.uniform(h, std::max(h + 1e-3f, (float)tx.height())));
  p.detail_tpm = tpm;
  p.detail.texture = ti;
  p.detail.gain = (float)opt_.people_detail;
  const cv::Rect crop = cv::Rect((int)(p.detail_anchor.x - 0.5f * w), (int)(p.detail_anchor.y - h), (int)w, (int)h) &
                        cv::Rect(0, 0, tx.width(), tx.height());
  const cv::Scalar m = cv::mean(tx.levels[0](crop));
  p.detail.mean = (float)std::max(1.0, 0.114 * m[0] + 0.587 * m[1] + 0.299 * m[2]);
}

SequenceGenerator::PersonState SequenceGenerator::personAt(const Person& p, double t) const {
  PersonState st;
  st.anim_t = t + p.anim_phase;
  if (p.sitting) {
    st.pos = p.a;
  } else if (!p.schedule.empty()) {
    double walked = 0;
    scheduleState(p.schedule, t, st.pos, st.vel, st.heading, walked);
    st.anim_t = walked / kWalkSpeed + p.anim_phase;
  } else {
    Eigen::Vector3d d = p.b - p.a;
    double L = d.norm();
    double s = std::fmod(p.phase * 2 * L + t * p.speed, 2 * L);
    if (s < L) st.pos = p.a + d * (s / L), st.vel = d / L * p.speed;
    else st.pos = p.b - d * ((s - L) / L), st.vel = -d / L * p.speed;
    st.heading = st.vel.normalized();
  }
  return st;
}

// Billboard facing the camera (horizontally), standing on the floor.
Quad SequenceGenerator::personQuad(const Person& p, const PersonState& st, double t) const {
  Eigen::Vector3d pos = st.pos;
  if (p.sitting) pos += st.right * (0.03 * std::sin(2 * kPi * t / 5.0 + p.phase));
  size_t k = p.track->fps > 0 ? (size_t)std::floor(st.anim_t * p.track->fps) % p.track->frames.size() : 0;
  const Sprite& sp = p.track->frames[k];
  double hs = p.height * p.track->height_scale[k];
  if (p.sitting) hs *= 1.0 + 0.01 * std::sin(2 * kPi * t / 3.7 + p.phase);
  double ws = hs * sp.bgra.cols / sp.bgra.rows;
  Quad q;
  q.origin = pos - st.right * (0.5 * ws);
  q.edge_u = st.right * ws;
  q.edge_v = kUp * hs;
  q.sprite = &sp;
  q.object_id = p.id;
  // Sprites face +u: mirror when walking (or, standing, last walked) towards the image left.
  const Eigen::Vector3d& facing = st.vel.squaredNorm() > 0 ? st.vel : st.heading;
  bool mirror = p.sitting ? p.mirror : facing.dot(st.right) < 0;
  q.tex_rect = mirror ? cv::Rect2f((float)sp.bgra.cols, 0, -(float)sp.bgra.cols, (float)sp.bgra.rows)
                      : cv::Rect2f(0, 0, (float)sp.bgra.cols, (float)sp.bgra.rows);
  if (p.detail.texture >= 0) {
    // A fixed scale in texels per metre, so the pattern does not stretch with the gait.
    q.detail = p.detail;
    const float w = (float)(ws * p.detail_tpm), h = (float)(hs * p.detail_tpm);
    q.detail.tex_rect = cv::Rect2f(p.detail_anchor.x - 0.5f * w, p.detail_anchor.y - h, w, h);
  }
  return q;
}

// The box held at hip height in front of the body, on the side it walks towards; while it
// rests on the floor (before pick-up, after put-down) it is static scene (object id 0).
void SequenceGenerator::addBoxQuads(const Person& p, const PersonState& st, double t, std::vector<Quad>& out) const {
  const BoxMove& m = p.box_move;
  const double tb = std::min(std::max(t, m.pick_up), m.put_down);
  const PersonState sb = tb == t ? st : personAt(p, tb);
  const bool moving = t > m.pick_up && t < m.put_down;
  const double lift = liftFraction(m, tb);
  const double height = lift >= 1.0 ? kBoxCarryHeight : kBoxRestHeight + lift * (kBoxCarryHeight - kBoxRestHeight);
  Eigen::Vector3d dir = sb.heading.squaredNorm() > 0 ? sb.heading : st.right;
  Eigen::Vector3d side = kUp.cross(dir);
  Eigen::Vector3d c = sb.pos + dir * kBoxReach + kUp * height;
  Eigen::Vector3d ex = dir * 0.4, ey = side * 0.3, ez = kUp * 0.3;
  Eigen::Vector3d lo = c - 0.5 * (ex + ey + ez);
  auto face = [&](const Eigen::Vector3d& o, const Eigen::Vector3d& eu, const Eigen::Vector3d& ev) {
    Quad f;
    f.origin = o;
    f.edge_u = eu;
    f.edge_v = ev;
    f.texture = box_texture_;
    const Texture& tx = textures_[box_texture_];
    f.tex_rect = cv::Rect2f(0, 0, (float)tx.width() * 0.5f, (float)tx.height() * 0.5f);
    f.brightness = 0.9f;
    f.two_sided = false;
    f.object_id = moving ? p.box_id : 0;
    out.push_back(f);
  };
  // Outward normals (edge_u x edge_v) for back-face culling.
  face(lo, ex, ez);       // -ey
  face(lo + ey, ez, ex);  // +ey
  face(lo, ez, ey);       // -ex
  face(lo + ex, ey, ez);  // +ex
  face(lo + ez, ex, ey);  // +ez
  face(lo, ey, ex);       // -ez
}

std::vector<Quad> SequenceGenerator::dynamicQuads(double t, const Pose& T_wc) const {
  std::vector<Quad> out;
  const Eigen::Vector3d cam = T_wc.translation();
  for (const Person& p : people_) {
    PersonState st = personAt(p, t);
    Eigen::Vector3d n = cam - st.pos;
    n.z() = 0;
    if (n.norm() < 1e-6) continue;
    st.right = kUp.cross(n.normalized());
    out.push_back(personQuad(p, st, t));
    if (p.box_id > 0 && opt_.objects) addBoxQuads(p, st, t, out);
  }
  return out;
}

SynthFrame SequenceGenerator::frame(size_t i) const {
  if (i >= size()) throw Error("frame index " + std::to_string(i) + " out of range");
  SynthFrame f;
  f.index = i;
  f.rgb_stamp = rgb_stamps_[i];
  f.depth_stamp = depth_stamps_[i];
  const double t = f.rgb_stamp - t0_;
  f.T_wc = path_->at(t);
  std::vector<Quad> dyn = dynamicQuads(t, f.T_wc);
  std::vector<Quad> all = room_;
  all.insert(all.end(), dyn.begin(), dyn.end());
  RenderOutput ro;
  renderer_->render(f.T_wc, all, ro);
  f.depth_exact = ro.depth;
  f.ids = ro.ids;
  f.mask = cv::Mat::zeros(ro.ids.size(), CV_8U);
  f.mask.setTo(kMaskOtherObject, ro.ids > 0);
  for (const Person& p : people_) f.mask.setTo(kMaskPerson, ro.ids == p.id);

  // Per-object truth from the id buffer.
  std::vector<int> ids;
  for (const Quad& q : dyn)
    if (q.object_id > 0 && std::find(ids.begin(), ids.end(), q.object_id) == ids.end()) ids.push_back(q.object_id);
  for (int id : ids) {
    cv::Mat m = ro.ids == id;
    int px = cv::countNonZero(m);
    if (px < 20) continue;
    ObjectTruth o;
    o.id = id;
    o.cls = id >= 100 ? "box" : "person";
    o.box = cv::boundingRect(m);
    o.pixels = px;
    double full = renderer_->unoccludedArea(f.T_wc, dyn, id);
    o.visible_fraction = full > 0 ? std::min(1.0, px / full) : 0.0;
    f.objects.push_back(o);
  }

  cv::RNG rng(mix(opt_.seed, 1000 + i));
  f.bgr = ro.bgr;
  if (opt_.sensor.motion_blur && opt_.sensor.exposure > 0) {
    // Image motion of the point 2 m ahead during the exposure.
    Pose T_prev = path_->at(t - opt_.sensor.exposure / opt_.fps);
    Eigen::Vector3d Xw = f.T_wc * Eigen::Vector3d(0, 0, 2.0);
    Eigen::Vector3d pc = T_prev.inverse() * Xw;
    Eigen::Vector2d uv = opt_.camera.project(pc);
    cv::Point2f shift((float)(uv.x() - opt_.camera.cx), (float)(uv.y() - opt_.camera.cy));
    applyMotionBlur(f.bgr, shift);
  }
  if (opt_.sensor.noise) applyImageNoise(f.bgr, opt_.sensor.image_noise, rng);
  f.depth = applyDepthModel(ro.depth, opt_.sensor, rng);
  return f;
}

void SequenceGenerator::renderFrames(const std::string& out_dir, bool progress,
                                     std::vector<std::vector<ObjectTruth>>& objects, Trajectory& gt) const {
  const size_t n = size();
  std::atomic<size_t> next{0};
  std::mutex err_mu;  // guards first_error and the progress bar
  std::exception_ptr first_error;
  std::atomic<size_t> done{0};
  ProgressBar bar("synth " + preset_.name, n);
  const std::vector<int> png = {cv::IMWRITE_PNG_COMPRESSION, 1};
  auto work = [&]() {
    try {
      for (size_t i; (i = next++) < n;) {
        SynthFrame f = frame(i);
        const std::string rs = stampStr(f.rgb_stamp), ds = stampStr(f.depth_stamp);
        cv::Mat d16;
        f.depth.convertTo(d16, CV_16U, opt_.camera.depth_map_factor);
        const std::string rp = joinPath(out_dir, "rgb/" + rs + ".png");
        const std::string dp = joinPath(out_dir, "depth/" + ds + ".png");
        const std::string mp = joinPath(out_dir, "masks/" + rs + ".png");
        if (!cv::imwrite(rp, f.bgr, png) || !cv::imwrite(dp, d16, png) || !cv::imwrite(mp, f.mask, png))
          throw Error("cannot write frame " + rs + " into " + out_dir + ": check free space and permissions");
        objects[i] = f.objects;
        gt[i].stamp = f.rgb_stamp;
        gt[i].T_wc = f.T_wc;
        size_t d = ++done;
        if (progress && opt_.threads >= 1) {
          std::lock_guard<std::mutex> lock(err_mu);
          bar.update(d);
        }
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(err_mu);
      if (!first_error) first_error = std::current_exception();
      next = n;
    }
  };
  // OpenCV creates the operator object behind cv::Mat::zeros on first use, in code TSan does not
  // see; created here, before the workers start, no two workers race to create it.
  cv::Mat::zeros(1, 1, CV_8U).operator cv::Mat();
  std::vector<std::thread> pool;
  for (int k = 1; k < opt_.threads; ++k) pool.emplace_back(work);
  work();
  for (auto& th : pool) th.join();
  if (first_error) std::rethrow_exception(first_error);
  if (progress) bar.finish();
}

namespace {

std::unique_ptr<std::ofstream> openOutput(const std::string& out_dir, const std::string& name) {
  auto f = std::make_unique<std::ofstream>(joinPath(out_dir, name));
  if (!*f) throw Error("cannot write " + joinPath(out_dir, name) + ": check permissions");
  return f;
}

}  // namespace

void SequenceGenerator::writeLists(const std::string& out_dir, const std::string& src) const {
  const size_t n = size();
  {
    auto f = openOutput(out_dir, "rgb.txt");
    *f << "# color images\n# file: '" << src << "'\n# timestamp filename\n";
    for (size_t i = 0; i < n; ++i) *f << stampStr(rgb_stamps_[i]) << " rgb/" << stampStr(rgb_stamps_[i]) << ".png\n";
  }
  {
    auto f = openOutput(out_dir, "depth.txt");
    *f << "# depth maps\n# file: '" << src << "'\n# timestamp filename\n";
    for (size_t i = 0; i < n; ++i) *f << stampStr(depth_stamps_[i]) << " depth/" << stampStr(depth_stamps_[i]) << ".png\n";
  }
  // ORB-SLAM2's association format (no header: its reader does not skip comments).
  auto f = openOutput(out_dir, "associations.txt");
  for (size_t i = 0; i < n; ++i)
    *f << stampStr(rgb_stamps_[i]) << " rgb/" << stampStr(rgb_stamps_[i]) << ".png " << stampStr(depth_stamps_[i])
       << " depth/" << stampStr(depth_stamps_[i]) << ".png\n";
}

void SequenceGenerator::writeBoxes(const std::string& out_dir, const std::string& src,
                                   const std::vector<std::vector<ObjectTruth>>& objects) const {
  auto f = openOutput(out_dir, "boxes.txt");
  *f << "# dynamic objects per frame (" << src << ")\n"
     << "# box = visible pixels; x2 y2 exclusive; visible_fraction = visible / unoccluded unclipped area\n"
     << "# rgb_timestamp id class x1 y1 x2 y2 visible_fraction\n";
  char buf[256];
  for (size_t i = 0; i < objects.size(); ++i)
    for (const auto& o : objects[i]) {
      std::snprintf(buf, sizeof buf, "%s %d %s %d %d %d %d %.3f\n", stampStr(rgb_stamps_[i]).c_str(), o.id,
                    o.cls.c_str(), o.box.x, o.box.y, o.box.x + o.box.width, o.box.y + o.box.height,
                    o.visible_fraction);
      *f << buf;
    }
}

void SequenceGenerator::writeCameraAndInfo(const std::string& out_dir, const std::string& src) const {
  {
    const CameraModel& c = opt_.camera;
    auto f = openOutput(out_dir, "camera.yaml");
    char buf[2048];
    std::snprintf(buf, sizeof buf,
                  "%%YAML:1.0\n# Camera of a yolo_slam_synth sequence (%s): ORB-SLAM2 keys.\n"
                  "Camera.fx: %.6f\nCamera.fy: %.6f\nCamera.cx: %.6f\nCamera.cy: %.6f\n"
                  "Camera.k1: 0.0\nCamera.k2: 0.0\nCamera.p1: 0.0\nCamera.p2: 0.0\nCamera.k3: 0.0\n"
                  "Camera.width: %d\nCamera.height: %d\nCamera.fps: %.1f\nCamera.bf: %.6f\nCamera.RGB: 1\n"
                  "ThDepth: %.1f\nDepthMapFactor: %.1f\n"
                  "ORBextractor.nFeatures: 1000\nORBextractor.scaleFactor: 1.2\nORBextractor.nLevels: 8\n"
                  "ORBextractor.iniThFAST: 20\nORBextractor.minThFAST: 7\n",
                  src.c_str(), c.fx, c.fy, c.cx, c.cy, c.width, c.height, opt_.fps, c.bf, c.th_depth,
                  c.depth_map_factor);
    *f << buf;
  }
  auto f = openOutput(out_dir, "synth_info.txt");
  *f << "# how this sequence was made\ncommand: " << src << " --frames " << size() << "\n"
     << "description: " << preset_.description << "\ntrajectory: " << path_->name() << "\ntextures:";
  for (const auto& t : texture_files_) *f << " " << t;
  *f << "\n";
  for (const Person& p : people_) *f << "person " << p.id << ": " << p.track->source << "\n";
}

double SequenceGenerator::generate(const std::string& out_dir, bool progress) const {
  Stopwatch sw;
  makeDir(out_dir);
  for (const char* sub : {"rgb", "depth", "masks"}) makeDir(joinPath(out_dir, sub));
  std::vector<std::vector<ObjectTruth>> objects(size());
  Trajectory gt(size());
  renderFrames(out_dir, progress, objects, gt);
  const std::string src = "yolo_slam_synth --preset " + preset_.name + " --seed " + std::to_string(opt_.seed);
  writeLists(out_dir, src);
  writeBoxes(out_dir, src, objects);
  writeCameraAndInfo(out_dir, src);
  io::writeTrajectory(joinPath(out_dir, "groundtruth.txt"), gt);
  return sw.ms() / 1000.0;
}

}  // namespace sim
}  // namespace yolo_slam
