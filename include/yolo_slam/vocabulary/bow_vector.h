#pragma once
// Bag-of-words value types shared by the vocabulary, the keyframe database and the matcher.
#include <cstdint>
#include <map>
#include <vector>

namespace yolo_slam {
namespace vocabulary {

using WordId = uint32_t;
using NodeId = uint32_t;

// word -> weight, sorted by word id; L1-normalised by Vocabulary::transform.
using BowVector = std::map<WordId, double>;
// Direct index: vocabulary node (at a chosen level) -> indices of the descriptors under it.
// Two frames' features under the same node are the only candidates SearchByBoW compares.
using FeatureVector = std::map<NodeId, std::vector<unsigned>>;

}  // namespace vocabulary
}  // namespace yolo_slam
