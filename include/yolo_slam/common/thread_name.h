#pragma once
// Names the calling thread (shown by top -H, ps -L, gdb and perf): each pipeline stage runs in
// a thread of its own, and a profile per thread is how stage costs are told apart.

namespace yolo_slam {

// At most 15 characters are kept (the kernel's limit); a failure is ignored.
void nameThisThread(const char* name);

}  // namespace yolo_slam
