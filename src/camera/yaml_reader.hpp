// src/camera/yaml_reader.hpp (internal) — checked reads from an OpenCV-YAML file.
//
// Contract: YamlReader opens a file written in OpenCV's FileStorage YAML dialect (the format
// of ORB-SLAM2 settings and EuRoC sensor.yaml, starting with %YAML:1.0) and returns values by
// key. Every failure — missing file, unparseable text, missing key, wrong type, wrong length —
// throws orbis::Error naming the file and the key (or the line, for parse errors).
// Not installed: settings.cpp and the camera readers share it.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "orbis/util/error.hpp"

namespace orbis::detail {

class YamlReader {
 public:
  explicit YamlReader(const std::filesystem::path& path);

  const std::string& path() const { return path_; }
  bool has(const std::string& key) const;
  Error error(const std::string& key, const std::string& what) const { return keyError(path_, key, what); }

  double real(const std::string& key) const;
  std::optional<double> optionalReal(const std::string& key) const;
  int integer(const std::string& key) const;
  std::optional<int> optionalInteger(const std::string& key) const;
  std::string string(const std::string& key) const;
  std::optional<std::string> optionalString(const std::string& key) const;
  // A YAML sequence of numbers whose length lies in [minCount, maxCount].
  std::vector<double> reals(const std::string& key, std::size_t minCount, std::size_t maxCount) const;
  // An !!opencv-matrix, or any map with rows, cols and data (EuRoC's T_BS), of any size ...
  Eigen::MatrixXd matrix(const std::string& key) const;
  // ... or of exactly the given size.
  Eigen::MatrixXd matrix(const std::string& key, int rows, int cols) const;

 private:
  cv::FileNode node(const std::string& key) const;  // throws when missing
  double number(const cv::FileNode& n, const std::string& key) const;
  int wholeNumber(const cv::FileNode& n, const std::string& key) const;

  std::string path_;
  cv::FileStorage storage_;
};

}  // namespace orbis::detail
