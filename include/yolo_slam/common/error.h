#pragma once
// One exception type for every user-facing failure of the core: the message names the file
// (and line or key, where there is one) and says how to fix it. Tools catch it at main() and
// print it as a one-line error with a non-zero exit code.
#include <stdexcept>
#include <string>

namespace yolo_slam {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace yolo_slam
