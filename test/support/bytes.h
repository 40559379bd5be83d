#pragma once
// Whole files as bytes, for tests that damage files on purpose.
#include <fstream>
#include <sstream>
#include <string>

// Global namespace, like mutate.h (the fuzz tests use both).
namespace test_support {

inline std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

inline void writeBytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

}  // namespace test_support
