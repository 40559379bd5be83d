#pragma once
// Names the calling thread (shown by top -H, ps -L, gdb and perf): each pipeline stage runs in
// a thread of its own, and a profile per thread is how stage costs are told apart.

#include <functional>

namespace yolo_slam {

// At most 15 characters are kept (the kernel's limit); a failure is ignored.
void nameThisThread(const char* name);

// Raises the calling thread's nice value by `delta` (0..19) above the process's, so that on a
// busy machine the scheduler gives the frame thread precedence over background work (Linux:
// nice is per thread). When the kernel refuses, logs a warning naming `option_key` (the
// setting that asked for it) and the thread runs unchanged.
void lowerThisThreadPriority(int delta, const char* option_key);

// Runs `work` on a new thread called `name` at `delta` above the process's nice value, waits
// for it and rethrows what it threw; with delta 0, runs it in the caller's thread. For heavy
// work that holds no lock the frame thread needs: a niced thread holding such a lock is
// preempted while it holds it and stalls the frame thread (priority inversion).
void runAtLowerPriority(int delta, const char* name, const char* option_key, const std::function<void()>& work);

}  // namespace yolo_slam
