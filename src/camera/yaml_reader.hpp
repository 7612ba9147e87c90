// src/camera/yaml_reader.hpp (internal) — checked reads from a YAML file of keys.
//
// Contract: YamlReader parses a YAML file with yaml-cpp — ORB-SLAM2 settings (OpenCV's
// FileStorage dialect: a "%YAML:1.0" first line, !!opencv-matrix maps) and EuRoC sensor.yaml (as
// published: plain YAML, a comment first) — and returns values by key. OpenCV's own parser is
// not used: it needs the header and hangs on some damaged files (found by fuzzing). With
// Header::Required the "%YAML:1.0" line must be there, as ORB-SLAM2 needs it. Every failure —
// missing file, unparseable text, missing key, wrong type, wrong length — throws orbis::Error
// naming the file and the key (or the line, for parse errors). A reader given a list of accepted
// keys (acceptOnly) refuses, as a programming error, to look up any other: the settings reader
// uses it so its published key list (orbis::settingsKeys) cannot fall behind what it reads.
// Not installed: settings.cpp and the camera readers share it.
#pragma once

#include <filesystem>
#include <optional>
#include <span>
#include <string_view>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <yaml-cpp/yaml.h>

#include "orbis/util/error.hpp"

namespace orbis::detail {

class YamlReader {
 public:
  enum class Header { Required, Optional };  // OpenCV's "%YAML:1.0" first line
  explicit YamlReader(const std::filesystem::path& path, Header header = Header::Required);

  const std::string& path() const { return path_; }
  // From now on, looking up a key outside `keys` throws std::logic_error (a reader bug, not bad
  // input); `keys` must outlive the reader.
  void acceptOnly(std::span<const std::string_view> keys) { accepted_ = keys; }
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
  YAML::Node node(const std::string& key) const;  // throws when missing
  double number(const YAML::Node& n, const std::string& key) const;
  int wholeNumber(const YAML::Node& n, const std::string& key) const;
  void requireAccepted(const std::string& key) const;

  std::string path_;
  YAML::Node root_;
  std::span<const std::string_view> accepted_;  // empty: every key
};

}  // namespace orbis::detail
