#include "yolo_slam/detection/model_files.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"

#include <dirent.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <map>
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

namespace {

struct CfgSection {
  std::string type;
  int line = 0;
  std::map<std::string, std::string> kv;
};

std::vector<CfgSection> readCfg(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error("cannot read Darknet cfg " + path + "; check the model path");
  std::vector<CfgSection> out;
  std::string line;
  int lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    line = trim(line.substr(0, line.find_first_of("#;")));
    if (line.empty()) continue;
    if (line.front() == '[') {
      out.push_back({line, lineno, {}});
      continue;
    }
    size_t eq = line.find('=');
    if (eq == std::string::npos || out.empty())
      throw Error(path + ":" + std::to_string(lineno) + ": expected key=value inside a [section]");
    out.back().kv[trim(line.substr(0, eq))] = trim(line.substr(eq + 1));
  }
  return out;
}

int cfgInt(const std::string& path, const CfgSection& s, const std::string& key, int def) {
  auto it = s.kv.find(key);
  if (it == s.kv.end()) return def;
  char* end = nullptr;
  long v = std::strtol(it->second.c_str(), &end, 10);
  if (it->second.empty() || *end)
    throw Error(path + ": section " + s.type + " at line " + std::to_string(s.line) + ": " +
                key + " must be an integer");
  return int(v);
}

}  // namespace

long long darknetParamCount(const std::string& path) {
  auto sections = readCfg(path);
  if (sections.empty() || (sections[0].type != "[net]" && sections[0].type != "[network]"))
    throw Error(path + ": first section must be [net]; is this a Darknet cfg?");
  std::vector<int> channels;  // output channels per layer
  int c = cfgInt(path, sections[0], "channels", 3);
  long long total = 0;
  for (size_t i = 1; i < sections.size(); ++i) {
    const CfgSection& s = sections[i];
    const std::string at = path + ":" + std::to_string(s.line) + ": ";
    if (s.type == "[convolutional]" || s.type == "[conv]") {
      int f = cfgInt(path, s, "filters", 1), k = cfgInt(path, s, "size", 1);
      int g = cfgInt(path, s, "groups", 1);
      bool bn = cfgInt(path, s, "batch_normalize", 0) != 0;
      if (f <= 0 || k <= 0 || g <= 0 || c % g) throw Error(at + "bad filters/size/groups");
      total += f + (bn ? 3LL * f : 0LL) + 1LL * f * (c / g) * k * k;
      c = f;
    } else if (s.type == "[route]") {
      auto it = s.kv.find("layers");
      if (it == s.kv.end()) throw Error(at + "[route] needs layers=");
      std::stringstream ss(it->second);
      std::string tok;
      int sum = 0;
      const int here = int(channels.size());
      while (std::getline(ss, tok, ',')) {
        int l = std::atoi(trim(tok).c_str());
        int idx = l < 0 ? here + l : l;
        if (idx < 0 || idx >= here) throw Error(at + "route layer " + tok + " out of range");
        sum += channels[idx];
      }
      c = sum / std::max(1, cfgInt(path, s, "groups", 1));
    } else if (s.type != "[maxpool]" && s.type != "[upsample]" && s.type != "[shortcut]" &&
               s.type != "[dropout]" && s.type != "[yolo]" && s.type != "[region]" &&
               s.type != "[avgpool]") {
      throw Error(at + "layer type " + s.type + " is not supported by the weights check");
    }
    channels.push_back(c);
  }
  return total;
}

void checkDarknetWeights(const std::string& cfg_path, const std::string& weights_path) {
  std::ifstream in(weights_path, std::ios::binary | std::ios::ate);
  if (!in) throw Error("cannot read Darknet weights " + weights_path + "; check the model path");
  const long long size = static_cast<long long>(in.tellg());
  in.seekg(0);
  int32_t ver[3] = {0, 0, 0};
  if (!in.read(reinterpret_cast<char*>(ver), sizeof(ver)))
    throw Error("Darknet weights " + weights_path + " is truncated (no header); re-download it");
  // Darknet >= 0.2 stores `seen` as uint64, older files as uint32.
  const long long header = 12 + ((ver[0] * 10 + ver[1]) >= 2 ? 8 : 4);
  const long long want = header + 4 * darknetParamCount(cfg_path);
  if (size != want)
    throw Error("Darknet weights " + weights_path + " has " + std::to_string(size) +
                " bytes but " + cfg_path + " needs " + std::to_string(want) + " (" +
                (size < want ? "truncated, or the weights of a smaller network"
                             : "weights of a different network") +
                "); re-download the weights or use the cfg they were trained with");
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
