#pragma once
// Every settings key some options loader reads, so that a settings file and an override can be
// checked for unknown (misspelt) keys when they are read, before any module loads its options.
// The list lives here, below the modules, because Config checks it; the test
// slam_test_settings_keys keeps it equal to the keys the loaders read and to config/TUM*.yaml.
#include <string>
#include <vector>

namespace yolo_slam {

const std::vector<std::string>& knownSettingsKeys();

// A key of the list, or of a section of ORB-SLAM2 files yolo_slam ignores (Viewer.*).
bool isKnownSettingsKey(const std::string& key);

// The known key closest to `key` (edit distance, case-insensitive): the suggestion for a typo.
std::string nearestSettingsKey(const std::string& key);

}  // namespace yolo_slam
