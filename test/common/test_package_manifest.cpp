// package.xml declares what the code uses and nothing else, and scripts/install_deps.sh (the one
// list of Debian packages) installs every key it declares. Reads the source tree (the tests run
// in the repository root).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>

namespace fs = std::filesystem;

namespace {

std::string readFile(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::set<std::string> allMatches(const std::string& text, const std::regex& re) {
  std::set<std::string> out;
  for (std::sregex_iterator it(text.begin(), text.end(), re), end; it != end; ++it) out.insert((*it)[1]);
  return out;
}

// package.xml keys by tag: "depend", "exec_depend", ...
std::map<std::string, std::set<std::string>> manifestKeys() {
  const std::string xml = readFile("package.xml");
  std::map<std::string, std::set<std::string>> keys;
  for (const char* tag : {"buildtool_depend", "depend", "build_depend", "exec_depend", "test_depend"})
    keys[tag] = allMatches(xml, std::regex(std::string("<") + tag + ">([^<]+)</" + tag + ">"));
  return keys;
}

std::set<std::string> allKeys() {
  std::set<std::string> all;
  for (const auto& kv : manifestKeys()) all.insert(kv.second.begin(), kv.second.end());
  return all;
}

// The "key: packages" rows of install_deps.sh's DEPENDENCIES block.
std::map<std::string, std::string> installRows() {
  const std::string sh = readFile("scripts/install_deps.sh");
  const size_t begin = sh.find("DEPENDENCIES='");
  const size_t end = sh.find('\'', begin + 14);
  EXPECT_NE(begin, std::string::npos) << "scripts/install_deps.sh has no DEPENDENCIES='...' block";
  std::map<std::string, std::string> rows;
  if (begin == std::string::npos || end == std::string::npos) return rows;
  std::istringstream block(sh.substr(begin + 14, end - begin - 14));
  std::string line;
  const std::regex row(R"(^\s*([^:]+):\s*(\S.*)$)");
  std::smatch m;
  while (std::getline(block, line))
    if (std::regex_match(line, m, row)) rows[m[1]] = m[2];
  return rows;
}

// Files under `dirs` whose name ends in one of `exts`.
std::string concatSources(std::initializer_list<const char*> dirs, std::initializer_list<const char*> exts) {
  std::string all;
  for (const char* d : dirs) {
    if (!fs::exists(d)) continue;
    for (const auto& e : fs::recursive_directory_iterator(d)) {
      const std::string name = e.path().filename().string();
      for (const char* x : exts)
        if (e.is_regular_file() && name.size() > std::string(x).size() &&
            name.compare(name.size() - std::string(x).size(), std::string::npos, x) == 0)
          all += readFile(e.path()) + "\n";
    }
  }
  return all;
}

// Include prefixes (<prefix/...>) that are not a package.xml key of the same name.
const std::map<std::string, std::string> kIncludeKey = {
    {"ros", "roscpp"}, {"opencv2", "libopencv-dev"}, {"Eigen", "eigen"},
    {"ceres", "libceres-dev"}, {"openni2", "libopenni2-dev"}, {"gtest", "gtest"},
    {"nlohmann", "nlohmann-json-dev"}, {"cereal", "libcereal-dev"},
    {"octomap", "liboctomap-dev"}};
// Include prefixes that need no key: the C library and the project itself.
const std::set<std::string> kIncludeNoKey = {"sys", "yolo_slam"};
// Python modules imported by scripts and benchmarks that need a key; the standard library needs none.
const std::map<std::string, std::string> kPythonKey = {
    {"rospy", "rospy"}, {"rosbag", "rosbag"}, {"tf2_msgs", "tf2_msgs"}, {"cv2", "python3-opencv"},
    {"numpy", "python3-numpy"}, {"sensor_msgs", "sensor_msgs"}, {"geometry_msgs", "geometry_msgs"},
    {"diagnostic_msgs", "diagnostic_msgs"}, {"nav_msgs", "nav_msgs"}, {"tf2_ros", "tf2_ros"}};
const std::set<std::string> kPythonStdlib = {"argparse", "collections", "json", "math", "os", "re",
                                             "statistics", "sys", "xml", "subprocess", "time", "glob",
                                             "shutil", "struct", "tempfile", "itertools", "functools", "signal",
                                             "random"};
// Keys a build needs without an include of their own.
const std::set<std::string> kBuildOnlyKeys = {"catkin", "message_generation", "message_runtime"};

}  // namespace

TEST(PackageManifest, EveryKeyIsInstalledByInstallDeps) {
  const auto rows = installRows();
  ASSERT_FALSE(rows.empty());
  for (const auto& key : allKeys())
    EXPECT_TRUE(rows.count(key)) << "package.xml declares '" << key
                                 << "' but scripts/install_deps.sh has no '" << key << ":' row";
  for (const auto& kv : rows) {
    if (kv.first == "build tools" || kv.first == "data" || kv.first == "optional") continue;
    EXPECT_TRUE(allKeys().count(kv.first)) << "scripts/install_deps.sh installs '" << kv.first
                                           << "' that package.xml does not declare";
  }
}

TEST(PackageManifest, EveryIncludeIsDeclared) {
  const std::string code = concatSources({"src", "include", "tools", "test", "bench"}, {".cpp", ".h"});
  const std::set<std::string> prefixes = allMatches(code, std::regex(R"(#include <([A-Za-z_0-9]+)/)"));
  const auto keys = allKeys();
  std::set<std::string> used;
  for (const auto& p : prefixes) {
    if (kIncludeNoKey.count(p)) continue;
    const auto it = kIncludeKey.find(p);
    const std::string key = it == kIncludeKey.end() ? p : it->second;
    used.insert(key);
    EXPECT_TRUE(keys.count(key)) << "#include <" << p << "/...> needs '" << key << "' in package.xml";
  }
  // A C++ dependency nothing includes is not needed.
  auto m = manifestKeys();
  for (const char* tag : {"depend", "build_depend"})
    for (const auto& key : m[tag])
      EXPECT_TRUE(used.count(key) || kBuildOnlyKeys.count(key))
          << "package.xml <" << tag << ">" << key << " is included by no source file";
}

TEST(PackageManifest, EveryPythonImportAndLaunchPackageIsDeclared) {
  const auto keys = allKeys();
  const std::string py = concatSources({"scripts", "bench", "test"}, {".py"});
  const auto modules = allMatches(py, std::regex(R"((?:^|\n)\s*(?:import|from)\s+([A-Za-z_0-9]+))"));
  ASSERT_FALSE(modules.empty());
  for (const auto& mod : modules) {
    if (kPythonStdlib.count(mod)) continue;
    const auto it = kPythonKey.find(mod);
    ASSERT_NE(it, kPythonKey.end()) << "Python module '" << mod << "': add its package.xml key to kPythonKey"
                                    << " (or to kPythonStdlib) in " << __FILE__;
    EXPECT_TRUE(keys.count(it->second)) << "import " << mod << " needs '" << it->second << "' in package.xml";
  }
  const std::string launch = concatSources({"launch", "test"}, {".launch", ".test"});
  for (const auto& pkg : allMatches(launch, std::regex(R"(pkg="([a-z_0-9]+)\")"))) {
    if (pkg == "yolo_slam") continue;
    EXPECT_TRUE(keys.count(pkg)) << "a launch file runs a node of '" << pkg << "': declare it in package.xml";
  }
}
