// Map ownership and graph consistency: keyframe/point erase keeps the covisibility graph, the
// spanning tree and the associations consistent; replaced points are followed; clear() frees.
#include "yolo_slam/slam/frame.h"
#include "yolo_slam/slam/keyframe.h"
#include "yolo_slam/slam/map.h"
#include "yolo_slam/slam/map_point.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <random>
#include <thread>

using namespace yolo_slam;
using namespace yolo_slam::slam;

namespace {

// A frame with n keypoints on a grid, random descriptors, all with depth 2 m.
Frame makeFrame(long id, int n, unsigned seed, double x_offset) {
  features::FeatureFrame ff;
  ff.stamp = id * 0.1;
  ff.width = 640;
  ff.height = 480;
  std::mt19937 rng(seed);
  ff.descriptors = cv::Mat(n, 32, CV_8U);
  for (int i = 0; i < n; ++i) {
    cv::KeyPoint kp(static_cast<float>(20 + (i % 30) * 20), static_cast<float>(20 + (i / 30) * 20), 31.f);
    kp.octave = i % 3;
    ff.keypoints.push_back(kp);
    for (int b = 0; b < 32; ++b) ff.descriptors.at<uint8_t>(i, b) = static_cast<uint8_t>(rng());
    ff.depth.push_back(2.f);
    ff.right_u.push_back(kp.pt.x - 20.f);
    ff.dynamic.push_back(0);
  }
  ff.keypoints_un = ff.keypoints;
  CameraModel cam;
  auto pyr = std::make_shared<ScalePyramid>(ScalePyramid::make(8, 1.2));
  Frame f(ff, cam, FrameGeometry::make(cam), pyr, id);
  Pose T = Pose::Identity();
  T.translation() = Eigen::Vector3d(-x_offset, 0, 0);
  f.setPose(T);
  return f;
}

struct Fixture {
  Map map;
  std::vector<KeyFramePtr> kfs;
  std::vector<MapPointPtr> points;
};

// Keyframe k observes points [10k, 10k + 60): neighbours share 50 points, next-but-one 40...
void build(Fixture& fx, int n_kf) {
  std::lock_guard<std::mutex> lk(fx.map.update_mutex);
  for (int k = 0; k < n_kf; ++k) {
    auto kf = std::make_shared<KeyFrame>(fx.map.newKeyFrameId(), makeFrame(k, 200, k + 1, 0.1 * k));
    fx.map.addKeyFrame(kf);
    fx.kfs.push_back(kf);
  }
  const int n_points = 10 * (n_kf - 1) + 60;
  for (int p = 0; p < n_points; ++p) {
    auto mp = std::make_shared<MapPoint>(fx.map.newPointId(), Eigen::Vector3d(0.01 * p, 0, 2), nullptr, 0);
    for (int k = 0; k < n_kf; ++k)
      if (p >= 10 * k && p < 10 * k + 60) Map::addObservation(mp, fx.kfs[k], p - 10 * k);
    mp->computeDistinctiveDescriptor();
    mp->updateNormalAndDepth();
    fx.map.addMapPoint(mp);
    fx.points.push_back(mp);
  }
  for (auto& kf : fx.kfs) kf->updateConnections();
}

void expectConsistent(const Map& map) {
  for (const auto& kf : map.keyframes()) {
    EXPECT_FALSE(kf->bad);
    for (const auto& c : kf->connections) {
      EXPECT_FALSE(c.first->bad) << "kf " << kf->id << " connected to erased kf " << c.first->id;
      EXPECT_EQ(c.first->weight(kf), c.second) << "asymmetric edge " << kf->id << "-" << c.first->id;
    }
    EXPECT_EQ(kf->connections.size(), kf->ordered_connections.size());
    if (kf->parent) {
      EXPECT_FALSE(kf->parent->bad);
      EXPECT_TRUE(kf->parent->children.count(kf.get()));
    }
    for (KeyFrame* ch : kf->children) EXPECT_EQ(ch->parent.get(), kf.get());
    for (size_t i = 0; i < kf->f.points.size(); ++i) {
      const auto& mp = kf->f.points[i];
      if (!mp) continue;
      EXPECT_FALSE(mp->bad);
      auto it = mp->observations.find(kf);
      ASSERT_NE(it, mp->observations.end());
      EXPECT_EQ(it->second, i);
    }
  }
  for (const auto& mp : map.mapPoints()) {
    EXPECT_FALSE(mp->bad);
    for (const auto& o : mp->observations) {
      EXPECT_FALSE(o.first->bad);
      EXPECT_EQ(o.first->f.points[o.second], mp);
    }
  }
}

}  // namespace

// A holder of the map lock hands it to a waiting Tracking between the parts of a step, and
// keeps it when nobody waits.
TEST(SlamMap, YieldToTrackingHandsTheLockOverOnlyWhenTrackingWaits) {
  Map map;
  std::unique_lock<std::mutex> mapper(map.update_mutex);
  map.yieldToTracking(mapper);  // nobody waits: a no-op
  EXPECT_TRUE(mapper.owns_lock());
  std::atomic<bool> tracked{false};
  std::thread tracking([&] {
    std::unique_lock<std::mutex> lk = map.lockForTracking();
    tracked = true;
  });
  // Until the mapper yields, Tracking waits; the yield returns only after Tracking's frame.
  while (!tracked) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    map.yieldToTracking(mapper);
  }
  EXPECT_TRUE(mapper.owns_lock());
  mapper.unlock();
  tracking.join();
}

TEST(SlamMap, CovisibilityWeightsAndTree) {
  Fixture fx;
  build(fx, 5);
  std::lock_guard<std::mutex> lk(fx.map.update_mutex);
  EXPECT_EQ(fx.kfs[1]->weight(fx.kfs[0]), 50);
  EXPECT_EQ(fx.kfs[1]->weight(fx.kfs[3]), 40);
  EXPECT_EQ(fx.kfs[0]->weight(fx.kfs[4]), 20);
  EXPECT_EQ(fx.kfs[2]->ordered_connections.front()->id == 1 || fx.kfs[2]->ordered_connections.front()->id == 3, true);
  EXPECT_TRUE(fx.kfs[0]->is_origin);
  EXPECT_FALSE(fx.kfs[0]->parent);
  for (int k = 1; k < 5; ++k) EXPECT_TRUE(fx.kfs[k]->parent) << k;
  expectConsistent(fx.map);
}

TEST(SlamMap, EraseKeyFrameKeepsGraphConsistent) {
  Fixture fx;
  build(fx, 6);
  std::lock_guard<std::mutex> lk(fx.map.update_mutex);
  // Make kf 2 the parent of several keyframes, then erase it.
  KeyFramePtr victim = fx.kfs[2];
  std::weak_ptr<KeyFrame> weak = victim;
  const size_t before = fx.map.numKeyFrames();
  const Pose T_cw = victim->Tcw();
  ASSERT_GT(victim->f.N, 0);
  fx.map.eraseKeyFrame(victim);
  EXPECT_TRUE(victim->bad);
  EXPECT_EQ(fx.map.numKeyFrames(), before - 1);
  // The trajectory keeps erased keyframes as anchors of relative poses: their features are freed,
  // the pose and the link to the parent stay.
  EXPECT_EQ(victim->f.N, 0);
  EXPECT_TRUE(victim->f.kps.empty());
  EXPECT_TRUE(victim->f.descriptors.empty());
  EXPECT_TRUE(victim->f.points.empty());
  EXPECT_TRUE(victim->f.featuresInArea(320, 240, 100).empty());
  EXPECT_TRUE(victim->Tcw().isApprox(T_cw));
  EXPECT_TRUE((victim->T_cp * victim->parent->Tcw()).isApprox(T_cw, 1e-9));
  for (const auto& kf : fx.map.keyframes()) EXPECT_EQ(kf->weight(victim), 0);
  expectConsistent(fx.map);
  // Every remaining non-origin keyframe still reaches the origin through the tree.
  for (const auto& kf : fx.map.keyframes()) {
    KeyFrame* k = kf.get();
    int steps = 0;
    while (k->parent && steps < 100) {
      k = k->parent.get();
      ++steps;
    }
    EXPECT_TRUE(k->is_origin) << "kf " << kf->id << " detached from the tree";
  }
  // The origin is never erased.
  fx.map.eraseKeyFrame(fx.kfs[0]);
  EXPECT_FALSE(fx.kfs[0]->bad);
  // Once nobody outside holds it, the erased keyframe is freed (no reference cycle left).
  fx.kfs.erase(fx.kfs.begin() + 2);
  victim.reset();
  EXPECT_TRUE(weak.expired());
}

TEST(SlamMap, ReplaceAndErasePoints) {
  Fixture fx;
  build(fx, 3);
  std::lock_guard<std::mutex> lk(fx.map.update_mutex);
  MapPointPtr a = fx.points[5];   // seen by kf 0 only
  MapPointPtr b = fx.points[15];  // seen by kf 0 and 1
  const size_t n = fx.map.numMapPoints();
  fx.map.replaceMapPoint(a, b);
  EXPECT_TRUE(a->bad);
  EXPECT_EQ(MapPoint::resolve(a), b);
  EXPECT_EQ(fx.map.numMapPoints(), n - 1);
  // b was already in kf 0, so a's slot there is emptied rather than duplicated.
  EXPECT_EQ(fx.kfs[0]->f.points[5], nullptr);
  expectConsistent(fx.map);

  // Erasing an observation of a point seen (with depth) by just two keyframes removes it.
  MapPointPtr c = fx.points[20];  // kf 0, 1, 2
  fx.map.eraseObservation(c, fx.kfs[2]);
  EXPECT_FALSE(c->bad);
  fx.map.eraseObservation(c, fx.kfs[1]);
  EXPECT_TRUE(c->bad);
  expectConsistent(fx.map);
}

TEST(SlamMap, ClearFreesEverything) {
  std::weak_ptr<KeyFrame> wk;
  std::weak_ptr<MapPoint> wp;
  {
    Fixture fx;
    build(fx, 4);
    wk = fx.kfs[1];
    wp = fx.points[12];
    std::lock_guard<std::mutex> lk(fx.map.update_mutex);
    fx.map.clear();
    EXPECT_EQ(fx.map.numKeyFrames(), 0u);
    EXPECT_EQ(fx.map.numMapPoints(), 0u);
  }
  EXPECT_TRUE(wk.expired());
  EXPECT_TRUE(wp.expired());
}

TEST(SlamFrame, GridSearchSkipsDynamic) {
  Frame f = makeFrame(0, 100, 3, 0);
  // Keypoint 0 is at (20, 20).
  auto idx = f.featuresInArea(20, 20, 5);
  ASSERT_EQ(idx.size(), 1u);
  EXPECT_EQ(idx[0], 0u);
  f.dynamic[0] = 1;
  // Frames are built once: rebuild with the dynamic flag set at construction.
  features::FeatureFrame ff;
  ff.keypoints = f.kps;
  ff.keypoints_un = f.kps;
  ff.descriptors = f.descriptors;
  ff.depth = f.depth;
  ff.right_u = f.right_u;
  ff.dynamic = f.dynamic;
  Frame g(ff, f.cam, f.geom, f.pyramid, 1);
  EXPECT_TRUE(g.featuresInArea(20, 20, 5).empty());
  EXPECT_EQ(g.featuresInArea(20, 20, 5, -1, -1, true).size(), 1u);
  EXPECT_EQ(g.countWithDepth(), 99);
}
