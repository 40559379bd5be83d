#include "yolo_slam/sim/people.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>

namespace yolo_slam {
namespace sim {

std::string defaultWalkerVideo() { return "/usr/share/doc/opencv-doc/examples/data/vtest.avi"; }
std::string defaultTumPeopleDir() {
  return joinPath(sharedDir(), "data/tum/rgbd_dataset_freiburg3_walking_xyz");
}

Sprite makeSprite(const cv::Mat& bgr, const cv::Mat& mask, const cv::Mat& relief, double thickness_m) {
  Sprite s;
  // Fill the colour outside the mask with a normalised blur of the inside.
  cv::Mat m;
  mask.convertTo(m, CV_32F, 1.0 / 255);
  cv::Mat col;
  bgr.convertTo(col, CV_32FC3);
  std::vector<cv::Mat> ch;
  cv::split(col, ch);
  cv::Mat mb;
  cv::blur(m, mb, cv::Size(9, 9));
  for (auto& c : ch) {
    cv::Mat cb;
    cv::blur(c.mul(m), cb, cv::Size(9, 9));
    cv::Mat fill = cb / cv::max(mb, 1e-3f);
    fill.copyTo(c, mask == 0);
  }
  cv::Mat alpha;
  cv::GaussianBlur(mask, alpha, cv::Size(3, 3), 0);
  ch.push_back(alpha);
  for (auto& c : ch) c.convertTo(c, CV_8U);
  cv::merge(ch, s.bgra);

  if (!relief.empty()) {
    s.relief = relief.clone();
  } else {
    s.relief = cv::Mat::zeros(mask.size(), CV_32F);
    for (int y = 0; y < mask.rows; ++y) {
      const uchar* mr = mask.ptr<uchar>(y);
      int l = -1, r = -1;
      for (int x = 0; x < mask.cols; ++x)
        if (mr[x]) {
          if (l < 0) l = x;
          r = x;
        }
      if (l < 0) continue;
      double c = 0.5 * (l + r), hw = 0.5 * (r - l) + 1;
      float* rr = s.relief.ptr<float>(y);
      for (int x = l; x <= r; ++x) {
        double t = (x - c) / hw;
        rr[x] = (float)(0.5 * thickness_m * std::sqrt(std::max(0.0, 1 - t * t)));
      }
    }
  }
  return s;
}

namespace {

struct Blob {
  int frame;
  cv::Rect box;
  cv::Point2f centroid;
  int area;
  bool clean;
  cv::Mat bgr, mask;  // crops
};

// Frames of the walker video read at most: the first minute holds enough walkers.
constexpr int kWalkerVideoFrames = 600;
constexpr int kBackgroundSampleStep = 12;   // every 12th frame votes in the median background
constexpr int kForegroundThreshold = 28;    // colour difference from the background (0-255)
constexpr int kMinBlobArea = 400, kMinBlobHeight = 50;  // pixels
constexpr int kMinTrackFrames = 25;         // 2.5 s at the video's 10 fps

// Per-pixel median of every kBackgroundSampleStep-th frame: the empty background. `frames_read`
// is how many frames the video gave (at most kWalkerVideoFrames).
cv::Mat medianBackground(cv::VideoCapture& cap, const std::string& video_path, int& frames_read) {
  std::vector<cv::Mat> samples;
  cv::Mat frame;
  int n = 0;
  for (; n < kWalkerVideoFrames && cap.read(frame); ++n)
    if (n % kBackgroundSampleStep == 0) samples.push_back(frame.clone());
  if (samples.size() < 5) throw Error("walker video " + video_path + " is too short or corrupt");
  frames_read = n;
  const cv::Size sz = samples[0].size();
  cv::Mat bg(sz, CV_8UC3);
  std::vector<uchar> vals(samples.size());
  for (int y = 0; y < sz.height; ++y)
    for (int x = 0; x < sz.width * 3; ++x) {
      for (size_t k = 0; k < samples.size(); ++k) vals[k] = samples[k].ptr<uchar>(y)[x];
      std::nth_element(vals.begin(), vals.begin() + vals.size() / 2, vals.end());
      bg.ptr<uchar>(y)[x] = vals[vals.size() / 2];
    }
  return bg;
}

// A clean blob keeps its crop (colour, and its mask with the holes filled).
void cropBlob(Blob& b, const cv::Mat& frame, const cv::Mat& labels, int label) {
  cv::Rect r = (b.box + cv::Size(6, 6) - cv::Point(3, 3)) & cv::Rect(0, 0, frame.cols, frame.rows);
  b.bgr = frame(r).clone();
  b.mask = (labels(r) == label);
  // Fill holes: everything not reachable from the crop border is inside.
  cv::Mat pad;
  cv::copyMakeBorder(b.mask, pad, 1, 1, 1, 1, cv::BORDER_CONSTANT, 0);
  cv::floodFill(pad, cv::Point(0, 0), 128);
  b.mask = (pad(cv::Rect(1, 1, r.width, r.height)) != 128);
  b.box = r;
}

// Foreground blobs of one frame; "clean" ones look like one whole walker.
std::vector<Blob> frameBlobs(const cv::Mat& frame, const cv::Mat& bg, int f) {
  static const cv::Mat k_open = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(3, 3));
  static const cv::Mat k_close = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(7, 11));
  cv::Mat diff;
  cv::absdiff(frame, bg, diff);
  std::vector<cv::Mat> ch;
  cv::split(diff, ch);
  cv::Mat fg = cv::max(cv::max(ch[0], ch[1]), ch[2]) > kForegroundThreshold;
  cv::morphologyEx(fg, fg, cv::MORPH_OPEN, k_open);
  cv::morphologyEx(fg, fg, cv::MORPH_CLOSE, k_close);
  cv::Mat labels, stats, cents;
  const int nl = cv::connectedComponentsWithStats(fg, labels, stats, cents, 8, CV_32S);
  std::vector<Blob> fb;
  for (int l = 1; l < nl; ++l) {
    Blob b;
    b.frame = f;
    b.box = cv::Rect(stats.at<int>(l, 0), stats.at<int>(l, 1), stats.at<int>(l, 2), stats.at<int>(l, 3));
    b.area = stats.at<int>(l, 4);
    if (b.area < kMinBlobArea || b.box.height < kMinBlobHeight) continue;
    b.centroid = cv::Point2f((float)cents.at<double>(l, 0), (float)cents.at<double>(l, 1));
    const double aspect = (double)b.box.width / b.box.height;
    const bool border = b.box.x <= 2 || b.box.y <= 2 || b.box.br().x >= frame.cols - 2 ||
                        b.box.br().y >= frame.rows - 2;
    const double fill = (double)b.area / b.box.area();
    b.clean = !border && aspect > 0.22 && aspect < 0.6 && fill > 0.45;
    if (b.clean) cropBlob(b, frame, labels, l);
    fb.push_back(b);
  }
  return fb;
}

struct Track {
  std::vector<const Blob*> blobs;
  bool open = true;
};

// Links blobs frame to frame (greedy nearest centroid, similar height) into tracks; a track
// ends when its blob is lost, merges (unclean) or two candidates compete.
std::vector<Track> linkTracks(const std::vector<std::vector<Blob>>& blobs) {
  std::vector<Track> tracks;
  std::vector<int> active;  // indices of open tracks
  for (size_t f = 0; f < blobs.size(); ++f) {
    std::vector<int> next_active;
    std::vector<bool> used(blobs[f].size(), false);
    for (int ti : active) {
      const Blob* last = tracks[ti].blobs.back();
      int best = -1, cands = 0;
      double bd = 1e9;
      for (size_t j = 0; j < blobs[f].size(); ++j) {
        const Blob& b = blobs[f][j];
        const double d = cv::norm(b.centroid - last->centroid);
        const double hr = (double)b.box.height / last->box.height;
        if (d < 0.3 * last->box.height && hr > 0.8 && hr < 1.25) {
          ++cands;
          if (d < bd) bd = d, best = (int)j;
        }
      }
      if (best >= 0 && cands == 1 && !used[best] && blobs[f][best].clean) {
        used[best] = true;
        tracks[ti].blobs.push_back(&blobs[f][best]);
        next_active.push_back(ti);
      }
    }
    for (size_t j = 0; j < blobs[f].size(); ++j)
      if (!used[j] && blobs[f][j].clean) {
        tracks.push_back(Track{{&blobs[f][j]}});
        next_active.push_back((int)tracks.size() - 1);
      }
    active = next_active;
  }
  return tracks;
}

// Tracks of at least kMinTrackFrames that walk across the view, ranked by length times size:
// big, long walkers first. Returns (score, track index), best first.
std::vector<std::pair<double, int>> rankTracks(const std::vector<Track>& tracks) {
  std::vector<std::pair<double, int>> rank;
  for (size_t i = 0; i < tracks.size(); ++i) {
    const auto& t = tracks[i].blobs;
    if (t.size() < static_cast<size_t>(kMinTrackFrames)) continue;
    std::vector<int> hs;
    for (auto* b : t) hs.push_back(b->box.height);
    std::nth_element(hs.begin(), hs.begin() + hs.size() / 2, hs.end());
    const double dx = t.back()->centroid.x - t.front()->centroid.x;
    if (std::abs(dx) < 0.5 * hs[hs.size() / 2]) continue;  // standing or walking at the camera
    rank.emplace_back(-(double)std::min<size_t>(t.size(), 80) * hs[hs.size() / 2], (int)i);
  }
  std::sort(rank.begin(), rank.end());
  return rank;
}

// The track's sprites, every walker facing right, with its gait's height relative to a moving
// average (keeps the bob, removes perspective growth).
SpriteTrack spriteTrack(const Track& track, const std::string& video_path, double fps) {
  const auto& t = track.blobs;
  const bool left = t.back()->centroid.x < t.front()->centroid.x;
  SpriteTrack st;
  st.source = video_path + " frames " + std::to_string(t.front()->frame) + "-" + std::to_string(t.back()->frame);
  st.fps = fps;
  std::vector<cv::Rect> bbs;
  for (auto* b : t) bbs.push_back(cv::boundingRect(b->mask));
  for (size_t i = 0; i < t.size(); ++i) {
    cv::Mat bgr = t[i]->bgr, mask = t[i]->mask;
    if (left) {
      cv::flip(bgr, bgr, 1);
      cv::flip(mask, mask, 1);
    }
    // Crop to the silhouette's own rows so the feet sit on the quad's bottom edge.
    const cv::Rect bb = cv::boundingRect(mask);  // of the flipped mask
    st.frames.push_back(makeSprite(bgr(bb), mask(bb), cv::Mat(), 0.25));
    double sum = 0;
    int cnt = 0;
    for (int k = std::max(0, (int)i - 5); k <= std::min((int)t.size() - 1, (int)i + 5); ++k)
      sum += bbs[k].height, ++cnt;
    st.height_scale.push_back((float)(bb.height / (sum / cnt)));
  }
  return st;
}

}  // namespace

std::vector<SpriteTrack> extractWalkers(const std::string& video_path, int max_tracks) {
  cv::VideoCapture cap(video_path);
  if (!cap.isOpened())
    throw Error("cannot open the walker video " + video_path +
                ": install opencv-doc (it ships examples/data/vtest.avi) or pass another video");
  int n = 0;
  const cv::Mat bg = medianBackground(cap, video_path, n);
  cap.release();
  cap.open(video_path);
  std::vector<std::vector<Blob>> blobs;
  cv::Mat frame;
  for (int f = 0; f < n && cap.read(frame); ++f) blobs.push_back(frameBlobs(frame, bg, f));
  const std::vector<Track> tracks = linkTracks(blobs);
  const double fps = cap.get(cv::CAP_PROP_FPS) > 0 ? cap.get(cv::CAP_PROP_FPS) : 10.0;
  std::vector<SpriteTrack> out;
  for (const auto& r : rankTracks(tracks)) {
    if ((int)out.size() >= max_tracks) break;
    out.push_back(spriteTrack(tracks[r.second], video_path, fps));
  }
  if (out.empty()) throw Error("no usable walker found in video " + video_path);
  return out;
}

std::vector<SpriteTrack> extractTumPeople(const std::string& tum_dir) {
  const std::string stamp = "1341846313.592026";
  const std::string rgb_path = joinPath(tum_dir, "rgb/" + stamp + ".png");
  const std::string mask_path = joinPath(tum_dir, "dynamic_mask/" + stamp + ".png");
  const std::string depth_path = joinPath(tum_dir, "depth/1341846313.592088.png");
  cv::Mat rgb = cv::imread(rgb_path, cv::IMREAD_COLOR);
  cv::Mat mask = cv::imread(mask_path, cv::IMREAD_GRAYSCALE);
  cv::Mat depth = cv::imread(depth_path, cv::IMREAD_ANYDEPTH);
  for (auto& pm : {std::make_pair(&rgb, rgb_path), std::make_pair(&mask, mask_path),
                   std::make_pair(&depth, depth_path)})
    if (pm.first->empty())
      throw Error("cannot read " + pm.second +
                  ": set YOLO_SLAM_SHARED to the folder holding data/tum (the real TUM frames)");
  if (depth.type() != CV_16U || depth.size() != rgb.size() || mask.size() != rgb.size())
    throw Error("unexpected image type or size in " + depth_path + " / " + mask_path);
  cv::Mat z;
  depth.convertTo(z, CV_32F, 1.0 / 5000);
  cv::Mat labels, stats, cents;
  int nl = cv::connectedComponentsWithStats(mask > 127, labels, stats, cents, 8, CV_32S);
  const double fy = 539.2;  // freiburg3 intrinsics: turns pixel height into metres
  std::vector<SpriteTrack> out;
  for (int l = 1; l < nl; ++l) {
    cv::Rect box(stats.at<int>(l, 0), stats.at<int>(l, 1), stats.at<int>(l, 2), stats.at<int>(l, 3));
    if (stats.at<int>(l, 4) < 3000) continue;
    // Only people seen whole: the standing one of this frame is cut by the image bottom.
    if (box.y <= 1 || box.height > 0.8 * rgb.rows) continue;
    cv::Mat m = labels(box) == l;
    cv::Mat zc = z(box);
    std::vector<float> zs;
    for (int y = 0; y < m.rows; ++y)
      for (int x = 0; x < m.cols; ++x)
        if (m.at<uchar>(y, x) && zc.at<float>(y, x) > 0) zs.push_back(zc.at<float>(y, x));
    if (zs.size() < 500) continue;
    std::nth_element(zs.begin(), zs.begin() + zs.size() / 2, zs.end());
    float zmed = zs[zs.size() / 2];
    // Relief from the real depth; holes in the depth take the smoothed neighbourhood.
    cv::Mat rel(m.size(), CV_32F, 0.f), valid(m.size(), CV_32F, 0.f);
    for (int y = 0; y < m.rows; ++y)
      for (int x = 0; x < m.cols; ++x) {
        float d = zc.at<float>(y, x);
        if (m.at<uchar>(y, x) && d > 0 && std::abs(d - zmed) < 0.6f) {
          rel.at<float>(y, x) = std::min(0.4f, std::max(-0.3f, zmed - d));
          valid.at<float>(y, x) = 1;
        }
      }
    cv::Mat rb, vb;
    cv::blur(rel, rb, cv::Size(15, 15));
    cv::blur(valid, vb, cv::Size(15, 15));
    cv::Mat fill = rb / cv::max(vb, 1e-3f);
    fill.copyTo(rel, valid == 0);
    SpriteTrack st;
    st.source = rgb_path + " person " + std::to_string(out.size());
    st.frames.push_back(makeSprite(rgb(box), m, rel, 0.3));
    st.height_scale.push_back(1.f);
    st.height_m = box.height * zmed / fy;
    st.sitting = true;
    out.push_back(std::move(st));
  }
  if (out.empty()) throw Error("no person seen whole in " + mask_path);
  return out;
}

namespace {
template <class F>
std::shared_ptr<const std::vector<SpriteTrack>> cached(const std::string& key, F make) {
  // Guards the map; extraction runs under the lock so concurrent callers wait for one result.
  static std::mutex mu;
  static std::map<std::string, std::shared_ptr<const std::vector<SpriteTrack>>> cache;
  std::lock_guard<std::mutex> lock(mu);
  auto it = cache.find(key);
  if (it != cache.end()) return it->second;
  auto v = std::make_shared<const std::vector<SpriteTrack>>(make());
  cache[key] = v;
  return v;
}
}  // namespace

std::shared_ptr<const std::vector<SpriteTrack>> cachedWalkers(const std::string& video_path) {
  return cached("video:" + video_path, [&] { return extractWalkers(video_path); });
}
std::shared_ptr<const std::vector<SpriteTrack>> cachedTumPeople(const std::string& tum_dir) {
  return cached("tum:" + tum_dir, [&] { return extractTumPeople(tum_dir); });
}

}  // namespace sim
}  // namespace yolo_slam
