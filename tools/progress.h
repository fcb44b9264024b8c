// Progress display of long solves on stderr (`solve`, `certify --improve`):
// the SolverProgress reports of SolverOptions::progress, shown either as one
// status line redrawn in place (a terminal) or as plain lines (a pipe or
// file, with --progress).
//
//   --progress      on: a status line on a terminal, plain lines otherwise;
//   --noprogress    off;
//   (not given)     a status line when stderr is a terminal and the solve
//                   has run for 0.2 s; nothing when stderr is not a terminal.

#ifndef CERES_SESYNC_TOOLS_PROGRESS_H_
#define CERES_SESYNC_TOOLS_PROGRESS_H_

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "ceres_sesync/sesync_solver.h"
#include "gflags/gflags.h"

DECLARE_bool(progress);

namespace ceres_sesync::tools {

class ProgressPrinter {
 public:
  enum class Style {
    // One line, redrawn in place ("\r" + erase to end of line) at most every
    // 0.1 s, erased by Finish().
    kStatusLine,
    // One line per new stage or level, and per iteration at most every
    // second.
    kLines,
  };
  // Shows nothing before `delay_s` seconds have passed since construction.
  ProgressPrinter(Style style, std::FILE* out, double delay_s = 0);
  ~ProgressPrinter();
  ProgressPrinter(const ProgressPrinter&) = delete;
  ProgressPrinter& operator=(const ProgressPrinter&) = delete;

  void Show(const SolverProgress& progress);
  // Erases the status line (kStatusLine); later reports draw it again.
  void Finish();
  // A callback for SolverOptions::progress that shows on this printer.
  std::function<void(const SolverProgress&)> Callback();

  // The text of one report, e.g. "[   1.20 s] optimize  rank 5  iter 12  F
  // 1.2345679e+03  |grad| 2.1e-04", with "component 2/3: " in front when
  // there are several; `seconds` is the time shown.
  static std::string Format(const SolverProgress& progress, double seconds);

 private:
  double Seconds() const;

  Style style_;
  std::FILE* out_;
  double delay_s_;
  std::chrono::steady_clock::time_point start_;
  double last_shown_s_ = -1e300;
  std::string last_key_;  // Stage, rank and component of the last report.
  bool line_drawn_ = false;
};

// The printer that --progress and stderr ask for (see above), or null.
std::unique_ptr<ProgressPrinter> ProgressPrinterFromFlags();

}  // namespace ceres_sesync::tools

#endif  // CERES_SESYNC_TOOLS_PROGRESS_H_
