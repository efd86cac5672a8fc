#include "app/progress.h"

#include <unistd.h>

#include <cstdio>

namespace airtwin::cli {

Progress::Progress(std::string label, std::string unit, int total)
    : label_(std::move(label)),
      unit_(std::move(unit)),
      total_(total > 0 ? total : 1),
      terminal_(isatty(fileno(stderr)) != 0),
      start_(std::chrono::steady_clock::now()) {}

void Progress::update(int done) {
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double rate = elapsed > 0 ? done / elapsed : 0.0;
  const double left = rate > 0 ? (total_ - done) / rate : 0.0;
  if (terminal_) {
    std::fprintf(stderr, "\r%s %d/%d %s, %.2f %s/s, %.0f s left   ", label_.c_str(), done, total_,
                 unit_.c_str(), rate, unit_.c_str(), left);
    open_line_ = true;
    if (done >= total_) finish();
  } else {
    const int decile = done * 10 / total_;
    if (decile == last_decile_) return;
    last_decile_ = decile;
    std::fprintf(stderr, "%s %d/%d %s, %.2f %s/s, %.0f s left\n", label_.c_str(), done, total_,
                 unit_.c_str(), rate, unit_.c_str(), left);
  }
  std::fflush(stderr);
}

void Progress::finish() {
  if (open_line_) std::fputc('\n', stderr);
  open_line_ = false;
}

Progress::~Progress() { finish(); }

}  // namespace airtwin::cli
