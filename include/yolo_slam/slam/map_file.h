#pragma once
// Map files: a slam::Map written to disk and read back, so that a map outlives the process
// (docs/map-file.md). A file holds the keyframes (pose, keypoints, descriptors, depth and right
// coordinates, covisibility edges, spanning-tree parent, loop edges), the map points (position,
// descriptor, observations, normal, scale range) and what the map was built with: the camera,
// the ORB pyramid and a checksum of the vocabulary's content. Bags of words are not stored:
// loading recomputes them with the (checked identical) vocabulary.
//
// Layout: a fixed header (magic, format version, payload size, payload checksum) followed by the
// payload, both written with cereal's portable binary archive. Files are written atomically
// (io::writeFileAtomic). Any problem (missing, truncated, corrupt, another format version,
// vocabulary or camera) throws yolo_slam::Error naming the file and the fix; the Map being
// loaded into is then left in an unspecified state, so load into a fresh Map and adopt it only on
// success (System::loadMap does).
#include "yolo_slam/common/camera.h"

#include <cstddef>
#include <cstdint>
#include <string>

namespace yolo_slam {
namespace vocabulary {
class Vocabulary;
}
namespace slam {

class Map;

// Raised whenever the layout of the payload changes; files of another version are refused.
constexpr uint32_t kMapFileFormatVersion = 1;

// What a map is tied to: the camera and ORB pyramid its keypoints and scale ranges come from and
// the vocabulary its bags of words come from (null: none; such a map loads only without one).
struct MapFileContext {
  CameraModel camera;
  int orb_levels = 8;
  double orb_scale_factor = 1.2;
  const vocabulary::Vocabulary* vocabulary = nullptr;
};

// What a save or load did, for stats.json ("map_file").
struct MapFileInfo {
  size_t bytes = 0;
  size_t keyframes = 0, map_points = 0;
  double ms = 0;  // wall time of the save or load (including the file I/O)
};

// Writes `map` to `path` atomically. Caller holds map.update_mutex. Throws yolo_slam::Error if
// the file cannot be written.
MapFileInfo saveMapFile(const std::string& path, const Map& map, const MapFileContext& context);

// Reads `path` into `out`, which must be empty and must not be shared yet (no locking). Rebuilds
// the keypoint grids, bags of words, ordered covisibility lists and spanning-tree children; `out`'s
// keyframe database (if set) receives every keyframe. Throws yolo_slam::Error naming the file.
MapFileInfo loadMapFile(const std::string& path, const MapFileContext& context, Map& out);

// FNV-1a over the vocabulary's tree, descriptors, word ids and weights: equal for identical
// vocabularies whatever file format they were read from.
uint64_t vocabularyChecksum(const vocabulary::Vocabulary& voc);

}  // namespace slam
}  // namespace yolo_slam
