// airtwin calibrate: the camera model from a folder of calibration-target frames
// (vision/camera_calibration.h), written as calib.yaml (vision/calibrated_camera.h). The folder
// is what `airtwin render` writes to DIR/calibration/, or what a user takes on the rig.

#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "app/cli_common.h"
#include "app/commands.h"
#include "common/errors.h"
#include "vision/camera_calibration.h"

namespace airtwin::cli {
namespace {

struct CalibrateArgs {
  std::string dir;
  std::string out;
  std::string lens = "auto";
  double max_view_rms_px = 1.0;
};

// --lens words -> the lens model (auto: the simplest model the corners support).
const std::map<std::string, LensModel>& lens_words() {
  static const std::map<std::string, LensModel> kWords = {
      {"pinhole", LensModel::kPinhole},
      {"k1", LensModel::kRadial1},
      {"k1k2", LensModel::kRadial2},
      {"k1k2p1p2", LensModel::kRadial2Tangential},
      {"k1k2p1p2k3", LensModel::kRadial3Tangential}};
  return kWords;
}

void run_calibrate(const CalibrateArgs& a) {
  // Flags first: a bad flag is a usage error before any work.
  CameraCalibrationOptions options;
  require_range(a.max_view_rms_px, 0.01, 100.0, "--max-view-rms", "a reprojection RMS in px");
  options.max_view_rms_px = a.max_view_rms_px;
  if (a.lens != "auto") {
    const auto it = lens_words().find(a.lens);
    if (it == lens_words().end()) {
      throw UsageError("--lens: expected auto, pinhole, k1, k1k2, k1k2p1p2 or k1k2p1p2k3, got '" +
                       a.lens + "'");
    }
    options.max_lens_model = it->second;
    options.select_model = false;
  }

  // Calibrate, then write the camera.
  const auto start = std::chrono::steady_clock::now();
  const CameraCalibrationResult r = calibrate_camera(a.dir, options);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ensure_parent_dir(a.out);
  r.camera.write(a.out);

  // The summary: one JSON line.
  const CalibratedCamera& c = r.camera;
  int used = 0, on_floor = 0;
  nlohmann::ordered_json rejected = nlohmann::ordered_json::array();
  for (const CalibrationViewReport& v : r.views) {
    used += v.used;
    on_floor += v.on_floor;
    if (!v.used) rejected.push_back({{"frame", v.frame}, {"reason", v.reason}});
  }
  const Eigen::Vector3d centre = c.centre_W();
  nlohmann::ordered_json j;
  j["out"] = a.out;
  j["views"] = r.views.size();
  j["views_used"] = used;
  j["views_on_floor"] = on_floor;
  j["rejected"] = rejected;
  j["lens_model"] = lens_model_name(r.lens_model);
  j["square_pixels"] = r.square_pixels;
  j["focal_px"] = {c.K(0, 0), c.K(1, 1)};
  j["principal_point_px"] = {c.K(0, 2), c.K(1, 2)};
  j["distortion"] = {c.distortion[0], c.distortion[1], c.distortion[2], c.distortion[3],
                     c.distortion[4]};
  j["camera_centre_m"] = {centre.x(), centre.y(), centre.z()};
  j["rms_px"] = c.rms_reprojection_px;
  j["pose_rms_px"] = c.pose_rms_px;
  j["floor_rms_mm"] = 1e3 * r.floor_rms_m;
  j["floor_mm_per_px"] = 1e3 * r.floor_m_per_px;
  j["seconds"] = seconds;
  std::printf("%s\n", j.dump().c_str());
}

}  // namespace

void add_calibrate_command(CLI::App& app) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* sub = app.add_subcommand(
      "calibrate",
      "Calibrate the top camera from frames of a checkerboard target: DIR holds the frames\n"
      "(png, jpg, bmp, tif) and target.yaml (board geometry, the reference frame and the board's\n"
      "measured pose on the floor in it), as 'airtwin render' writes to DIR/calibration/ or as\n"
      "taken on the rig. Writes the camera model (YAML) and prints a JSON summary: views used and\n"
      "rejected, lens model, intrinsics, RMS reprojection error (px), floor error at the boards\n"
      "lying on the floor (mm). docs/camera_calibration.md.");
  sub->add_option("DIR", args->dir, "Folder of calibration frames and target.yaml")->required();
  sub->add_option("--out", args->out, "Output camera model (calib.yaml)")->required();
  sub->add_option("--lens", args->lens,
                  "Lens model: auto (the simplest the corners support), pinhole, k1, k1k2, "
                  "k1k2p1p2 or k1k2p1p2k3")
      ->capture_default_str();
  sub->add_option(
         "--max-view-rms", args->max_view_rms_px,
         "A view whose reprojection RMS exceeds max(this, 3 x the median) is rejected (px)")
      ->capture_default_str();
  sub->callback([args] { run_calibrate(*args); });
}

}  // namespace airtwin::cli
