// Every settings key read into its field: a YAML with every key of config/TUM3.yaml set to a
// valid non-default value loads into SystemOptions, DetectorOptions and CameraModel, and each
// field holds its value. Then each options struct rejects representative bad values with
// "<file>: key '<Key>' must be <rule> (got <value>)".
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"
#include "yolo_slam/detection/async_detector.h"
#include "yolo_slam/detection/detector.h"
#include "yolo_slam/slam/system.h"

#include <gtest/gtest.h>

#include <opencv2/core/persistence.hpp>

#include <set>
#include <tuple>

using namespace yolo_slam;

namespace {

const char* const kEveryKey = R"(%YAML:1.0
Camera.fx: 517.5
Camera.fy: 516.25
Camera.cx: 318.75
Camera.cy: 255.5
Camera.k1: 0.25
Camera.k2: -0.75
Camera.p1: -0.0078125
Camera.p2: 0.001953125
Camera.k3: 1.125
Camera.width: 800
Camera.height: 600
Camera.fps: 15.0
Camera.bf: 35.5
Camera.RGB: 0
ThDepth: 35.0
DepthMapFactor: 1000.0
DepthMaxRange: 8.5
ORBextractor.nFeatures: 1500
ORBextractor.scaleFactor: 1.25
ORBextractor.nLevels: 6
ORBextractor.iniThFAST: 18
ORBextractor.minThFAST: 6
ORBextractor.dynamicBoostMax: 1.5
ORBextractor.threads: 1
Detector.model: "/tmp/ys_model"
Detector.extraModels: [ "/tmp/ys_extra_a", "/tmp/ys_extra_b" ]
Detector.inputWidth: 320
Detector.inputHeight: 256
Detector.letterbox: 0
Detector.confThreshold: 0.375
Detector.nmsThreshold: 0.5
Detector.threads: 3
Detector.dynamicClasses: [ "person" ]
Detection.async: 1
Detection.maxAge: 0.375
Detection.asyncThreads: 2
Detection.asyncMinInterval: 0.05
Detection.threadNice: 2
Detection.asyncMaxLag: 5
Screening.mode: "detect"
Screening.variant: "grow"
Screening.varianceThreshold: 0.03125
Screening.probability: 0.9375
Screening.maxIterations: 300
Screening.seed: 7
Screening.noDepth: "nearest"
Screening.noDepthRadius: 35
Screening.silhouetteRadius: 3
Screening.boxDilation: 0.125
Screening.growRadius: 25
Screening.growDepth: 0.1875
Screening.clusterMinFraction: 0.375
Screening.dilationDepthOnly: 1
Screening.rejectFlatBoxes: 1
Screening.flatBoxFraction: 0.5
Screening.flatBoxTolerance: 0.015625
Screening.flatBoxRing: 0.375
Screening.occlusionRule: 0
Screening.occlusionMaxIou: 0.375
Screening.growOutside: 0.375
Screening.maskInBoxes: 1
Screening.noDepthHoleRadius: 12.5
Screening.noDepthProbeRadius: 6.5
Screening.trackBoxes: 0
Screening.trackMaxAge: 4
Screening.trackRadius: 35.5
Screening.trackMaxHamming: 45
Screening.trackMinMatches: 6
Screening.trackMinScore: 0.625
Screening.trackShiftStale: 0
Screening.trackNearFraction: 0.625
Screening.trackNearMaxAge: 21
Screening.staticBoxVeto: 0
Screening.staticBoxMaxScore: 0.75
Screening.staticBoxFraction: 0.625
Screening.staticBoxMinPoints: 12
Screening.propagateLabels: 1
Screening.propagateMaxAge: 2
Screening.temporalRadius: 25.5
Screening.temporalMaxHamming: 40
Screening.temporalMaxDepthChange: 0.25
Screening.temporalStaticTolerance: 2.5
Screening.motionScreening: 0
Screening.motionMinResidual: 7.5
Screening.motionSupportRadius: 35
Screening.motionMinSupport: 4
Screening.motionMinShare: 0.625
Screening.motionSupportDepth: 0.25
Screening.motionFlowTolerance: 3.5
Tracking.initMinKeyPoints: 400
Tracking.initMinDepthPoints: 80
Tracking.motionWindow: 12
Tracking.localWindow: 4
Tracking.minInliers: 25
Tracking.relocMinInliers: 40
Tracking.maxFrames: 20
Tracking.minFrames: 2
Tracking.refRatio: 0.875
Tracking.closeTrackedMax: 90
Tracking.closeUntrackedMin: 60
Tracking.closeMinFrames: 7
Tracking.keyFramePoints: 150
Tracking.lostResetFrames: 120
Tracking.lostResetMaxKeyFrames: 4
Tracking.youngMapFrames: 45
Tracking.youngLostResetFrames: 3
Tracking.voPoints: 80
Tracking.voBelowMapPoints: 40
Tracking.motionPrior: 0.03125
Tracking.motionPriorDeg: 1.5
Tracking.motionPriorFrames: 6
Tracking.maxJump: 0.125
Tracking.maxJumpDeg: 7.5
Tracking.maxJumpInliers: 90
Tracking.maxJumpLocalization: 0.0625
Tracking.maxStampGap: 0.5
Tracking.relocMaxSpeed: 0.75
Tracking.relocMargin: 0.25
Tracking.localMapFromPrediction: 0
Tracking.youngPointCheck: 0
Tracking.boxedPointsStaticOnly: 0
Tracking.movedPointsWithheld: 0
Tracking.droppedMapMatches: 5
LocalMapping.triangulationNeighbours: 12
LocalMapping.fuseNeighbours: 8
LocalMapping.cullingRedundancy: 0.875
LocalMapping.freeSpaceRatio: 0.25
LocalMapping.localBA: 0
LocalMapping.queueSize: 4
LocalMapping.threadNice: 3
LoopClosing.enabled: 0
LoopClosing.minScore: 0.0625
LoopClosing.consistency: 4
LoopClosing.minKeyFrames: 12
LoopClosing.minBowMatches: 25
LoopClosing.minRansacInliers: 22
LoopClosing.minMatches: 45
LoopClosing.maxCorrectionM: 0.375
LoopClosing.maxCorrectionDeg: 15.0
LoopClosing.covisibilityWeight: 80
LoopClosing.poseGraphIterations: 25
LoopClosing.globalBA: 0
LoopClosing.globalBAIterations: 8
LoopClosing.threadNice: 4
System.sequential: 1
System.youngMapSync: 0
DenseMap.enabled: 1
DenseMap.resolution: 0.125
DenseMap.maxRange: 3.5
DenseMap.pixelStride: 3
DenseMap.cloudResolution: 0.03125
DenseMap.probHit: 0.75
DenseMap.probMiss: 0.375
DenseMap.queueSize: 5
DenseMap.threadNice: 6
DenseMap.finalRebuild: 0
DenseMap.maskPeople: 0
DenseMap.maskMargin: 9
DenseMap.maskSampleStride: 2
)";

std::set<std::string> topLevelKeys(const cv::FileStorage& fs) {
  std::set<std::string> keys;
  for (const auto& k : fs.root().keys()) keys.insert(k);
  return keys;
}

// Every options struct of the settings file but the camera, whose intrinsics have no default.
void loadOptions(const Config& cfg) {
  slam::SystemOptions::load(cfg);
  detection::DetectorOptions::load(cfg);
  detection::AsyncDetectionOptions::load(cfg);
}

const std::string kTum3 = joinPath(YOLO_SLAM_SOURCE_DIR, "config/TUM3.yaml");

}  // namespace

TEST(Options, TheTestYamlSetsEveryKeyOfTum3) {
  cv::FileStorage tum3(kTum3, cv::FileStorage::READ);
  cv::FileStorage every(kEveryKey, cv::FileStorage::READ | cv::FileStorage::MEMORY);
  ASSERT_TRUE(tum3.isOpened());
  std::set<std::string> expected = topLevelKeys(tum3);
  expected.insert("Detector.extraModels");  // documented in TUM3.yaml, absent there
  EXPECT_EQ(topLevelKeys(every), expected);
}

TEST(Options, EveryKeyIsReadAndDiffersFromItsDefault) {
  const Config cfg = Config::fromString(kEveryKey, "every_key.yaml");
  CameraModel::load(cfg);
  loadOptions(cfg);
  const Config none;
  loadOptions(none);
  const Json got = cfg.effective(), def = none.effective();
  cv::FileStorage every(kEveryKey, cv::FileStorage::READ | cv::FileStorage::MEMORY);
  for (const std::string& key : topLevelKeys(every)) {
    ASSERT_TRUE(got.contains(key)) << key << " is not read by any loader";
    if (def.contains(key)) {
      EXPECT_NE(got[key], def[key]) << key << " keeps its default";
    }
  }
}

// The values of kEveryKey are exact in binary, so fields compare with ==.
TEST(Options, EveryFieldHoldsItsValue) {
  const Config cfg = Config::fromString(kEveryKey, "every_key.yaml");
  const CameraModel c = CameraModel::load(cfg);
  EXPECT_EQ(std::tie(c.fx, c.fy, c.cx, c.cy), std::make_tuple(517.5, 516.25, 318.75, 255.5));
  EXPECT_EQ(std::tie(c.k1, c.k2, c.p1, c.p2, c.k3),
            std::make_tuple(0.25, -0.75, -0.0078125, 0.001953125, 1.125));
  EXPECT_EQ(std::tie(c.width, c.height, c.fps, c.bf, c.rgb_order, c.th_depth, c.depth_map_factor, c.max_depth),
            std::make_tuple(800, 600, 15.0, 35.5, false, 35.0, 1000.0, 8.5));

  const slam::SystemOptions sys = slam::SystemOptions::load(cfg);
  const features::OrbOptions& orb = sys.orb;
  EXPECT_EQ(std::tie(orb.n_features, orb.scale_factor, orb.n_levels, orb.ini_th_fast, orb.min_th_fast),
            std::make_tuple(1500, 1.25, 6, 18, 6));
  EXPECT_DOUBLE_EQ(orb.dynamic_boost_max, 1.5);
  EXPECT_EQ(orb.threads, 1);
  EXPECT_TRUE(sys.sequential);
  EXPECT_FALSE(sys.young_map_sync);
  const mapping::DenseMapOptions& dm = sys.dense;
  EXPECT_EQ(std::tie(dm.enabled, dm.resolution_m, dm.max_range_m, dm.pixel_stride, dm.cloud_resolution_m),
            std::make_tuple(true, 0.125, 3.5, 3, 0.03125));
  EXPECT_EQ(std::tie(dm.prob_hit, dm.prob_miss, dm.queue_size, dm.final_rebuild, dm.mask_people, dm.mask.margin_px,
                     dm.mask.sample_stride_px),
            std::make_tuple(0.75, 0.375, 5, false, false, 9, 2));
  EXPECT_EQ(dm.thread_nice, 6);

  const detection::DetectorOptions d = detection::DetectorOptions::load(cfg);
  EXPECT_EQ(d.model, "/tmp/ys_model");
  EXPECT_EQ(d.extra_models, (std::vector<std::string>{"/tmp/ys_extra_a", "/tmp/ys_extra_b"}));
  EXPECT_EQ(std::tie(d.input_width, d.input_height, d.letterbox, d.conf_threshold, d.nms_threshold, d.threads),
            std::make_tuple(320, 256, false, 0.375f, 0.5f, 3));
  EXPECT_EQ(d.dynamic_classes, std::vector<std::string>{"person"});
  const detection::AsyncDetectionOptions a = detection::AsyncDetectionOptions::load(cfg);
  EXPECT_EQ(std::tie(a.enabled, a.max_age_s, a.threads, a.min_interval_s, a.thread_nice, a.max_lag_frames),
            std::make_tuple(true, 0.375, 2, 0.05, 2, 5));

  const screening::ScreeningOptions& s = sys.screening;
  using screening::DynamicMode;
  using screening::ScreeningVariant;
  using NoDepth = screening::ScreeningOptions::NoDepthRule;
  EXPECT_EQ(std::tie(s.mode, s.variant, s.variance_threshold_m2, s.probability, s.max_iterations, s.seed),
            std::make_tuple(DynamicMode::Detect, ScreeningVariant::Grow, 0.03125, 0.9375, 300, 7u));
  EXPECT_EQ(std::tie(s.no_depth, s.no_depth_radius_px, s.silhouette_radius_px, s.box_dilation),
            std::make_tuple(NoDepth::Nearest, 35.0, 3.0, 0.125));
  EXPECT_EQ(std::tie(s.grow_radius_px, s.grow_depth_m, s.cluster_min_fraction, s.dilation_depth_only),
            std::make_tuple(25.0, 0.1875, 0.375, true));
  EXPECT_EQ(std::tie(s.occlusion_rule, s.occlusion_max_iou), std::make_tuple(false, 0.375));
  EXPECT_EQ(std::tie(s.grow_outside, s.no_depth_hole_radius_px, s.no_depth_probe_radius_px),
            std::make_tuple(0.375, 12.5, 6.5));
  EXPECT_TRUE(s.mask_in_boxes);
  EXPECT_EQ(std::tie(s.reject_flat_boxes, s.flat_box_fraction, s.flat_box_tolerance, s.flat_box_ring),
            std::make_tuple(true, 0.5, 0.015625, 0.375));
  const screening::BoxTrackerOptions& t = s.tracker;
  EXPECT_EQ(std::tie(t.enabled, t.max_age, t.radius_px, t.max_hamming, t.min_matches, t.min_score, t.shift_stale),
            std::make_tuple(false, 4, 35.5, 45, 6, 0.625, false));
  EXPECT_EQ(t.near_fraction, 0.625);
  EXPECT_EQ(t.near_max_age, 21);
  const screening::TemporalOptions& m = s.temporal;
  EXPECT_EQ(std::tie(m.static_box_veto, m.static_box_max_score, m.static_box_fraction, m.static_box_min_points),
            std::make_tuple(false, 0.75, 0.625, 12));
  EXPECT_EQ(std::tie(m.propagate_labels, m.propagate_max_age), std::make_tuple(true, 2));
  EXPECT_EQ(std::tie(m.radius_px, m.max_hamming, m.max_depth_change_m, m.static_tolerance_px),
            std::make_tuple(25.5, 40, 0.25, 2.5));
  EXPECT_EQ(std::tie(m.motion_screening, m.motion_min_residual_px, m.motion_support_radius_px, m.motion_min_support),
            std::make_tuple(false, 7.5, 35.0, 4));
  EXPECT_EQ(std::tie(m.motion_min_share, m.motion_support_depth_m, m.motion_flow_tolerance_px),
            std::make_tuple(0.625, 0.25, 3.5));

  const slam::TrackingOptions& k = sys.slam.tracking;
  EXPECT_EQ(std::tie(k.init_min_keypoints, k.init_min_depth_points, k.motion_window, k.local_window, k.min_inliers),
            std::make_tuple(400, 80, 12, 4, 25));
  EXPECT_EQ(std::tie(k.max_frames_between_kf, k.min_frames_between_kf, k.ref_ratio, k.close_tracked_max,
                     k.close_untracked_min, k.close_min_frames),
            std::make_tuple(20, 2, 0.875, 90, 60, 7));
  EXPECT_EQ(std::tie(k.lost_reset_frames, k.lost_reset_max_keyframes, k.vo_points, k.max_stamp_gap,
                     k.local_map_from_prediction, k.young_point_check, k.boxed_points_static_only),
            std::make_tuple(120, 4, 80, 0.5, false, false, false));
  EXPECT_FALSE(k.moved_points_withheld);
  EXPECT_EQ(std::tie(k.young_map_frames, k.young_lost_reset_frames, k.keyframe_points, k.reloc_min_inliers),
            std::make_tuple(45, 3, 150, 40));
  EXPECT_EQ(k.vo_below_map_points, 40);
  EXPECT_EQ(k.dropped_map_matches, 5);
  EXPECT_EQ(std::tie(k.motion_prior, k.motion_prior_deg, k.max_jump, k.max_jump_deg, k.max_jump_inliers),
            std::make_tuple(0.03125, 1.5, 0.125, 7.5, 90));
  EXPECT_EQ(k.max_jump_localization, 0.0625);
  EXPECT_EQ(std::tie(k.reloc_max_speed, k.reloc_margin), std::make_tuple(0.75, 0.25));
  EXPECT_EQ(k.motion_prior_frames, 6);
  const slam::LocalMappingOptions& p = sys.slam.mapping;
  EXPECT_EQ(std::tie(p.triangulation_neighbours, p.fuse_neighbours, p.culling_redundancy, p.local_ba, p.queue_size,
                     p.thread_nice, p.free_space_ratio),
            std::make_tuple(12, 8, 0.875, false, 4, 3, 0.25));
  const slam::LoopClosingOptions& l = sys.slam.loop;
  EXPECT_EQ(std::tie(l.enabled, l.min_score, l.consistency, l.min_keyframes, l.min_bow_matches),
            std::make_tuple(false, 0.0625, 4, 12, 25));
  EXPECT_EQ(std::tie(l.min_ransac_inliers, l.min_matches, l.max_correction_m, l.max_correction_deg),
            std::make_tuple(22, 45, 0.375, 15.0));
  EXPECT_EQ(std::tie(l.covisibility_weight, l.pose_graph_iterations, l.global_ba, l.global_ba_iterations,
                     l.thread_nice),
            std::make_tuple(80, 25, false, 8, 4));
}

TEST(Options, TheShippedSettingsLoadWithTheDefaults) {
  const Config tum3 = Config::fromFile(kTum3);
  loadOptions(tum3);
  const Config none;
  loadOptions(none);
  const Json got = tum3.effective(), def = none.effective();
  for (const auto& kv : def.items()) {
    const Json& g = got[kv.key()];
    if (g.is_number_float() && kv.value().is_number_float())  // float fields read back as double
      EXPECT_NEAR(g.get<double>(), kv.value().get<double>(), 1e-6) << kv.key();
    else
      EXPECT_EQ(g, kv.value()) << kv.key() << ": TUM3.yaml differs from the default";
  }
}

// ---- Rejections: one message format, naming file and key -------------------------------

namespace {

// The message of loading `load` from a YAML with `key: value`, or "" if it loads.
template <class Load>
std::string rejection(const std::string& key, const std::string& value, Load load) {
  try {
    load(Config::fromString(key + ": " + value + "\n", "bad.yaml"));
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

std::string systemRejection(const std::string& key, const std::string& value) {
  return rejection(key, value, [](const Config& c) { slam::SystemOptions::load(c); });
}

std::string detectorRejection(const std::string& key, const std::string& value) {
  return rejection(key, value, [](const Config& c) { detection::DetectorOptions::load(c); });
}

}  // namespace

TEST(Options, RejectionsNameFileKeyRuleAndValue) {
  EXPECT_EQ(systemRejection("Tracking.minInliers", "5"),
            "bad.yaml: key 'Tracking.minInliers' must be >= 6 (got 5)");
  EXPECT_EQ(systemRejection("Tracking.refRatio", "1.5"),
            "bad.yaml: key 'Tracking.refRatio' must be in [0, 1] (got 1.5)");
  EXPECT_EQ(systemRejection("Tracking.motionPriorFrames", "0"),
            "bad.yaml: key 'Tracking.motionPriorFrames' must be in [1, 30] (got 0)");
  EXPECT_EQ(systemRejection("LocalMapping.queueSize", "0"),
            "bad.yaml: key 'LocalMapping.queueSize' must be >= 1 (got 0)");
  EXPECT_EQ(systemRejection("LocalMapping.threadNice", "20"),
            "bad.yaml: key 'LocalMapping.threadNice' must be in [0, 19] (got 20)");
  EXPECT_EQ(systemRejection("LoopClosing.maxCorrectionDeg", "190"),
            "bad.yaml: key 'LoopClosing.maxCorrectionDeg' must be in [0, 180] (got 190)");
  EXPECT_EQ(systemRejection("ORBextractor.scaleFactor", "1.0"),
            "bad.yaml: key 'ORBextractor.scaleFactor' must be in (1, 4] (got 1)");
  EXPECT_EQ(systemRejection("ORBextractor.minThFAST", "25"),
            "bad.yaml: key 'ORBextractor.minThFAST' must be in [1, iniThFAST = 20] (got 25)");
  EXPECT_EQ(systemRejection("Screening.probability", "1"),
            "bad.yaml: key 'Screening.probability' must be in (0, 1) (got 1)");
  EXPECT_EQ(systemRejection("Screening.seed", "-1"),
            "bad.yaml: key 'Screening.seed' must be >= 0 (got -1)");
  EXPECT_EQ(systemRejection("Screening.varianceThreshold", "0"),
            "bad.yaml: key 'Screening.varianceThreshold' must be > 0 (got 0)");
  EXPECT_EQ(systemRejection("Screening.clusterMinFraction", "0"),
            "bad.yaml: key 'Screening.clusterMinFraction' must be in (0, 1] (got 0)");
  EXPECT_EQ(systemRejection("DenseMap.resolution", "0"),
            "bad.yaml: key 'DenseMap.resolution' must be > 0 (got 0)");
  EXPECT_EQ(systemRejection("DenseMap.probMiss", "0.6"),
            "bad.yaml: key 'DenseMap.probMiss' must be in (0, 0.5) (got 0.6)");
  EXPECT_EQ(systemRejection("DenseMap.pixelStride", "0"),
            "bad.yaml: key 'DenseMap.pixelStride' must be >= 1 (got 0)");
  EXPECT_EQ(systemRejection("Screening.mode", "sometimes"),
            "bad.yaml: key 'Screening.mode' must be one of off, detect, geometry, detect+geometry "
            "(got 'sometimes')");
  EXPECT_EQ(systemRejection("Screening.noDepth", "maybe"),
            "bad.yaml: key 'Screening.noDepth' must be one of dynamic, static, nearest, "
            "near-dynamic (got 'maybe')");
  EXPECT_EQ(systemRejection("Screening.trackMaxAge", "0"),
            "bad.yaml: key 'Screening.trackMaxAge' must be >= 1 (got 0)");
  EXPECT_EQ(systemRejection("Screening.trackMaxHamming", "300"),
            "bad.yaml: key 'Screening.trackMaxHamming' must be in [0, 256] (got 300)");
  EXPECT_EQ(systemRejection("Screening.staticBoxFraction", "1.2"),
            "bad.yaml: key 'Screening.staticBoxFraction' must be in (0, 1] (got 1.2)");
  EXPECT_EQ(systemRejection("Screening.temporalStaticTolerance", "-1"),
            "bad.yaml: key 'Screening.temporalStaticTolerance' must be >= 0 (got -1)");
  EXPECT_EQ(detectorRejection("Detector.confThreshold", "1"),
            "bad.yaml: key 'Detector.confThreshold' must be in (0, 1) (got 1)");
  EXPECT_EQ(detectorRejection("Detector.threads", "0"),
            "bad.yaml: key 'Detector.threads' must be in [1, 64] (got 0)");
  EXPECT_EQ(detectorRejection("Detector.inputWidth", "100"),
            "bad.yaml: key 'Detector.inputWidth' must be a multiple of 32 (got 100)");
  EXPECT_EQ(rejection("Detection.maxAge", "-1", [](const Config& c) { detection::AsyncDetectionOptions::load(c); }),
            "bad.yaml: key 'Detection.maxAge' must be >= 0 (got -1)");
  EXPECT_EQ(detectorRejection("Detector.dynamicClasses", "[]"),
            "bad.yaml: key 'Detector.dynamicClasses' must be a list of at least one class name (got [])");
}

TEST(Options, ValidateAppliesTheLoadersRules) {
  auto message = [](auto&& validate) {
    try {
      validate();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  screening::ScreeningOptions s;
  EXPECT_EQ(message([&] { s.validate(); }), "");
  s.tracker.max_age = 0;
  EXPECT_EQ(message([&] { s.validate(); }),
            "ScreeningOptions: key 'Screening.trackMaxAge' must be >= 1 (got 0)");
  s = screening::ScreeningOptions();
  s.temporal.radius_px = 0;
  EXPECT_EQ(message([&] { s.validate(); }),
            "ScreeningOptions: key 'Screening.temporalRadius' must be > 0 (got 0)");
  s = screening::ScreeningOptions();
  s.box_dilation = 2;
  EXPECT_EQ(message([&] { s.validate(); }),
            "ScreeningOptions: key 'Screening.boxDilation' must be in [0, 1] (got 2)");
  features::OrbOptions o;
  o.n_levels = 40;
  EXPECT_EQ(message([&] { o.validate(); }),
            "OrbOptions: key 'ORBextractor.nLevels' must be in [1, 32] (got 40)");
}
