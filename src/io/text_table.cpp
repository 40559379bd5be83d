#include "yolo_slam/io/text_table.h"

#include "yolo_slam/common/error.h"
#include "yolo_slam/common/paths.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace yolo_slam {
namespace io {

void throwAtLine(const std::string& path, size_t line, const std::string& msg) {
  throw Error(path + ":" + std::to_string(line) + ": " + msg);
}

std::vector<TextRow> readTextTable(const std::string& path) {
  if (dirExists(path)) throw Error(path + ": is a folder, expected a text file");
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open file (missing or unreadable); check the path");
  std::vector<TextRow> rows;
  std::string text;
  size_t line_no = 0;
  while (std::getline(in, text)) {
    ++line_no;
    if (!text.empty() && text.back() == '\r') text.pop_back();  // files written on Windows
    // associate.py treats ',' and tabs as separators too.
    for (char& c : text) {
      if (c == ',' || c == '\t') c = ' ';
    }
    size_t first = text.find_first_not_of(' ');
    if (first == std::string::npos || text[first] == '#') continue;
    TextRow row;
    row.line = line_no;
    std::istringstream ss(text);
    std::string f;
    while (ss >> f) row.fields.push_back(f);
    rows.push_back(std::move(row));
  }
  if (in.bad()) throw Error(path + ":" + std::to_string(line_no + 1) + ": read error");
  return rows;
}

double parseFiniteDouble(const std::string& field, const std::string& path, size_t line,
                         const std::string& what) {
  const char* s = field.c_str();
  char* end = nullptr;
  errno = 0;
  double v = std::strtod(s, &end);
  if (end == s || *end != '\0') {
    throwAtLine(path, line, what + " '" + field + "' is not a number");
  }
  if (!std::isfinite(v) || errno == ERANGE) {
    throwAtLine(path, line, what + " '" + field + "' is not a finite number (NaN or inf)");
  }
  return v;
}

}  // namespace io
}  // namespace yolo_slam
