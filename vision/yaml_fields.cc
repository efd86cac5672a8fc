#include "vision/yaml_fields.h"

namespace airtwin {

void YamlFields::fail(const std::string& key, const std::string& what) const {
  std::string message = path_;
  message += ": ";
  message += key;
  message += " ";
  message += what;
  throw InputError(message);
}

cv::FileNode YamlFields::node(const std::string& key) const {
  const size_t dot = key.find('.');
  cv::FileNode n;
  if (dot == std::string::npos) {
    n = fs_[key];
  } else {
    const std::string section = key.substr(0, dot);
    const cv::FileNode map = fs_[section];
    if (map.empty() || map.isNone()) fail(section, "is missing");
    if (!map.isMap()) fail(section, "must be a map of keys");
    n = map[key.substr(dot + 1)];
  }
  if (n.empty() || n.isNone()) fail(key, "is missing");
  return n;
}

double YamlFields::real(const std::string& key) const {
  const cv::FileNode n = node(key);
  if (!n.isReal() && !n.isInt()) fail(key, "must be a number");
  const double value = static_cast<double>(n);
  if (!std::isfinite(value)) fail(key, "must be finite");
  return value;
}

int YamlFields::integer(const std::string& key) const {
  const cv::FileNode n = node(key);
  if (!n.isInt()) fail(key, "must be an integer");
  return static_cast<int>(n);
}

std::string YamlFields::text(const std::string& key) const {
  const cv::FileNode n = node(key);
  if (!n.isString()) fail(key, "must be a string");
  return static_cast<std::string>(n);
}

cv::Mat YamlFields::matrix_of(const std::string& key, int rows, int cols) const {
  const cv::FileNode n = node(key);
  cv::Mat m;
  try {
    n >> m;
  } catch (const cv::Exception&) {
    fail(key, "must be an opencv-matrix");
  }
  if (cols == 1 && m.rows == 1) m = m.t();
  if (m.rows != rows || m.cols != cols || m.channels() != 1) {
    fail(key, "must be a " + std::to_string(rows) + " x " + std::to_string(cols) + " matrix");
  }
  m.convertTo(m, CV_64F);
  return m;
}

}  // namespace airtwin
