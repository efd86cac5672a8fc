#pragma once
// Checked reading of the YAML files of vision/ (calib.yaml, target.yaml) through cv::FileStorage:
// every failure is one InputError naming the file and the key ("calib.yaml: K must be a 3 x 3
// matrix"). Keys are top-level ("width_px") or one level deep in dotted form
// ("board.square_size_m").

#include <Eigen/Core>
#include <cmath>
#include <string>

#include <opencv2/core.hpp>

#include "common/errors.h"

namespace airtwin {

/// Opens the YAML `text` of the file `path` in `fs` (cv::FileStorage, from memory). Throws
/// InputError naming the file, saying it is not a YAML `what`, when OpenCV's parser refuses it or
/// when the text is not one document whose top level is a block map starting at column 0 (after
/// a %YAML directive and a --- line, both optional): OpenCV's parser loops forever on some text
/// after a first document, so a second one is never handed to it.
void open_yaml(const std::string& text, const std::string& path, const std::string& what,
               cv::FileStorage* fs);

class YamlFields {
 public:
  /// `path` names the file in messages; both must outlive the reader.
  YamlFields(const std::string& path, const cv::FileStorage& fs) : path_(path), fs_(fs) {}

  /// Throws InputError "<path>: <key> <what>".
  [[noreturn]] void fail(const std::string& key, const std::string& what) const;

  /// The node of `key` ("name" or "section.name"); fails when it is missing or the section is not
  /// a map.
  cv::FileNode node(const std::string& key) const;

  double real(const std::string& key) const;  ///< a finite number
  int integer(const std::string& key) const;
  std::string text(const std::string& key) const;

  /// An opencv-matrix of exactly Rows x Cols finite numbers (a vector may be stored as a row).
  template <int Rows, int Cols>
  Eigen::Matrix<double, Rows, Cols> matrix(const std::string& key) const {
    const cv::Mat m = matrix_of(key, Rows, Cols);
    Eigen::Matrix<double, Rows, Cols> e;
    for (int r = 0; r < Rows; ++r) {
      for (int c = 0; c < Cols; ++c) e(r, c) = m.at<double>(r, c);
    }
    if (!e.allFinite()) fail(key, "must hold finite numbers");
    return e;
  }

 private:
  cv::Mat matrix_of(const std::string& key, int rows, int cols) const;

  const std::string& path_;
  const cv::FileStorage& fs_;
};

}  // namespace airtwin
