#include "bench/bench_util.h"

#include <dlfcn.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "ceres_sesync/process_memory.h"
#include "gflags/gflags.h"
#include "glog/logging.h"

DEFINE_bool(keep_freed_memory, true,
            "Keep freed memory in the process (KeepFreedMemory(), "
            "process_memory.h) for every method alike; false: glibc's "
            "defaults.");

namespace ceres_sesync::bench {

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double Sum(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return s;
}

double Min(const std::vector<double>& v) {
  return v.empty() ? NAN : *std::min_element(v.begin(), v.end());
}

double Median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const size_t k = v.size() / 2;
  return v.size() % 2 ? v[k] : 0.5 * (v[k - 1] + v[k]);
}

std::string Fmt(const char* format, double v) {
  if (std::isnan(v)) return "";
  char buf[64];
  std::snprintf(buf, sizeof(buf), format, v);
  return buf;
}

std::string CsvField(const std::string& s) {
  if (s.find_first_of(",\"") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += (c == '"') ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::vector<int> ParseInts(const std::string& s) {
  std::vector<int> out;
  std::stringstream in(s);
  std::string token;
  while (std::getline(in, token, ',')) {
    if (!token.empty()) out.push_back(std::stoi(token));
  }
  return out;
}

std::vector<double> ParseDoubles(const std::string& s) {
  std::vector<double> out;
  std::stringstream in(s);
  std::string token;
  while (std::getline(in, token, ',')) {
    if (!token.empty()) out.push_back(std::stod(token));
  }
  return out;
}

double PeakRssMiB() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmHWM:", 0) == 0) {
      std::istringstream s(line.substr(6));
      double kb = 0;
      s >> kb;
      return kb / 1024.0;
    }
  }
  return NAN;
}

std::string BlasLibrary() {
  void* symbol = dlsym(RTLD_DEFAULT, "dgemm_");
  Dl_info info;
  if (symbol == nullptr || dladdr(symbol, &info) == 0 ||
      info.dli_fname == nullptr) {
    return "unknown";
  }
  // Follow the alternatives' links (libblas.so.3 -> .../atlas/libblas.so.3).
  char resolved[4096];
  if (realpath(info.dli_fname, resolved) != nullptr) return resolved;
  return info.dli_fname;
}

std::string CeresStatus(const CeresBaselineSummary& summary) {
  const ceres::Solver::Summary& c = summary.solver_summary;
  if (c.termination_type == ceres::CONVERGENCE) return "converged";
  if (c.termination_type == ceres::NO_CONVERGENCE) {
    if (c.message.find("time") != std::string::npos) return "timeout";
    if (c.message.find("iteration") != std::string::npos) {
      return "max_iterations";
    }
    return "no_convergence";
  }
  return ceres::TerminationTypeToString(c.termination_type);
}

void InitBenchProgram(int* argc, char*** argv) {
  gflags::ParseCommandLineFlags(argc, argv, /*remove_flags=*/true);
  if (FLAGS_keep_freed_memory && !KeepFreedMemory()) {
    std::fprintf(stderr, "note: KeepFreedMemory() not available here\n");
  }
  google::InitGoogleLogging((*argv)[0]);
  FLAGS_logtostderr = true;
  if (FLAGS_minloglevel < google::GLOG_WARNING) {
    FLAGS_minloglevel = google::GLOG_WARNING;
  }
}

bool RunInChildProcess(double timeout_s, double max_memory_gb,
                       const std::function<void(void* buffer)>& child,
                       void* out, size_t size, std::string* failure) {
  int fds[2];
  if (pipe(fds) != 0) {
    *failure = std::string("pipe: ") + std::strerror(errno);
    return false;
  }
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t pid = fork();
  if (pid < 0) {
    *failure = std::string("fork: ") + std::strerror(errno);
    close(fds[0]);
    close(fds[1]);
    return false;
  }
  if (pid == 0) {
    close(fds[0]);
    alarm(static_cast<unsigned>(std::max(1.0, timeout_s)));
    if (max_memory_gb > 0) {
      const rlim_t bytes =
          static_cast<rlim_t>(max_memory_gb * 1024 * 1024 * 1024);
      const struct rlimit limit = {bytes, bytes};
      setrlimit(RLIMIT_AS, &limit);
    }
    std::vector<char> buffer(size);
    child(buffer.data());
    const char* p = buffer.data();
    size_t left = size;
    while (left > 0) {
      const ssize_t k = write(fds[1], p, left);
      if (k <= 0) _exit(3);
      p += k;
      left -= k;
    }
    _exit(0);
  }
  close(fds[1]);
  char* p = static_cast<char*>(out);
  size_t got = 0;
  while (got < size) {
    const ssize_t k = read(fds[0], p + got, size - got);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) break;
    got += k;
  }
  close(fds[0]);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (got == size && WIFEXITED(status) && WEXITSTATUS(status) == 0) {
    return true;
  }
  if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    *failure = sig == SIGALRM ? "killed at --child_timeout"
                              : "killed by signal " + std::to_string(sig) +
                                    " (" + strsignal(sig) + ")";
  } else {
    *failure = "child exited with " +
               std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) +
               " (memory limit?)";
  }
  return false;
}

std::vector<LandmarkCase> LandmarkCases(bool quick) {
  const int n = quick ? 300 : 2000;
  std::vector<LandmarkCase> cases;
  LandmarkGraphOptions m2;
  m2.dimension = 2;
  m2.num_poses = n;
  m2.world_size = 40;
  m2.num_landmarks = 400;
  m2.sensor_range = 5;
  m2.seed = 1;
  cases.push_back({"manhattan2d", m2});
  LandmarkGraphOptions g2 = m2;
  g2.gps_interval = 20;
  g2.start_prior = true;
  cases.push_back({"manhattan2d_gps", g2});
  LandmarkGraphOptions m3 = m2;
  m3.dimension = 3;
  m3.world_size = 20;
  m3.num_landmarks = 600;
  cases.push_back({"manhattan3d", m3});
  LandmarkGraphOptions g3 = m3;
  g3.gps_interval = 20;
  g3.start_prior = true;
  cases.push_back({"manhattan3d_gps", g3});
  LandmarkGraphOptions v = VictoriaParkLikeOptions();
  v.seed = 1;
  if (quick) v.num_poses = n;
  cases.push_back({"victoria", v});
  return cases;
}

}  // namespace ceres_sesync::bench
