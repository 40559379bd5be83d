#include "yolo_slam/common/settings_keys.h"

#include <algorithm>
#include <cctype>

namespace yolo_slam {
namespace {

// Sections of ORB-SLAM2 settings files that yolo_slam has no use for: accepted without a word,
// so ORB-SLAM2 users' files load unchanged.
const char* const kForeignPrefixes[] = {"Viewer."};

// Edit distance of the lower-cased names (a misspelt key differs in case as often as in letters).
size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diag = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      const bool same = std::tolower(static_cast<unsigned char>(a[i - 1])) ==
                        std::tolower(static_cast<unsigned char>(b[j - 1]));
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (same ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

}  // namespace

const std::vector<std::string>& knownSettingsKeys() {
  static const std::vector<std::string> keys = {
      "Camera.RGB",
      "Camera.bf",
      "Camera.cx",
      "Camera.cy",
      "Camera.fps",
      "Camera.fx",
      "Camera.fy",
      "Camera.height",
      "Camera.k1",
      "Camera.k2",
      "Camera.k3",
      "Camera.p1",
      "Camera.p2",
      "Camera.width",
      "DenseMap.cloudResolution",
      "DenseMap.enabled",
      "DenseMap.finalRebuild",
      "DenseMap.maskMargin",
      "DenseMap.maskPeople",
      "DenseMap.maskSampleStride",
      "DenseMap.maxRange",
      "DenseMap.pixelStride",
      "DenseMap.probHit",
      "DenseMap.probMiss",
      "DenseMap.queueSize",
      "DenseMap.resolution",
      "DenseMap.threadNice",
      "DepthMapFactor",
      "DepthMaxRange",
      "Detection.async",
      "Detection.asyncMaxLag",
      "Detection.asyncMinInterval",
      "Detection.asyncThreads",
      "Detection.maxAge",
      "Detection.threadNice",
      "Detector.confThreshold",
      "Detector.dynamicClasses",
      "Detector.extraModels",
      "Detector.inputHeight",
      "Detector.inputWidth",
      "Detector.letterbox",
      "Detector.model",
      "Detector.nmsThreshold",
      "Detector.threads",
      "LocalMapping.cullingRedundancy",
      "LocalMapping.freeSpaceRatio",
      "LocalMapping.fuseNeighbours",
      "LocalMapping.localBA",
      "LocalMapping.queueSize",
      "LocalMapping.threadNice",
      "LocalMapping.triangulationNeighbours",
      "LoopClosing.consistency",
      "LoopClosing.covisibilityWeight",
      "LoopClosing.enabled",
      "LoopClosing.globalBA",
      "LoopClosing.globalBAIterations",
      "LoopClosing.maxCorrectionDeg",
      "LoopClosing.maxCorrectionM",
      "LoopClosing.minBowMatches",
      "LoopClosing.minKeyFrames",
      "LoopClosing.minMatches",
      "LoopClosing.minRansacInliers",
      "LoopClosing.minScore",
      "LoopClosing.poseGraphIterations",
      "LoopClosing.threadNice",
      "ORBextractor.dynamicBoostMax",
      "ORBextractor.iniThFAST",
      "ORBextractor.minThFAST",
      "ORBextractor.nFeatures",
      "ORBextractor.nLevels",
      "ORBextractor.scaleFactor",
      "ORBextractor.threads",
      "Screening.boxDilation",
      "Screening.clusterMinFraction",
      "Screening.dilationDepthOnly",
      "Screening.flatBoxFraction",
      "Screening.flatBoxRing",
      "Screening.flatBoxTolerance",
      "Screening.growDepth",
      "Screening.growOutside",
      "Screening.growRadius",
      "Screening.maskInBoxes",
      "Screening.maxIterations",
      "Screening.mode",
      "Screening.motionFlowTolerance",
      "Screening.motionMinResidual",
      "Screening.motionMinShare",
      "Screening.motionMinSupport",
      "Screening.motionScreening",
      "Screening.motionSupportDepth",
      "Screening.motionSupportRadius",
      "Screening.noDepth",
      "Screening.noDepthHoleRadius",
      "Screening.noDepthProbeRadius",
      "Screening.noDepthRadius",
      "Screening.occlusionMaxIou",
      "Screening.occlusionRule",
      "Screening.probability",
      "Screening.propagateLabels",
      "Screening.propagateMaxAge",
      "Screening.rejectFlatBoxes",
      "Screening.seed",
      "Screening.silhouetteRadius",
      "Screening.staticBoxFraction",
      "Screening.staticBoxMaxScore",
      "Screening.staticBoxMinPoints",
      "Screening.staticBoxVeto",
      "Screening.temporalMaxDepthChange",
      "Screening.temporalMaxHamming",
      "Screening.temporalRadius",
      "Screening.temporalStaticTolerance",
      "Screening.trackBoxes",
      "Screening.trackMaxAge",
      "Screening.trackMaxHamming",
      "Screening.trackMinMatches",
      "Screening.trackMinScore",
      "Screening.trackShiftStale",
      "Screening.trackNearFraction",
      "Screening.trackNearMaxAge",
      "Screening.trackRadius",
      "Screening.varianceThreshold",
      "Screening.variant",
      "Synth.depthNoiseA",
      "Synth.depthNoiseB",
      "Synth.exposure",
      "Synth.fps",
      "Synth.frames",
      "Synth.holeRate",
      "Synth.imageNoise",
      "Synth.maxDepth",
      "Synth.minDepth",
      "Synth.motionBlur",
      "Synth.noise",
      "Synth.objects",
      "Synth.peopleDetail",
      "Synth.preset",
      "Synth.seed",
      "Synth.textures",
      "Synth.threads",
      "Synth.trajectory",
      "System.sequential",
      "System.youngMapSync",
      "ThDepth",
      "Tracking.closeMinFrames",
      "Tracking.closeTrackedMax",
      "Tracking.closeUntrackedMin",
      "Tracking.initMinDepthPoints",
      "Tracking.initMinKeyPoints",
      "Tracking.keyFramePoints",
      "Tracking.localMapFromPrediction",
      "Tracking.localWindow",
      "Tracking.lostResetFrames",
      "Tracking.lostResetMaxKeyFrames",
      "Tracking.maxFrames",
      "Tracking.maxJump",
      "Tracking.maxJumpDeg",
      "Tracking.maxJumpInliers",
      "Tracking.maxJumpLocalization",
      "Tracking.maxStampGap",
      "Tracking.minFrames",
      "Tracking.motionPrior",
      "Tracking.motionPriorDeg",
      "Tracking.motionPriorFrames",
      "Tracking.minInliers",
      "Tracking.relocMargin",
      "Tracking.relocMaxSpeed",
      "Tracking.relocMinInliers",
      "Tracking.motionWindow",
      "Tracking.refRatio",
      "Tracking.voBelowMapPoints",
      "Tracking.voPoints",
      "Tracking.youngLostResetFrames",
      "Tracking.youngMapFrames",
      "Tracking.youngPointCheck",
      "Tracking.boxedPointsStaticOnly",
      "Tracking.movedPointsWithheld",
      "Tracking.droppedMapMatches",
  };
  return keys;
}

bool isKnownSettingsKey(const std::string& key) {
  const auto& keys = knownSettingsKeys();
  if (std::find(keys.begin(), keys.end(), key) != keys.end()) return true;
  for (const char* prefix : kForeignPrefixes)
    if (key.rfind(prefix, 0) == 0) return true;
  return false;
}

std::string nearestSettingsKey(const std::string& key) {
  std::string best;
  size_t best_d = 0;
  for (const std::string& k : knownSettingsKeys()) {
    const size_t d = editDistance(key, k);
    if (best.empty() || d < best_d) {
      best = k;
      best_d = d;
    }
  }
  return best;
}

}  // namespace yolo_slam
