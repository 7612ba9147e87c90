// Checked reads from YAML files of keys; see yaml_reader.hpp.
#include "yaml_reader.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

namespace orbis::detail {

namespace {

std::string typeName(const YAML::Node& n) {
  if (n.IsSequence()) return "a sequence";
  if (n.IsMap()) return "a map";
  if (n.IsNull()) return "no value";
  return "the text \"" + n.Scalar() + "\"";
}

std::string readText(const std::filesystem::path& path, const std::string& name) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw fileError(name, "no such file");
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  if (!in) throw fileError(name, "cannot be opened for reading");
  return text.str();
}

}  // namespace

YamlReader::YamlReader(const std::filesystem::path& path, Header header) : path_(path.string()) {
  std::string text = readText(path, path_);
  if (text.find_first_not_of(" \t\r\n") == std::string::npos) throw fileError(path_, "empty file, expected YAML");
  // OpenCV's "%YAML:1.0" is not a YAML 1.x directive: made a comment, so line numbers stay.
  const bool openCvHeader = text.rfind("%YAML:", 0) == 0;
  if (openCvHeader) text[0] = '#';
  if (!openCvHeader && header == Header::Required)
    throw fileError(path_, "not an OpenCV YAML file (it must start with %YAML:1.0, as ORB-SLAM2's settings do)");
  try {
    root_ = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw lineError(path_, static_cast<std::size_t>(e.mark.line) + 1, "not valid YAML: " + e.msg);
  }
  if (!root_.IsMap()) throw fileError(path_, "expected a YAML map of keys at the top level");
}

void YamlReader::requireAccepted(const std::string& key) const {
  if (!accepted_.empty() && std::find(accepted_.begin(), accepted_.end(), key) == accepted_.end())
    throw std::logic_error("orbis: the reader of " + path_ + " looks up the key " + key +
                           ", which is missing from its list of accepted keys (add it there)");
}

bool YamlReader::has(const std::string& key) const {
  requireAccepted(key);
  return static_cast<bool>(root_[key]);
}

YAML::Node YamlReader::node(const std::string& key) const {
  requireAccepted(key);
  const YAML::Node n = root_[key];
  if (!n) throw error(key, "missing");
  return n;
}

double YamlReader::number(const YAML::Node& n, const std::string& key) const {
  double value = 0.0;
  if (!n.IsScalar() || !YAML::convert<double>::decode(n, value))
    throw error(key, "expected a number, found " + typeName(n));
  if (!std::isfinite(value)) throw error(key, "expected a finite number");
  return value;
}

int YamlReader::wholeNumber(const YAML::Node& n, const std::string& key) const {
  const double value = number(n, key);
  if (value != std::floor(value) || std::abs(value) > 2e9) throw error(key, "expected a whole number");
  return static_cast<int>(value);
}

double YamlReader::real(const std::string& key) const { return number(node(key), key); }

std::optional<double> YamlReader::optionalReal(const std::string& key) const {
  if (!has(key)) return std::nullopt;
  return real(key);
}

int YamlReader::integer(const std::string& key) const { return wholeNumber(node(key), key); }

std::optional<int> YamlReader::optionalInteger(const std::string& key) const {
  if (!has(key)) return std::nullopt;
  return integer(key);
}

std::string YamlReader::string(const std::string& key) const {
  const YAML::Node n = node(key);
  if (!n.IsScalar()) throw error(key, "expected text, found " + typeName(n));
  return n.Scalar();
}

std::optional<std::string> YamlReader::optionalString(const std::string& key) const {
  if (!has(key)) return std::nullopt;
  return string(key);
}

std::vector<double> YamlReader::reals(const std::string& key, std::size_t minCount, std::size_t maxCount) const {
  const YAML::Node n = node(key);
  if (!n.IsSequence()) throw error(key, "expected a sequence of numbers, found " + typeName(n));
  if (n.size() < minCount || n.size() > maxCount) {
    throw error(key, "expected " + std::to_string(minCount) +
                         (maxCount != minCount ? " to " + std::to_string(maxCount) : "") + " numbers, found " +
                         std::to_string(n.size()));
  }
  std::vector<double> values;
  for (const YAML::Node& item : n) values.push_back(number(item, key));
  return values;
}

Eigen::MatrixXd YamlReader::matrix(const std::string& key) const {
  const YAML::Node n = node(key);
  if (!n.IsMap() || !n["rows"] || !n["cols"] || !n["data"]) {
    throw error(key, "expected a matrix (a map with rows, cols and data), found " + typeName(n));
  }
  const int rows = wholeNumber(n["rows"], key + ".rows");
  const int cols = wholeNumber(n["cols"], key + ".cols");
  if (rows <= 0 || cols <= 0 || rows > 64 || cols > 64) throw error(key, "expected 1 to 64 rows and columns");
  const YAML::Node data = n["data"];
  if (!data.IsSequence() || data.size() != static_cast<std::size_t>(rows * cols)) {
    throw error(key + ".data", "expected " + std::to_string(rows * cols) + " numbers (rows x cols)");
  }
  Eigen::MatrixXd m(rows, cols);
  int i = 0;
  for (const YAML::Node& item : data) {
    m(i / cols, i % cols) = number(item, key + ".data");
    ++i;
  }
  return m;
}

Eigen::MatrixXd YamlReader::matrix(const std::string& key, int rows, int cols) const {
  Eigen::MatrixXd m = matrix(key);
  if (m.rows() != rows || m.cols() != cols) {
    throw error(key, "expected a " + std::to_string(rows) + "x" + std::to_string(cols) + " matrix, found " +
                         std::to_string(m.rows()) + "x" + std::to_string(m.cols()));
  }
  return m;
}

}  // namespace orbis::detail
