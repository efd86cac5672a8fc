#pragma once
// A checkerboard calibration target in the twin, and a dataset of rendered views of it: what a
// person does on the rig to calibrate its camera (lay a printed board on the floor at a marked
// spot, then hold it at a few angles), done in the twin so that the vision pipeline can calibrate
// the twin's camera exactly as it calibrates the rig's (vision/camera_calibration.h), from frames
// alone, and be scored against the renderer's ground truth (renders/camera_model.h).
//
// The board (docs/camera_calibration.md): 10 x 7 inner corners (11 x 8 squares of 8 cm, 0.88 m x
// 0.64 m) on a white board with a 4 cm white margin, 3 mm thick, drawn as one box geom per black
// square on a white box (crisp corners, no texture filtering), matte. An odd number of squares
// along one side makes the pattern asymmetric, so its origin can be found in any view: the origin
// is the inner corner next to a black corner square, x along the long side, y along the short side,
// z = x cross y out of the printed face; the square between inner corners 0, 1, 10 and 11 is black.
//
// The board is a mocap body of the twin's own scene (scene_xml with no objects: floor, nozzle rig,
// camera `top`), rendered by FrameRenderer through the camera `top` (4x multisampled, so that the
// squares' edges are area-averaged as a camera's pixels do). View 0 is the reference: the board
// lies flat on the floor, its pose written to target.yaml as a person would measure it on the rig.
// Every other view lies flat too, somewhere else (boards on the floor all over the picture pin the
// floor's image); the rest are propped up at 15-35 deg on one of the board's edges, the edges'
// directions spread over half a turn (views of one plane parallel to the image cannot separate
// the focal length from the camera height). The views' board centres go round the picture in
// sectors, out to its corners. Poses are drawn from the seed (RandomStream), each board entirely
// in view and clear of the nozzle rig that hangs in the middle of the picture.

#include <cstdint>
#include <string>

#include "sim/scene_spec.h"

namespace airtwin {

struct CalibrationDatasetOptions {
  int views = 8;                  ///< frames to render, including the reference; 3 to 100
  uint64_t seed = 0;              ///< fixes the board poses and the sensor noise
  double noise_sigma_grey = 0.0;  ///< sensor noise of the frames (grey levels, >= 0)
  double blur_sigma_px = 0.0;     ///< Gaussian blur of the frames (px, >= 0)
};

/// Renders views of the target in the twin's scene (params = the twin's SceneParameters) into
/// `dir` (created, with its parents): PNG frames view_00.png, view_01.png, ... and target.yaml
/// (board geometry: inner corners cols x rows, square size m, thickness m; which view is the
/// reference and the board's world pose in it: origin corner x, y in m and yaw in deg; format in
/// docs/data_formats.md). Existing files of those names are replaced. Returns the number of views
/// written. Same arguments, same bytes. Throws InputError for bad options or parameters, when the
/// camera cannot see the board whole, or when a file cannot be written; RenderError when OSMesa
/// fails.
int write_calibration_dataset(const std::string& dir, const SceneParameters& params,
                              const CalibrationDatasetOptions& options);

}  // namespace airtwin
