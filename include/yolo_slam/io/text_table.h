#pragma once
// Reading the whitespace-separated text lists of the TUM RGB-D benchmark (rgb.txt, depth.txt,
// groundtruth.txt, associations, trajectories): '#' starts a comment line, blank lines are
// skipped, ',' and tabs count as spaces (as TUM's associate.py reads them). Every error names
// the file and the 1-based line.
#include <cstddef>
#include <string>
#include <vector>

namespace yolo_slam {
namespace io {

struct TextRow {
  size_t line = 0;                  // 1-based line number in the file
  std::vector<std::string> fields;  // non-empty fields of that line
};

// Reads all non-comment, non-blank rows. Throws yolo_slam::Error naming the file when it is
// missing or unreadable.
std::vector<TextRow> readTextTable(const std::string& path);

// Parses a finite double from `field`; throws yolo_slam::Error "<path>:<line>: ..." naming
// `what` when it is not a number, NaN or infinite.
double parseFiniteDouble(const std::string& field, const std::string& path, size_t line,
                         const std::string& what);

// Throws yolo_slam::Error with the message "<path>:<line>: <msg>".
[[noreturn]] void throwAtLine(const std::string& path, size_t line, const std::string& msg);

}  // namespace io
}  // namespace yolo_slam
