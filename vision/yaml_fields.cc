#include "vision/yaml_fields.h"

#include <algorithm>
#include <cctype>
#include <string_view>

namespace airtwin {

void open_yaml(const std::string& text, const std::string& path, const std::string& what,
               cv::FileStorage* fs) {
  const std::string refused = path + ": not a YAML " + what;
  bool started = false, in_document = false;
  for (size_t pos = 0; pos < text.size();) {
    const size_t end = std::min(text.find('\n', pos), text.size());
    const std::string_view line(text.data() + pos, end - pos);
    pos = end + 1;
    const size_t first = line.find_first_not_of(" \r");
    if (first == std::string_view::npos || line[first] == '#') continue;
    const bool marker = line.rfind("---", 0) == 0 || line.rfind("...", 0) == 0;
    if (in_document) {
      if (marker) throw InputError(refused + " (one YAML document only)");
      continue;
    }
    if (line[0] == '%' && !started) continue;
    if (line.rfind("---", 0) == 0 && !started &&
        line.find_first_not_of(" \r", 3) == std::string_view::npos) {
      started = true;
      continue;
    }
    if (first != 0 || !(std::isalnum(static_cast<unsigned char>(line[0])) || line[0] == '_')) {
      throw InputError(refused + " (expected keys at the start of the line, line '" +
                       std::string(line.substr(0, 40)) + "')");
    }
    in_document = true;
  }
  try {
    if (!fs->open(text,
                  cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML)) {
      throw InputError(refused + " (cv::FileStorage cannot open it)");
    }
  } catch (const InputError&) {
    throw;
  } catch (const std::exception&) {
    throw InputError(refused + " (cv::FileStorage cannot parse it)");
  }
}

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
  if (!n.isMap() || !n["rows"].isInt() || !n["cols"].isInt() || !n["data"].isSeq()) {
    fail(key, "must be an opencv-matrix");
  }
  const int file_rows = static_cast<int>(n["rows"]);
  const int file_cols = static_cast<int>(n["cols"]);
  const cv::FileNode data = n["data"];
  if (!((file_rows == rows && file_cols == cols) ||
        (cols == 1 && file_rows == 1 && file_cols == rows)) ||
      data.size() != static_cast<size_t>(rows) * static_cast<size_t>(cols)) {
    fail(key, "must be a " + std::to_string(rows) + " x " + std::to_string(cols) + " matrix");
  }
  cv::Mat m(rows, cols, CV_64F);
  int i = 0;
  for (const cv::FileNode value : data) {
    if (!value.isReal() && !value.isInt()) fail(key, "must hold numbers");
    m.at<double>(i / cols, i % cols) = static_cast<double>(value);
    ++i;
  }
  return m;
}

}  // namespace airtwin
