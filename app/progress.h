#pragma once
// Progress of long work on stderr: on a terminal one line rewritten in place ("collect 37/100,
// 4.1 trials/s, 15 s left"), otherwise a plain line at every tenth of the work, so logs stay
// readable. Thread-compatible: call update() from one thread at a time.
//
// For long work (a batch of runs) a Style adds a bar on the terminal ("batch [######----] 37/100
// runs, 12.3 runs/min, 5 min 07 s left"), the rate per minute, work finished before this session
// (counted as done, not in the rate: a resumed batch's time left is honest), and a plain line at
// least every heartbeat_s so that a cluster's log shows the work is alive.

#include <chrono>
#include <string>

namespace airtwin::cli {

class Progress {
 public:
  struct Style {
    bool bar = false;         ///< a bar on a terminal
    bool per_minute = false;  ///< the rate per minute instead of per second
    int already_done = 0;     ///< items finished before this session (0..total)
    double heartbeat_s = 0;   ///< not a terminal: a line at least this often (0: only tenths)
  };

  /// `label` starts each line; `unit` names what is counted ("trials"); `total` > 0.
  Progress(std::string label, std::string unit, int total);
  Progress(std::string label, std::string unit, int total, Style style);
  /// `done` items finished so far (0..total).
  void update(int done);
  /// Ends the line on a terminal (idempotent; also called by the destructor).
  void finish();
  ~Progress();

 private:
  std::string label_, unit_;
  int total_;
  Style style_;
  int last_decile_ = -1;
  double last_line_s_ = 0.0;
  bool terminal_;
  bool open_line_ = false;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace airtwin::cli
