// yolo_slam_synth: generates a synthetic dynamic RGB-D sequence in the TUM layout.
#include "yolo_slam/common/config.h"
#include "yolo_slam/common/error.h"
#include "yolo_slam/sim/contact_sheet.h"
#include "yolo_slam/sim/generator.h"
#include "yolo_slam/sim/textures.h"

#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <unistd.h>

using namespace yolo_slam;

static void usage() {
  std::printf(
      "usage: yolo_slam_synth --out DIR [--preset NAME] [--seed N] [--frames N] [--textures DIR]\n"
      "                       [--trajectory static|xyz|rpy|halfsphere|loop|FILE] [--config FILE]\n"
      "                       [--motion-blur] [--no-noise] [--threads N] [--people-detail GAIN]\n"
      "                       [--no-objects]\n"
      "       yolo_slam_synth --list-presets | --list-textures [--textures DIR]\n"
      "       yolo_slam_synth --contact-sheet PNG [--preset NAME ...]  (rgb, depth, mask of frames 0\n"
      "                       and 300 of each preset; all presets by default)\n"
      "Writes a TUM-format RGB-D sequence (rgb/, depth/, rgb.txt, depth.txt, groundtruth.txt,\n"
      "associations.txt, camera.yaml) with dynamic ground truth (masks/, boxes.txt).\n"
      "Presets: walking_xyz (default) walking_static walking_rpy walking_half sitting_static\n"
      "static_xyz loop crowd close moved_object. --frames 0 keeps the preset's length. Same --seed,\n"
      "same bytes. --people-detail 0 drops the clothing pattern on people (default 0.6; 0: the\n"
      "sequences of before it); --no-objects leaves out the boxes (compare moved_object's ATE).\n");
}

static long parseInt(const std::string& flag, const std::string& v, long lo) {
  char* end = nullptr;
  long x = std::strtol(v.c_str(), &end, 10);
  if (v.empty() || *end || x < lo)
    throw Error("bad value '" + v + "' for " + flag + ": expected an integer >= " + std::to_string(lo));
  return x;
}

static double parseGain(const std::string& flag, const std::string& v) {
  char* end = nullptr;
  double x = std::strtod(v.c_str(), &end);
  if (v.empty() || *end || !(x >= 0))
    throw Error("bad value '" + v + "' for " + flag + ": expected a number >= 0");
  return x;
}

// The command line; unset numbers are negative, unset strings empty.
struct Args {
  std::string out, config, sheet, preset, textures, trajectory;
  std::vector<std::string> sheet_presets;
  bool help = false, list_presets = false, list_textures = false, blur = false, no_noise = false,
       no_objects = false;
  double people_detail = -1;
  int threads = -1;
  long seed = -1, frames = -1;
};

static Args parseArgs(int argc, char** argv) {
  Args g;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    auto val = [&]() -> std::string {
      if (i + 1 >= argc) throw Error("missing value after " + a + " (see --help)");
      return argv[++i];
    };
    if (a == "-h" || a == "--help") { g.help = true; return g; }
    else if (a == "--out") g.out = val();
    else if (a == "--preset") g.preset = val(), g.sheet_presets.push_back(g.preset);
    else if (a == "--contact-sheet") g.sheet = val();
    else if (a == "--seed") g.seed = parseInt(a, val(), 0);
    else if (a == "--frames") g.frames = parseInt(a, val(), 0);
    else if (a == "--textures") g.textures = val();
    else if (a == "--trajectory") g.trajectory = val();
    else if (a == "--config") g.config = val();
    else if (a == "--threads") g.threads = (int)parseInt(a, val(), 1);
    else if (a == "--motion-blur") g.blur = true;
    else if (a == "--no-noise") g.no_noise = true;
    else if (a == "--no-objects") g.no_objects = true;
    else if (a == "--people-detail") g.people_detail = parseGain(a, val());
    else if (a == "--list-presets") g.list_presets = true;
    else if (a == "--list-textures") g.list_textures = true;
    else throw Error("unknown argument '" + a + "' (see --help)");
  }
  return g;
}

// The options of --config (or the defaults), with what the command line sets over them.
static sim::SynthOptions synthOptions(const Args& g) {
  sim::SynthOptions opt;
  if (!g.config.empty()) opt = sim::SynthOptions::load(Config::fromFile(g.config));
  if (!g.preset.empty()) opt.preset = g.preset;
  if (g.seed >= 0) opt.seed = (unsigned)g.seed;
  if (g.frames >= 0) opt.frames = (int)g.frames;
  if (!g.textures.empty()) opt.textures_dir = g.textures;
  if (!g.trajectory.empty()) opt.trajectory = g.trajectory;
  if (g.threads > 0) opt.threads = g.threads;
  if (g.blur) opt.sensor.motion_blur = true;
  if (g.no_noise) opt.sensor.noise = false;
  if (g.no_objects) opt.objects = false;
  if (g.people_detail >= 0) opt.people_detail = g.people_detail;
  return opt;
}

static void listPresets() {
  for (const auto& p : sim::presets())
    std::printf("%-15s %5d frames  motion %-10s  %s\n", p.name.c_str(), p.frames, p.motion.c_str(),
                p.description.c_str());
}

static void listTextures(const sim::SynthOptions& opt) {
  std::string dir = opt.textures_dir.empty() ? sim::defaultTextureDir() : opt.textures_dir;
  for (const auto& f : sim::listTextureFiles(dir)) std::printf("%s/%s\n", dir.c_str(), f.c_str());
}

static void writeContactSheet(const sim::SynthOptions& opt, std::vector<std::string> presets,
                              const std::string& path) {
  if (presets.empty())
    for (const auto& p : sim::presets()) presets.push_back(p.name);
  cv::Mat img = sim::contactSheet(opt, presets, {0, 300}, 200);
  if (!cv::imwrite(path, img, {cv::IMWRITE_PNG_COMPRESSION, 9}))
    throw Error("cannot write contact sheet " + path + ": check the folder exists and is writable");
}

static void generate(const sim::SynthOptions& opt, const std::string& out) {
  if (out.empty()) throw Error("--out DIR is required (see --help)");
  sim::SequenceGenerator gen(opt);
  double s = gen.generate(out, isatty(2));
  std::fprintf(stderr, "yolo_slam_synth: %zu frames of '%s' in %s (%.1f s, %.1f frames/s)\n", gen.size(),
               opt.preset.c_str(), out.c_str(), s, gen.size() / std::max(s, 1e-9));
}

int main(int argc, char** argv) {
  try {
    const Args args = parseArgs(argc, argv);
    if (args.help) {
      usage();
      return 0;
    }
    const sim::SynthOptions opt = synthOptions(args);
    if (args.list_presets) listPresets();
    else if (args.list_textures) listTextures(opt);
    else if (!args.sheet.empty()) writeContactSheet(opt, args.sheet_presets, args.sheet);
    else generate(opt, args.out);
    return 0;
  } catch (const std::exception& e) {
    std::string msg = e.what();
    for (auto& c : msg) if (c == '\n') c = ' ';
    std::fprintf(stderr, "error: %s\n", msg.c_str());
    return 1;
  }
}
