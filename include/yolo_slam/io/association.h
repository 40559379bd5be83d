#pragma once
// Timestamp association exactly as TUM's associate.py.
#include <cstddef>
#include <utility>
#include <vector>

namespace yolo_slam {
namespace io {

// Pairs (index into a, index into b) such that |a - (b + offset)| < max_diff (strict), chosen
// greedily by increasing difference with every stamp used at most once, returned sorted by the
// a stamp. Ties in the difference are broken like Python's tuple sort in associate.py: by the
// a stamp, then the b stamp (then by index, for duplicate stamps). Inputs need not be sorted.
std::vector<std::pair<size_t, size_t>> associate(const std::vector<double>& a,
                                                 const std::vector<double>& b,
                                                 double offset = 0.0, double max_diff = 0.02);

}  // namespace io
}  // namespace yolo_slam
