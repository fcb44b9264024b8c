#include "bench/bench_util.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

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

}  // namespace ceres_sesync::bench
