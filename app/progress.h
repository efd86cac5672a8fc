#pragma once
// Progress of long work on stderr: on a terminal one line rewritten in place ("collect 37/100,
// 4.1 trials/s, 15 s left"), otherwise a plain line at every tenth of the work, so logs stay
// readable. Thread-compatible: call update() from one thread at a time.

#include <chrono>
#include <string>

namespace airtwin::cli {

class Progress {
 public:
  /// `label` starts each line; `unit` names what is counted ("trials"); `total` > 0.
  Progress(std::string label, std::string unit, int total);
  /// `done` items finished so far (0..total).
  void update(int done);
  /// Ends the line on a terminal (idempotent; also called by the destructor).
  void finish();
  ~Progress();

 private:
  std::string label_, unit_;
  int total_;
  int last_decile_ = -1;
  bool terminal_;
  bool open_line_ = false;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace airtwin::cli
