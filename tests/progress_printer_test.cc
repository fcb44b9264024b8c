// Tests of the command line's progress display (tools/progress.h).

#include <cstdio>
#include <string>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tools/progress.h"

namespace ceres_sesync::tools {
namespace {

using testing::HasSubstr;
using testing::Not;

// Everything written to `file` so far.
std::string Contents(std::FILE* file) {
  std::fflush(file);
  std::rewind(file);
  std::string text;
  char buffer[4096];
  size_t n;
  while ((n = std::fread(buffer, 1, sizeof(buffer), file)) > 0) {
    text.append(buffer, n);
  }
  return text;
}

SolverProgress Report(const char* stage, int rank, int iteration, double f) {
  SolverProgress p;
  p.stage = stage;
  p.rank = rank;
  p.iteration = iteration;
  p.objective = f;
  p.gradient_norm = f > 0 ? 1e-3 : 0;
  return p;
}

TEST(ProgressPrinter, FormatsOneReport) {
  SolverProgress p = Report("optimize", 5, 12, 1234.5);
  EXPECT_EQ(ProgressPrinter::Format(p, 1.5),
            "[    1.50 s] optimize    rank 5  iter 12  F 1.23450000e+03  "
            "|grad| 1.00e-03");
  p.component = 1;
  p.num_components = 3;
  EXPECT_THAT(ProgressPrinter::Format(p, 0), HasSubstr("] component 2/3: "));
  EXPECT_EQ(ProgressPrinter::Format(Report("data", 0, 0, 0), 0),
            "[    0.00 s] data");
  EXPECT_EQ(ProgressPrinter::Format(Report("round", 5, 0, 0), 0),
            "[    0.00 s] round       rank 5");
  EXPECT_THAT(ProgressPrinter::Format(Report("done", 5, 7, 2.5), 0),
              HasSubstr("F(x) 2.50000000e+00"));
}

TEST(ProgressPrinter, LinesShowEveryNewStageAndThrottleIterations) {
  std::FILE* file = std::tmpfile();
  ASSERT_NE(file, nullptr);
  {
    ProgressPrinter printer(ProgressPrinter::Style::kLines, file);
    printer.Show(Report("optimize", 5, 0, 10));
    for (int k = 1; k <= 50; ++k) printer.Show(Report("optimize", 5, k, 9));
    printer.Show(Report("verify", 5, 50, 9));
    printer.Show(Report("optimize", 6, 0, 9));
    printer.Show(Report("done", 6, 60, 8));
  }
  const std::string text = Contents(file);
  std::fclose(file);
  // 50 iterations within a second: none of them shown.
  EXPECT_THAT(text, Not(HasSubstr("iter 1 ")));
  int lines = 0;
  for (char c : text) lines += c == '\n';
  EXPECT_EQ(lines, 4) << text;
  EXPECT_THAT(text, HasSubstr("verify      rank 5  iter 50"));
  EXPECT_THAT(text, HasSubstr("optimize    rank 6  iter 0"));
  EXPECT_THAT(text, Not(HasSubstr("\r")));
}

TEST(ProgressPrinter, StatusLineIsRedrawnInPlaceAndErased) {
  std::FILE* file = std::tmpfile();
  ASSERT_NE(file, nullptr);
  ProgressPrinter printer(ProgressPrinter::Style::kStatusLine, file);
  printer.Show(Report("optimize", 5, 0, 10));
  printer.Show(Report("optimize", 5, 1, 9));  // Within 0.1 s: not drawn.
  printer.Show(Report("verify", 5, 1, 9));
  printer.Finish();
  const std::string text = Contents(file);
  std::fclose(file);
  EXPECT_EQ(text.find("\r\033[K[    0.00 s] optimize    rank 5  iter 0"), 0u)
      << text;
  EXPECT_THAT(text, Not(HasSubstr("optimize    rank 5  iter 1")));
  EXPECT_THAT(text, HasSubstr("\r\033[K[    0.00 s] verify"));
  EXPECT_THAT(text, Not(HasSubstr("\n")));
  // Finish() erases the line.
  EXPECT_EQ(text.substr(text.size() - 4), "\r\033[K");
}

TEST(ProgressPrinter, NothingBeforeTheDelay) {
  std::FILE* file = std::tmpfile();
  ASSERT_NE(file, nullptr);
  {
    ProgressPrinter printer(ProgressPrinter::Style::kStatusLine, file, 60);
    printer.Show(Report("optimize", 5, 0, 10));
  }
  EXPECT_EQ(Contents(file), "");
  std::fclose(file);
}

}  // namespace
}  // namespace ceres_sesync::tools
