#include "yolo_slam/vocabulary/bow_matcher.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/features/rotation_histogram.h"
#include "yolo_slam/vocabulary/descriptor.h"

#include <algorithm>
#include <string>

namespace yolo_slam {
namespace vocabulary {

namespace {

void checkSide(const BowSide& s, const char* name, bool need_kps) {
  const std::string n = std::string("searchByBow: side ") + name;
  if (!s.fv || !s.descriptors) throw Error(n + " needs a feature vector and descriptors");
  if (!s.descriptors->empty() && (s.descriptors->type() != CV_8UC1 || s.descriptors->cols != kDescriptorBytes))
    throw Error(n + ": descriptors must be N x 32 CV_8U");
  const size_t rows = static_cast<size_t>(s.descriptors->rows);
  if (need_kps && (!s.keypoints || s.keypoints->size() != rows))
    throw Error(n + ": orientation check needs one keypoint per descriptor");
  if (s.usable && s.usable->size() != rows) throw Error(n + ": usable mask size differs from descriptor count");
  for (const auto& node : *s.fv)
    for (unsigned i : node.second)
      if (i >= rows) throw Error(n + ": feature vector index " + std::to_string(i) + " out of range");
}

// The usable features of A under one vocabulary node against the free usable ones of B under
// the same node: best and second-best distance, th_low and the ratio test.
void matchNode(const BowSide& a, const std::vector<unsigned>& node_a, const BowSide& b,
               const std::vector<unsigned>& node_b, const BowMatchOptions& opt, std::vector<uint8_t>& b_taken,
               std::vector<BowMatch>& matches) {
  for (unsigned fa : node_a) {
    if (a.usable && !(*a.usable)[fa]) continue;
    const uint8_t* da = a.descriptors->ptr<uint8_t>(static_cast<int>(fa));
    int best = 256, second = 256;
    unsigned best_b = 0;
    for (unsigned fb : node_b) {
      if (b_taken[fb] || (b.usable && !(*b.usable)[fb])) continue;
      const int d = descriptorDistance(da, b.descriptors->ptr<uint8_t>(static_cast<int>(fb)));
      if (d < best) {
        second = best;
        best = d;
        best_b = fb;
      } else if (d < second) {
        second = d;
      }
    }
    if (best <= opt.th_low && static_cast<float>(best) < opt.nn_ratio * static_cast<float>(second)) {
      b_taken[best_b] = 1;
      matches.push_back({fa, best_b, best});
    }
  }
}

}  // namespace

std::vector<BowMatch> searchByBow(const BowSide& a, const BowSide& b, const BowMatchOptions& opt) {
  checkSide(a, "A", opt.check_orientation);
  checkSide(b, "B", opt.check_orientation);
  std::vector<BowMatch> matches;
  std::vector<uint8_t> b_taken(static_cast<size_t>(b.descriptors->rows), 0);
  auto ia = a.fv->begin();
  auto ib = b.fv->begin();
  while (ia != a.fv->end() && ib != b.fv->end()) {
    if (ia->first < ib->first) {
      ia = a.fv->lower_bound(ib->first);
      continue;
    }
    if (ib->first < ia->first) {
      ib = b.fv->lower_bound(ia->first);
      continue;
    }
    matchNode(a, ia->second, b, ib->second, opt, b_taken, matches);
    ++ia;
    ++ib;
  }

  if (opt.check_orientation && !matches.empty() && opt.histogram_bins > 0) {
    features::RotationHistogram hist(opt.histogram_bins);
    for (size_t i = 0; i < matches.size(); ++i)
      hist.add((*a.keypoints)[matches[i].a].angle, (*b.keypoints)[matches[i].b].angle, i);
    std::vector<uint8_t> drop(matches.size(), 0);
    for (size_t i : hist.outliers()) drop[i] = 1;
    std::vector<BowMatch> kept;
    for (size_t i = 0; i < matches.size(); ++i)
      if (!drop[i]) kept.push_back(matches[i]);
    matches.swap(kept);
  }
  std::sort(matches.begin(), matches.end(), [](const BowMatch& x, const BowMatch& y) { return x.a < y.a; });
  return matches;
}

}  // namespace vocabulary
}  // namespace yolo_slam
