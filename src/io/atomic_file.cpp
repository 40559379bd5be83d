#include "yolo_slam/io/atomic_file.h"

#include "yolo_slam/common/error.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

#include <unistd.h>

namespace yolo_slam {
namespace io {

std::string temporaryPathOf(const std::string& path) { return path + ".tmp"; }

void writeFileAtomic(const std::string& path, const std::string& content) {
  const std::string tmp = temporaryPathOf(path);
  std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(tmp.c_str(), "wb"), &std::fclose);
  if (!f)
    throw Error(path + ": cannot write file (" + std::strerror(errno) +
                "); check that the folder exists and is writable and that no folder has the name " + tmp);
  bool ok = std::fwrite(content.data(), 1, content.size(), f.get()) == content.size();
  ok = (std::fflush(f.get()) == 0) && ok;
  // On disk before the rename: a power cut never leaves an empty file under the final name.
  ok = (::fsync(::fileno(f.get())) == 0) && ok;
  int err = ok ? 0 : errno;
  ok = (std::fclose(f.release()) == 0) && ok;
  if (ok && std::rename(tmp.c_str(), path.c_str()) != 0) ok = false;
  if (!ok) {
    if (err == 0) err = errno;
    std::remove(tmp.c_str());
    throw Error(path + ": failed to write file (" + std::strerror(err) +
                "); free disk space, or remove the folder of that name if there is one");
  }
}

}  // namespace io
}  // namespace yolo_slam
