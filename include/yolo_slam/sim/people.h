#pragma once
// Real person imagery for the synthetic sequences: animated walking cut-outs segmented out of
// a real video of people walking past a static camera (background subtraction), and seated
// people cut out of real TUM frames with their mask and depth.
#include "yolo_slam/sim/renderer.h"

#include <memory>
#include <string>
#include <vector>

namespace yolo_slam {
namespace sim {

struct SpriteTrack {
  std::string source;           // where it came from (file and track/person)
  std::vector<Sprite> frames;   // one cut-out per video frame; walkers face right (+u)
  std::vector<float> height_scale;  // per frame: silhouette height / smoothed height (gait bob)
  double fps = 0;               // animation rate of `frames` (0: a still)
  double height_m = 0;          // real height of the cut-out in metres if known (TUM), else 0
  bool sitting = false;
};

// Default sources: opencv-doc's vtest.avi and the real fr3_walking_xyz frames in sharedDir().
std::string defaultWalkerVideo();
std::string defaultTumPeopleDir();

// Walkers of a video of people walking past a static camera: median background over sampled
// frames, foreground by colour difference and morphology, blobs linked frame to frame by
// position and size, and the longest clean runs (not touching the border, person-shaped, no
// merge with another blob) kept, largest people first. Deterministic. Throws
// yolo_slam::Error naming the video when it cannot be read or holds no usable walker.
std::vector<SpriteTrack> extractWalkers(const std::string& video_path, int max_tracks = 8);

// People fully inside the frame 1341846313.592026 of a TUM folder holding rgb/, depth/ and
// dynamic_mask/ (the seated person of fr3_walking_xyz), with their real depth as relief and
// their real height. Throws yolo_slam::Error naming the missing file.
std::vector<SpriteTrack> extractTumPeople(const std::string& tum_dir);

// Process-wide cache of the two extractions above (the video takes about two seconds).
std::shared_ptr<const std::vector<SpriteTrack>> cachedWalkers(const std::string& video_path);
std::shared_ptr<const std::vector<SpriteTrack>> cachedTumPeople(const std::string& tum_dir);

// A cut-out from a colour crop and its mask (255 inside); colour outside the mask is filled
// from the inside so bilinear sampling leaves no dark fringe. `relief` may be empty: a rounded
// body profile of `thickness_m` across each row's silhouette is used.
Sprite makeSprite(const cv::Mat& bgr, const cv::Mat& mask, const cv::Mat& relief, double thickness_m);

}  // namespace sim
}  // namespace yolo_slam
