#include "ceres_sesync/internal/openmp_teams.h"

#include <dlfcn.h>

namespace ceres_sesync::internal {

namespace {

struct OpenMpRuntime {
  int (*get_dynamic)() = nullptr;
  void (*set_dynamic)(int) = nullptr;
  int (*get_max_threads)() = nullptr;
  void (*set_num_threads)(int) = nullptr;
};

// libgomp's ICV accessors if it is loaded (CHOLMOD depends on it);
// RTLD_NOLOAD never loads it. Looked up once.
const OpenMpRuntime& Runtime() {
  static const OpenMpRuntime runtime = []() -> OpenMpRuntime {
    // The handle is kept: the library stays loaded while CHOLMOD is.
    void* gomp = dlopen("libgomp.so.1", RTLD_LAZY | RTLD_NOLOAD);
    if (gomp == nullptr) return {};
    OpenMpRuntime r;
    r.get_dynamic = reinterpret_cast<int (*)()>(dlsym(gomp, "omp_get_dynamic"));
    r.set_dynamic =
        reinterpret_cast<void (*)(int)>(dlsym(gomp, "omp_set_dynamic"));
    r.get_max_threads =
        reinterpret_cast<int (*)()>(dlsym(gomp, "omp_get_max_threads"));
    r.set_num_threads =
        reinterpret_cast<void (*)(int)>(dlsym(gomp, "omp_set_num_threads"));
    const bool complete = r.get_dynamic && r.set_dynamic && r.get_max_threads &&
                          r.set_num_threads;
    return complete ? r : OpenMpRuntime{};
  }();
  return runtime;
}

}  // namespace

ScopedSerialOpenMpTeams::ScopedSerialOpenMpTeams() {
  const OpenMpRuntime& runtime = Runtime();
  if (runtime.set_dynamic == nullptr) return;
  dynamic_ = runtime.get_dynamic() != 0;
  max_threads_ = runtime.get_max_threads();
  runtime.set_dynamic(1);
  runtime.set_num_threads(1);
}

ScopedSerialOpenMpTeams::~ScopedSerialOpenMpTeams() {
  const OpenMpRuntime& runtime = Runtime();
  if (runtime.set_dynamic == nullptr) return;
  runtime.set_dynamic(dynamic_ ? 1 : 0);
  runtime.set_num_threads(max_threads_);
}

bool ScopedSerialOpenMpTeams::RuntimeLoaded() {
  return Runtime().set_dynamic != nullptr;
}

bool ScopedSerialOpenMpTeams::Dynamic() {
  const OpenMpRuntime& runtime = Runtime();
  return runtime.get_dynamic != nullptr && runtime.get_dynamic() != 0;
}

int ScopedSerialOpenMpTeams::MaxThreads() {
  const OpenMpRuntime& runtime = Runtime();
  return runtime.get_max_threads != nullptr ? runtime.get_max_threads() : 0;
}

}  // namespace ceres_sesync::internal
