#include "yolo_slam/features/rotation_histogram.h"

#include "yolo_slam/common/error.h"

#include <cmath>
#include <string>

namespace yolo_slam {
namespace features {

RotationHistogram::RotationHistogram(int bins) {
  if (bins <= 0) throw Error("RotationHistogram: bins must be > 0, got " + std::to_string(bins));
  bins_.resize(static_cast<size_t>(bins));
}

int RotationHistogram::bin(float angle_a, float angle_b) const {
  const int n = static_cast<int>(bins_.size());
  float rot = angle_a - angle_b;
  if (rot < 0.0f) rot += 360.0f;
  const int b = static_cast<int>(std::round(rot * (1.0f / 360.0f) * n));
  return b >= n || b < 0 ? 0 : b;  // 360 degrees wraps to 0
}

void RotationHistogram::add(float angle_a, float angle_b, size_t item) {
  bins_[static_cast<size_t>(bin(angle_a, angle_b))].push_back(item);
}

std::vector<size_t> RotationHistogram::outliers() const {
  // The three fullest bins; on a tie the lower bin ranks first.
  int m1 = 0, m2 = 0, m3 = 0, i1 = -1, i2 = -1, i3 = -1;
  for (int i = 0; i < static_cast<int>(bins_.size()); ++i) {
    const int s = static_cast<int>(bins_[i].size());
    if (s > m1) {
      m3 = m2; i3 = i2; m2 = m1; i2 = i1; m1 = s; i1 = i;
    } else if (s > m2) {
      m3 = m2; i3 = i2; m2 = s; i2 = i;
    } else if (s > m3) {
      m3 = s; i3 = i;
    }
  }
  if (m2 < kMinRotationShare * m1) i2 = i3 = -1;
  else if (m3 < kMinRotationShare * m1) i3 = -1;
  std::vector<size_t> out;
  for (int i = 0; i < static_cast<int>(bins_.size()); ++i) {
    if (i == i1 || i == i2 || i == i3) continue;
    out.insert(out.end(), bins_[i].begin(), bins_[i].end());
  }
  return out;
}

}  // namespace features
}  // namespace yolo_slam
