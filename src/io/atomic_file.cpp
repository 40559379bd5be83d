#include "yolo_slam/io/atomic_file.h"

#include "yolo_slam/common/error.h"

#include <cstdio>
#include <memory>

namespace yolo_slam {
namespace io {

void writeFileAtomic(const std::string& path, const std::string& content) {
  const std::string tmp = path + ".tmp";
  std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(tmp.c_str(), "wb"), &std::fclose);
  if (!f) throw Error(path + ": cannot write file (does the folder exist and is it writable?)");
  bool ok = std::fwrite(content.data(), 1, content.size(), f.get()) == content.size();
  ok = (std::fflush(f.get()) == 0) && ok;
  ok = (std::fclose(f.release()) == 0) && ok;
  if (!ok || std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw Error(path + ": failed to write file (disk full or not writable?)");
  }
}

}  // namespace io
}  // namespace yolo_slam
