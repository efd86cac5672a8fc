#include "app/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace airtwin::cli {
namespace {

// "45 s", "3 min 20 s", "2 h 05 min": a time left as people read it.
std::string duration_text(double s) {
  char text[64];
  if (s < 120.0) {
    std::snprintf(text, sizeof text, "%.0f s", s);
  } else if (s < 7200.0) {
    const long total = std::lround(s);
    std::snprintf(text, sizeof text, "%ld min %02ld s", total / 60, total % 60);
  } else {
    const long minutes = std::lround(s / 60.0);
    std::snprintf(text, sizeof text, "%ld h %02ld min", minutes / 60, minutes % 60);
  }
  return text;
}

}  // namespace

Progress::Progress(std::string label, std::string unit, int total)
    : Progress(std::move(label), std::move(unit), total, Style{}) {}

Progress::Progress(std::string label, std::string unit, int total, Style style)
    : label_(std::move(label)),
      unit_(std::move(unit)),
      total_(total > 0 ? total : 1),
      style_(style),
      terminal_(isatty(fileno(stderr)) != 0),
      start_(std::chrono::steady_clock::now()) {
  style_.already_done = std::clamp(style_.already_done, 0, total_);
}

void Progress::update(int done) {
  // Rate and time left from the items of this session only.
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const int fresh = done - style_.already_done;
  const double rate = elapsed > 0 && fresh > 0 ? fresh / elapsed : 0.0;
  const double shown_rate = style_.per_minute ? 60.0 * rate : rate;
  const char* per = style_.per_minute ? "min" : "s";
  const std::string left = done >= total_ ? std::string("done")
                           : rate > 0     ? duration_text((total_ - done) / rate) + " left"
                                          : std::string("time left unknown yet");
  std::string bar;
  if (style_.bar) {
    constexpr int kWidth = 24;
    const int filled = static_cast<int>(static_cast<long long>(kWidth) * done / total_);
    bar = " [" + std::string(filled, '#') + std::string(kWidth - filled, '-') + "]";
  }
  if (terminal_) {
    // Rewrite the line in place and clear what a longer previous line left (ESC [K).
    std::fprintf(stderr, "\r%s%s %d/%d %s, %.2f %s/%s, %s\033[K", label_.c_str(), bar.c_str(), done,
                 total_, unit_.c_str(), shown_rate, unit_.c_str(), per, left.c_str());
    open_line_ = true;
    if (done >= total_) finish();
  } else {
    // A plain line at each tenth of the work, or when the heartbeat is due.
    const int decile = done * 10 / total_;
    const bool heartbeat = style_.heartbeat_s > 0 && elapsed - last_line_s_ >= style_.heartbeat_s;
    if (decile == last_decile_ && !heartbeat) return;
    last_decile_ = decile;
    last_line_s_ = elapsed;
    std::fprintf(stderr, "%s %d/%d %s, %.2f %s/%s, %s\n", label_.c_str(), done, total_,
                 unit_.c_str(), shown_rate, unit_.c_str(), per, left.c_str());
  }
  std::fflush(stderr);
}

void Progress::finish() {
  if (open_line_) std::fputc('\n', stderr);
  open_line_ = false;
}

Progress::~Progress() { finish(); }

}  // namespace airtwin::cli
