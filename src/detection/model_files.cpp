#include "yolo_slam/detection/model_files.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"

#include <dirent.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <set>
#include <sstream>

namespace yolo_slam {
namespace detection {
namespace {

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string trim(const std::string& s) {
  const char* ws = " \t\r\n";
  size_t b = s.find_first_not_of(ws);
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(ws) - b + 1);
}

std::string dirOf(const std::string& path) {
  size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? "." : path.substr(0, slash == 0 ? 1 : slash);
}

// Files in `dir` whose names end with `ext`, sorted, as full paths.
std::vector<std::string> listWithExt(const std::string& dir, const std::string& ext) {
  std::vector<std::string> out;
  DIR* d = ::opendir(dir.c_str());
  if (!d) return out;
  while (dirent* e = ::readdir(d)) {
    std::string name = e->d_name;
    if (endsWith(name, ext) && fileExists(joinPath(dir, name))) out.push_back(joinPath(dir, name));
  }
  ::closedir(d);
  std::sort(out.begin(), out.end());
  return out;
}

std::string joinList(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

// Exactly one file with `ext` in `dir`, else an Error saying what to pass instead.
std::string single(const std::string& dir, const std::string& ext, const std::string& what) {
  auto files = listWithExt(dir, ext);
  if (files.empty())
    throw Error("model folder " + dir + " has no " + ext + " file (" + what +
                "); add it or set Detector.model / YOLO_SLAM_MODEL to a complete model");
  if (files.size() > 1)
    throw Error("model folder " + dir + " has " + std::to_string(files.size()) + " " + ext +
                " files (" + joinList(files) + "); pass the one to use as the model path");
  return files.front();
}

// --- minimal protobuf reading, just enough to find an ONNX graph input's shape ------------
struct Pb {
  const uint8_t* p;
  const uint8_t* end;
  bool ok = true;
  uint64_t varint() {
    uint64_t v = 0;
    for (int shift = 0; shift < 64; shift += 7) {
      if (p >= end) { ok = false; return 0; }
      uint8_t b = *p++;
      v |= uint64_t(b & 0x7f) << shift;
      if (!(b & 0x80)) return v;
    }
    ok = false;
    return 0;
  }
  // Next field: number and wire type; for length-delimited fields `sub` spans the payload.
  bool next(uint32_t& field, uint32_t& wire, Pb& sub) {
    if (!ok || p >= end) return false;
    uint64_t key = varint();
    field = uint32_t(key >> 3);
    wire = uint32_t(key & 7);
    switch (wire) {
      case 0: sub = Pb{p, end}; varint(); break;
      case 1: p += 8; break;
      case 2: {
        uint64_t len = varint();
        if (!ok || len > uint64_t(end - p)) { ok = false; return false; }
        sub = Pb{p, p + len};
        p += len;
        break;
      }
      case 5: p += 4; break;
      default: ok = false; return false;
    }
    if (p > end) ok = false;
    return ok;
  }
};

}  // namespace

ModelFiles resolveModel(const std::string& path) {
  ModelFiles m;
  if (path.empty())
    throw Error("no detection model given; set Detector.model, YOLO_SLAM_MODEL or --model");
  std::string dir;
  if (dirExists(path)) {
    dir = path;
    auto onnx = listWithExt(dir, ".onnx");
    auto cfgs = listWithExt(dir, ".cfg");
    if (!cfgs.empty() || onnx.empty()) {
      m.format = ModelFormat::Darknet;
      m.cfg = single(dir, ".cfg", "Darknet network definition");
      m.weights = single(dir, ".weights", "Darknet weights");
    } else {
      m.format = ModelFormat::Onnx;
      m.weights = single(dir, ".onnx", "ONNX model");
    }
  } else if (endsWith(path, ".cfg") || endsWith(path, ".onnx")) {
    if (!fileExists(path))
      throw Error("model file " + path + " not found; set Detector.model / YOLO_SLAM_MODEL / "
                  "--model to an existing .cfg, .onnx or model folder");
    dir = dirOf(path);
    if (endsWith(path, ".onnx")) {
      m.format = ModelFormat::Onnx;
      m.weights = path;
    } else {
      m.format = ModelFormat::Darknet;
      m.cfg = path;
      std::string same = path.substr(0, path.size() - 4) + ".weights";
      m.weights = fileExists(same) ? same : single(dir, ".weights", "Darknet weights for " + path);
    }
  } else {
    throw Error("model path " + path + " is neither a folder nor a .cfg/.onnx file; set "
                "Detector.model / YOLO_SLAM_MODEL / --model to a model folder, .cfg or .onnx");
  }
  m.names = single(dir, ".names", "class names, one per line");
  return m;
}

std::vector<std::string> readClassNames(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error("cannot read class names file " + path + "; check the model folder");
  std::vector<std::string> names;
  std::string line;
  while (std::getline(in, line)) {
    line = trim(line);
    if (!line.empty()) names.push_back(line);
  }
  if (names.empty())
    throw Error("class names file " + path + " is empty; it needs one class name per line");
  return names;
}

cv::Size darknetInputSize(const std::string& cfg_path) {
  std::ifstream in(cfg_path);
  if (!in) throw Error("cannot read Darknet cfg " + cfg_path + "; check the model path");
  std::string line, section;
  int w = 0, h = 0, lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    line = trim(line.substr(0, line.find_first_of("#;")));
    if (line.empty()) continue;
    if (line.front() == '[') {
      if (!section.empty()) break;  // only the first section ([net]) matters
      section = line;
      continue;
    }
    size_t eq = line.find('=');
    if (eq == std::string::npos) continue;
    std::string key = trim(line.substr(0, eq)), val = trim(line.substr(eq + 1));
    if (key != "width" && key != "height") continue;
    int v = 0;
    std::istringstream ss(val);
    if (!(ss >> v) || v <= 0)
      throw Error(cfg_path + ":" + std::to_string(lineno) + ": " + key +
                  " must be a positive integer");
    (key == "width" ? w : h) = v;
  }
  if (section != "[net]" && section != "[network]")
    throw Error(cfg_path + ": first section must be [net]; is this a Darknet cfg?");
  if (w <= 0 || h <= 0)
    throw Error(cfg_path + ": [net] lacks width/height; add them or set Detector.inputWidth/"
                "inputHeight");
  return {w, h};
}

cv::Size onnxInputSize(const std::string& onnx_path) {
  std::ifstream in(onnx_path, std::ios::binary);
  if (!in) throw Error("cannot read ONNX model " + onnx_path + "; check the model path");
  std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto* begin = reinterpret_cast<const uint8_t*>(data.data());
  Pb model{begin, begin + data.size()};
  uint32_t f, w;
  Pb graph{nullptr, nullptr}, sub{nullptr, nullptr};
  bool have_graph = false;
  while (model.next(f, w, sub))
    if (f == 7 && w == 2) { graph = sub; have_graph = true; }
  if (!model.ok || !have_graph)
    throw Error("ONNX model " + onnx_path + " is corrupt or truncated (no graph); "
                "re-download or re-export it");
  // Graph inputs (field 11) may include initializers (field 5, name = field 8) in old exports.
  std::set<std::string> initializers;
  std::vector<Pb> inputs;
  while (graph.next(f, w, sub)) {
    if (f == 11 && w == 2) inputs.push_back(sub);
    if (f == 5 && w == 2) {
      Pb t = sub, s{nullptr, nullptr};
      uint32_t tf, tw;
      while (t.next(tf, tw, s))
        if (tf == 8 && tw == 2) initializers.insert(std::string(s.p, s.end));
    }
  }
  if (!graph.ok)
    throw Error("ONNX model " + onnx_path + " is corrupt or truncated; re-download or "
                "re-export it");
  for (Pb vi : inputs) {
    std::string name;
    Pb type{nullptr, nullptr}, s{nullptr, nullptr};
    bool have_type = false;
    while (vi.next(f, w, s)) {
      if (f == 1 && w == 2) name.assign(s.p, s.end);
      if (f == 2 && w == 2) { type = s; have_type = true; }
    }
    if (initializers.count(name) || !have_type) continue;
    // TypeProto.tensor_type(1) -> shape(2) -> dim(1) -> dim_value(1)
    std::vector<int64_t> dims;
    Pb t{nullptr, nullptr};
    while (type.next(f, w, s)) if (f == 1 && w == 2) t = s;
    Pb shape{nullptr, nullptr};
    while (t.p && t.next(f, w, s)) if (f == 2 && w == 2) shape = s;
    while (shape.p && shape.next(f, w, s)) {
      if (f != 1 || w != 2) continue;
      Pb dim = s, d{nullptr, nullptr};
      int64_t value = 0;
      while (dim.next(f, w, d))
        if (f == 1 && w == 0) value = int64_t(Pb(d).varint());
      dims.push_back(value);
    }
    if (dims.size() == 4 && dims[2] > 0 && dims[3] > 0)
      return {int(dims[3]), int(dims[2])};
    return {0, 0};
  }
  return {0, 0};
}

}  // namespace detection
}  // namespace yolo_slam
