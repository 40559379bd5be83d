#include "yolo_slam/common/cli.h"

#include <cstdio>
#include <exception>
#include <iostream>

namespace yolo_slam {

int runGuarded(int (*run)(int, char**), int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    // Whatever the tool printed so far comes before the error line.
    std::cout.flush();
    std::fflush(stdout);
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}

}  // namespace yolo_slam
