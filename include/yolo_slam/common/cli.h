#pragma once
// The one main() wrapper of the command-line tools: every failure ends as a single
// "error: <message>" line on stderr and exit code 1, never as an uncaught exception.
namespace yolo_slam {

int runGuarded(int (*run)(int, char**), int argc, char** argv);

}  // namespace yolo_slam
