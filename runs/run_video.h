#pragma once
// The video of a closed-loop run (`airtwin run --video`): the twin's top camera rendered every
// kept camera frame (renders/frame_renderer.h), the overlay for people drawn on it (the reference
// path or zones, the current reference, the stagnation point, the nozzle heading, trails, time;
// renders/overlay.h) and encoded as H.264 at 40 fps (renders/video_writer.h) on the encoder's own
// thread. With a stride k only every k-th camera frame is rendered and kept: the video then plays
// k times faster than the simulation, as its sidecar JSON says.
//
// The overlay is drawn on the picture saved for people only; the perception (truth or vision)
// never sees it.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "controller/closed_loop.h"
#include "controller/task.h"
#include "renders/video_writer.h"
#include "sim/twin.h"

namespace airtwin {

class RunVideo {
 public:
  /// Opens `path` (its folder must exist). `caption` is drawn under the time. Throws InputError
  /// as VideoWriter does.
  RunVideo(const std::string& path, const TaskSpec& task, const std::string& caption,
           int stride = 1);
  ~RunVideo();
  RunVideo(const RunVideo&) = delete;
  RunVideo& operator=(const RunVideo&) = delete;

  /// One camera frame of the run; `decisions` so far (the last one's stagnation point and
  /// reference are drawn). The renderer is created on the first call, in the calling thread.
  void on_frame(const Twin& twin, int64_t frame_index,
                const std::vector<DecisionRecord>& decisions);

  /// Flushes and finalises the file and its sidecar.
  VideoSummary close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace airtwin
