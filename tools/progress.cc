#include "tools/progress.h"

#include <sys/ioctl.h>
#include <unistd.h>

#include <cstring>

DEFINE_bool(progress, false,
            "Show solver progress on stderr (level, iteration, F, gradient "
            "norm, time). Not given: only when stderr is a terminal; "
            "--noprogress: never.");

namespace ceres_sesync::tools {

ProgressPrinter::ProgressPrinter(Style style, std::FILE* out, double delay_s)
    : style_(style),
      out_(out),
      delay_s_(delay_s),
      start_(std::chrono::steady_clock::now()) {}

ProgressPrinter::~ProgressPrinter() { Finish(); }

double ProgressPrinter::Seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                       start_)
      .count();
}

std::string ProgressPrinter::Format(const SolverProgress& p, double seconds) {
  std::string out;
  char buf[256];
  auto add = [&](const char* format, auto... args) {
    std::snprintf(buf, sizeof(buf), format, args...);
    out += buf;
  };
  add("[%8.2f s] ", seconds);
  if (p.num_components > 1) {
    add("component %d/%d: ", p.component + 1, p.num_components);
  }
  const bool done = std::strcmp(p.stage, "done") == 0;
  add("%-10s", p.stage);
  if (p.rank > 0) add("  rank %d", p.rank);
  if (p.rank > 0 && std::strcmp(p.stage, "round") != 0) {
    add("  iter %d", p.iteration);
    add(done ? "  F(x) %.8e" : "  F %.8e", p.objective);
    if (p.gradient_norm > 0) add("  |grad| %.2e", p.gradient_norm);
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

void ProgressPrinter::Show(const SolverProgress& p) {
  const double now = Seconds();
  if (now < delay_s_) return;
  const std::string key = std::string(p.stage) + " " + std::to_string(p.rank) +
                          " " + std::to_string(p.component);
  const bool is_new = key != last_key_;
  const double interval = style_ == Style::kStatusLine ? 0.1 : 1.0;
  if (!is_new && now - last_shown_s_ < interval) return;
  last_key_ = key;
  last_shown_s_ = now;
  std::string text = Format(p, now);
  if (style_ == Style::kStatusLine) {
    // A line longer than the terminal would wrap, and "\r" would then redraw
    // only its last row.
    winsize size{};
    if (ioctl(fileno(out_), TIOCGWINSZ, &size) == 0 && size.ws_col > 1 &&
        text.size() >= size.ws_col) {
      text.resize(size.ws_col - 1);
    }
    std::fprintf(out_, "\r\033[K%s", text.c_str());
    line_drawn_ = true;
  } else {
    std::fprintf(out_, "%s\n", text.c_str());
  }
  std::fflush(out_);
}

void ProgressPrinter::Finish() {
  if (!line_drawn_) return;
  std::fputs("\r\033[K", out_);
  std::fflush(out_);
  line_drawn_ = false;
}

std::function<void(const SolverProgress&)> ProgressPrinter::Callback() {
  return [this](const SolverProgress& p) { Show(p); };
}

std::unique_ptr<ProgressPrinter> ProgressPrinterFromFlags() {
  gflags::CommandLineFlagInfo info;
  const bool given =
      gflags::GetCommandLineFlagInfo("progress", &info) && !info.is_default;
  const bool terminal = isatty(fileno(stderr)) == 1;
  using Style = ProgressPrinter::Style;
  if (given) {
    if (!FLAGS_progress) return nullptr;
    return std::make_unique<ProgressPrinter>(
        terminal ? Style::kStatusLine : Style::kLines, stderr);
  }
  if (!terminal) return nullptr;
  return std::make_unique<ProgressPrinter>(Style::kStatusLine, stderr,
                                           /*delay_s=*/0.2);
}

}  // namespace ceres_sesync::tools
