// airtwin render: a synthetic camera dataset of a scenario. The twin is built from the scenario's
// objects, the jet runs (settled) at one fixed nozzle orientation, and the top camera renders N
// frames at its 40 Hz of simulated time (section II-A), the twin stepping between frames. Writes
//   DIR/frames/frame_000000.png ...   the camera's frames (what vision reads)
//   DIR/truth.csv                     frame,t,id,object,x,y,x_px,y_px (the renderer's ground truth)
//   DIR/nozzle.csv                    t,pan_deg,tilt_deg: the one command, in force from t = 0
//   DIR/calibration/                  views of a checkerboard for the camera calibration
// and optionally an H.264 video (with overlays for people when --overlay). docs/rendering.md.

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "app/cli_common.h"
#include "app/commands.h"
#include "app/progress.h"
#include "common/errors.h"
#include "common/units.h"
#include "controller/task.h"
#include "models/air_field.h"
#include "models/field_model_file.h"
#include "models/nozzle_log.h"
#include "renders/calibration_target.h"
#include "renders/camera_model.h"
#include "renders/frame_renderer.h"
#include "renders/overlay.h"
#include "renders/png.h"
#include "renders/video_writer.h"
#include "scenes/scenario.h"
#include "sim/twin.h"

#if defined(__SANITIZE_ADDRESS__)
// LeakSanitizer (the AIRTWIN_SANITIZE build): Mesa's OSMesa keeps a small record for every buffer
// bound with OSMesaMakeCurrent and offers no call to free it (as tests/renders/lsan_osmesa.cc
// explains). The binary renders, so it suppresses leaks inside libOSMesa, and nothing else.
extern "C" const char* __lsan_default_suppressions();
extern "C" const char* __lsan_default_suppressions() { return "leak:libOSMesa.so\n"; }
// Without the statistics of the suppressions used: a run's stderr stays its one-line contract.
extern "C" const char* __lsan_default_options();
extern "C" const char* __lsan_default_options() { return "print_suppressions=0"; }
#endif

namespace airtwin::cli {
namespace {

constexpr double kCameraRateHz = 40.0;  // section II-A: 1024 x 1024 px at 40 Hz

struct RenderArgs {
  std::string scenario;
  int frames = 0;
  uint64_t seed = 1;
  std::string noise = "none";
  double pan_deg = 0.0;
  double tilt_deg = 20.0;
  bool overlay = false;
  std::string video;
  int stride = 1;
  int calibration_views = 8;
  std::string out;
  bool quiet = false;
  AirFlags air;
  std::string table;
};

void make_dir(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir)) {
    throw InputError(dir + ": cannot create directory: " + ec.message());
  }
}

// PNG encoding (~20 ms a frame) on a thread of its own behind a short queue, so that rendering
// the next frame overlaps it. Frames are written in order; the first failure is rethrown.
class PngWriterThread {
 public:
  explicit PngWriterThread(size_t capacity) : capacity_(capacity) {
    worker_ = std::thread([this] { run(); });
  }
  ~PngWriterThread() {
    if (worker_.joinable()) {
      try {
        finish();
      } catch (const std::exception&) {
        // Reported by finish() when called explicitly; here the run is failing already.
      }
    }
  }

  void write(const std::string& path, const cv::Mat& image) {
    std::unique_lock lock(mutex_);
    room_.wait(lock, [&] { return jobs_.size() < capacity_ || !error_.empty(); });
    if (!error_.empty()) throw InputError(error_);
    jobs_.push_back({path, image.clone()});
    lock.unlock();
    ready_.notify_one();
  }

  /// Waits until everything queued is written; throws the first error.
  void finish() {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    ready_.notify_all();
    if (worker_.joinable()) worker_.join();
    if (!error_.empty()) throw InputError(error_);
  }

 private:
  struct Job {
    std::string path;
    cv::Mat image;
  };
  void run() {
    for (;;) {
      Job job;
      {
        std::unique_lock lock(mutex_);
        ready_.wait(lock, [&] { return stopping_ || !jobs_.empty(); });
        if (jobs_.empty()) return;
        job = std::move(jobs_.front());
        jobs_.pop_front();
      }
      room_.notify_one();
      std::string error;
      try {
        write_png(job.path, job.image);
      } catch (const std::exception& e) {
        error = e.what();
      }
      if (!error.empty()) {
        std::lock_guard lock(mutex_);
        if (error_.empty()) error_ = error;
        jobs_.clear();
        room_.notify_all();
      }
    }
  }

  size_t capacity_;
  std::mutex mutex_;
  std::condition_variable ready_, room_;
  std::deque<Job> jobs_;
  bool stopping_ = false;
  std::string error_;
  std::thread worker_;
};

std::string frame_name(int k) {
  char name[32];
  std::snprintf(name, sizeof(name), "frame_%06d.png", k);
  return name;
}

// The object's 3-D centre as the renderer draws it: the area-weighted centres of mass of its
// bodies (the weights Twin::object_state uses), so that x_px, y_px include the small parallax of
// the body's height above the floor.
Eigen::Vector3d object_centre_W(const Twin& twin, size_t i) {
  const SceneObject& o = twin.object(i);
  const mjData* d = twin.data();
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < o.bodies.size(); ++k) {
    const int b = o.bodies[k];
    c += o.area_share[k] *
         Eigen::Vector3d(d->xipos[3 * b], d->xipos[3 * b + 1], d->xipos[3 * b + 2]);
  }
  return c;
}

// The overlay's fixed part from the task: the path and its references, or the zones.
OverlayData task_overlay(const Scenario& s) {
  OverlayData data;
  switch (s.task.kind) {
    case TaskKind::kPath:
      data.path_W = s.task.path_W;
      data.path_references_W = path_references(s.task);
      break;
    case TaskKind::kAggregation:
      data.zones.push_back({s.task.zone.centre_W, s.task.zone.radius_m, ""});
      break;
    case TaskKind::kSorting:
      for (const auto& [type, zone] : s.task.zones_by_type) {
        data.zones.push_back({zone.centre_W, zone.radius_m, type});
      }
      break;
  }
  return data;
}

void run_render(const RenderArgs& a) {
  // Flags first (usage errors, exit 2), then the scenario (input errors, exit 1).
  if (a.frames < 1 || a.frames > 10000000) {
    throw UsageError("--frames: expected a frame count >= 1, got " + std::to_string(a.frames));
  }
  const NoiseLevel noise = parse_noise(a.noise);
  if (!a.table.empty() && a.air.air != "model") throw UsageError("--table needs --air model");
  require_range(a.pan_deg, -180, 180, "--pan", "a pan angle in [-180, 180] deg");
  require_range(a.tilt_deg, 0, 60, "--tilt", "a tilt angle in [0, 60] deg");
  if (a.stride < 1)
    throw UsageError("--stride: expected an integer >= 1, got " + std::to_string(a.stride));
  if (a.calibration_views != 0 && (a.calibration_views < 3 || a.calibration_views > 100)) {
    throw UsageError("--calibration-views: expected 0 (none) or 3 to 100, got " +
                     std::to_string(a.calibration_views));
  }
  const Scenario scenario = read_scenario(a.scenario);

  // The twin: the scenario's objects, the jet on and settled at the given orientation.
  const AirFieldModel field = field_model_or_default(a.table);
  TwinParameters params;
  apply_air_flags(a.air, &params);
  const NozzleOrientation orientation{deg_to_rad(a.pan_deg), deg_to_rad(a.tilt_deg)};
  params.initial_orientation = orientation;
  params.jet_on_at_start = true;
  Twin twin(scenario.scene, params, field, a.seed);
  twin.command_nozzle(orientation);
  twin.set_jet(true);
  twin.settle_jet();

  // Outputs.
  const std::string frames_dir = a.out + "/frames";
  make_dir(frames_dir);
  const std::string overlay_dir = a.out + "/overlay";
  if (a.overlay && a.video.empty()) make_dir(overlay_dir);
  std::unique_ptr<VideoWriter> video;
  if (!a.video.empty()) {
    ensure_parent_dir(a.video);
    VideoOptions vo;
    vo.camera_rate_hz = kCameraRateHz;
    vo.stride = a.stride;
    video = std::make_unique<VideoWriter>(a.video, vo);
  }

  RenderOptions ro;
  ro.noise_sigma_grey = noise.noise_sigma_grey;
  ro.blur_sigma_px = noise.blur_sigma_px;
  ro.seed = a.seed;
  FrameRenderer renderer(twin.model(), ro);
  const GroundTruthCamera camera = GroundTruthCamera::from_model(twin.model());

  // What the overlay follows: the task's progress, the objects' trails.
  std::vector<std::string> types;
  for (const ObjectSpec& o : scenario.scene.objects) types.push_back(o.type);
  TaskProgress progress_of_task(scenario.task);
  TrailHistory trails;
  const OverlayData task_layer = task_overlay(scenario);

  std::string truth = "frame,t,id,object,x,y,x_px,y_px\n";
  PngWriterThread pngs(4);
  std::unique_ptr<Progress> progress;
  if (!a.quiet) progress = std::make_unique<Progress>("render", "frames", a.frames);
  const auto start = std::chrono::steady_clock::now();
  cv::Mat frame, decorated;
  for (int k = 0; k < a.frames; ++k) {
    // Step the twin to the frame's time, render what the camera sees, queue the PNG.
    const double t = k / kCameraRateHz;
    twin.advance_to(t);
    renderer.render_into(twin.data(), k, frame);
    pngs.write(frames_dir + "/" + frame_name(k), frame);

    // Ground truth of every object: floor position (m) and the pixel of its centre.
    std::vector<Eigen::Vector2d> positions;
    for (size_t i = 0; i < twin.object_count(); ++i) {
      const Eigen::Vector2d p = twin.object_state(i).p_W;
      positions.push_back(p);
      const auto uv = camera.project(object_centre_W(twin, i));
      AIRTWIN_DEMAND(uv.has_value());  // the camera looks down from above every object
      char row[256];
      std::snprintf(row, sizeof(row), "%d,%.6f,%s,%s,%.6f,%.6f,%.6f,%.6f\n", k, t,
                    twin.object(i).id.c_str(), object_type_name(twin.object(i).type), p.x(), p.y(),
                    uv->x(), uv->y());
      truth += row;
    }

    // For people: the overlay on a copy, into the video or its own frames.
    const cv::Mat* shown = &frame;
    if (a.overlay) {
      progress_of_task.update(positions, types, t);
      trails.push(positions);
      OverlayData data = task_layer;
      // The current reference of each object, each point once.
      for (const Eigen::Vector2d& r : progress_of_task.references(types)) {
        if (std::find(data.current_references_W.begin(), data.current_references_W.end(), r) ==
            data.current_references_W.end()) {
          data.current_references_W.push_back(r);
        }
      }
      data.stagnation_W = twin.stagnation_point();
      data.nozzle_pan_rad = twin.actual_orientation().pan_rad;
      data.trails_W = trails.trails();
      data.time_s = t;
      char caption[160];
      std::snprintf(caption, sizeof(caption), "%s  pan %.1f deg  tilt %.1f deg",
                    scenario.name.c_str(), rad_to_deg(twin.actual_orientation().pan_rad),
                    rad_to_deg(twin.actual_orientation().tilt_rad));
      data.caption = caption;
      frame.copyTo(decorated);
      draw_overlay(decorated, camera, data);
      shown = &decorated;
      if (!video) pngs.write(overlay_dir + "/" + frame_name(k), decorated);
    }
    if (video) video->write(*shown);
    if (progress) progress->update(k + 1);
  }
  pngs.finish();
  std::optional<VideoSummary> video_summary;
  if (video) video_summary = video->close();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (progress) progress->finish();
  write_text_file(a.out + "/truth.csv", truth);
  // The nozzle's log (models/nozzle_log.h): one command, in force from the first frame on.
  write_text_file(a.out + "/nozzle.csv", nozzle_log_csv({{0.0, twin.commanded_orientation()}}));

  // The calibration views of the same camera (renders/calibration_target.h).
  int views = 0;
  if (a.calibration_views > 0) {
    CalibrationDatasetOptions co;
    co.views = a.calibration_views;
    co.seed = a.seed;
    co.noise_sigma_grey = noise.noise_sigma_grey;
    co.blur_sigma_px = noise.blur_sigma_px;
    views = write_calibration_dataset(a.out + "/calibration", params.scene, co);
  }

  std::printf(
      "rendered %d frames (%.2f s at %.0f Hz) of %s, %zu objects, seed %llu, noise %s, "
      "pan %.1f deg, tilt %.1f deg, into %s: %.1f frames/s\n",
      a.frames, a.frames / kCameraRateHz, kCameraRateHz, scenario.name.c_str(), twin.object_count(),
      static_cast<unsigned long long>(a.seed), a.noise.c_str(), a.pan_deg, a.tilt_deg,
      a.out.c_str(), a.frames / seconds);
  if (views > 0) std::printf("calibration: %d views in %s/calibration\n", views, a.out.c_str());
  if (video_summary) {
    std::printf("video %s: %lld frames, stride %d, time scale %gx, encoding %.1f ms/frame\n",
                video_summary->path.c_str(), static_cast<long long>(video_summary->frames_written),
                a.stride, video_summary->time_scale, video_summary->encode_ms_per_frame);
  }
}

}  // namespace

void add_render_command(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* sub = app.add_subcommand(
      "render",
      "Render a synthetic camera dataset of a scenario in the MuJoCo twin: the scenario's "
      "objects,\n"
      "the jet on (settled) at one nozzle orientation, N frames of the top camera at 40 Hz of\n"
      "simulated time. Writes DIR/frames/frame_NNNNNN.png, DIR/truth.csv\n"
      "(frame,t,id,object,x,y,x_px,y_px: world m and ground-truth pixel), DIR/nozzle.csv\n"
      "(t,pan_deg,tilt_deg: the command) and DIR/calibration/ (checkerboard views);\n"
      "optionally an H.264 video, with overlays for people.\n"
      "docs/rendering.md, docs/data_formats.md.");
  sub->add_option("scenario", args->scenario, "Scenario YAML file (docs/scenario_schema.md)")
      ->required();
  sub->add_option("--frames", args->frames, "Camera frames to render (>= 1)")->required();
  add_air_flags(sub, args->air);
  sub->add_option(
      "--table", args->table,
      std::string("With --air model: the twin's air model (a coefficient table CSV or a\n"
                  "field-model JSON); ") +
          kDefaultFieldModelHelp);
  sub->add_option("--seed", args->seed,
                  "Seed of the twin (headings, cotton shapes, turbulence), "
                  "the sensor noise and the calibration views")
      ->capture_default_str();
  sub->add_option("--noise", args->noise,
                  "Sensor level: none | low (noise 3 grey levels, blur 0.7 px) | high (6, 1.0 px)")
      ->capture_default_str();
  sub->add_option("--pan", args->pan_deg, "Nozzle pan (deg), in [-180, 180]")
      ->capture_default_str();
  sub->add_option("--tilt", args->tilt_deg, "Nozzle tilt (deg), in [0, 60]")->capture_default_str();
  sub->add_flag("--overlay", args->overlay,
                "Draw the task, stagnation point, nozzle heading, trails and time on the video's "
                "frames (or into DIR/overlay/ without --video); never on DIR/frames");
  sub->add_option("--video", args->video, "Also write an H.264 MP4 (40 fps) and its .json sidecar");
  sub->add_option("--stride", args->stride, "Video: keep every k-th frame (plays k times faster)")
      ->capture_default_str();
  sub->add_option("--calibration-views", args->calibration_views,
                  "Checkerboard views in DIR/calibration (0: none)")
      ->capture_default_str();
  sub->add_option("--out", args->out, "Output folder")->required();
  sub->add_flag("--quiet", args->quiet, "No progress on stderr");
  sub->callback([args] { run_render(*args); });
}

}  // namespace airtwin::cli
