// Checked reads from OpenCV-YAML files; see yaml_reader.hpp.
#include "yaml_reader.hpp"

#include <cmath>
#include <regex>

namespace orbis::detail {

namespace {

std::string typeName(const cv::FileNode& n) {
  if (n.isString()) return "the text \"" + static_cast<std::string>(n) + "\"";
  if (n.isSeq()) return "a sequence";
  if (n.isMap()) return "a map";
  if (n.isNone()) return "no value";
  return "a value of another type";
}

// OpenCV reports parse errors as "... in function '<file>(<line>): <problem>'".
Error parseError(const std::string& path, const cv::Exception& e) {
  static const std::regex located(R"(\((\d+)\): (.*)')");
  std::smatch m;
  if (std::regex_search(e.msg, m, located)) {
    return lineError(path, std::stoul(m[1].str()), "not valid YAML: " + m[2].str());
  }
  return fileError(path, "not an OpenCV YAML file (it must start with %YAML:1.0): " + e.err);
}

}  // namespace

YamlReader::YamlReader(const std::filesystem::path& path) : path_(path.string()) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw fileError(path_, "no such file");
  if (std::filesystem::file_size(path, ec) == 0) throw fileError(path_, "empty file, expected OpenCV YAML (%YAML:1.0)");
  try {
    if (!storage_.open(path_, cv::FileStorage::READ)) throw fileError(path_, "cannot be opened for reading");
  } catch (const cv::Exception& e) {
    throw parseError(path_, e);
  }
  if (!storage_.root().isMap()) throw fileError(path_, "expected a YAML map of keys at the top level");
}

bool YamlReader::has(const std::string& key) const { return !storage_[key].empty(); }

cv::FileNode YamlReader::node(const std::string& key) const {
  cv::FileNode n = storage_[key];
  if (n.empty()) throw error(key, "missing");
  return n;
}

double YamlReader::number(const cv::FileNode& n, const std::string& key) const {
  if (!n.isInt() && !n.isReal()) throw error(key, "expected a number, found " + typeName(n));
  const double value = static_cast<double>(n);
  if (!std::isfinite(value)) throw error(key, "expected a finite number");
  return value;
}

int YamlReader::wholeNumber(const cv::FileNode& n, const std::string& key) const {
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
  const cv::FileNode n = node(key);
  if (!n.isString()) throw error(key, "expected text, found " + typeName(n));
  return static_cast<std::string>(n);
}

std::optional<std::string> YamlReader::optionalString(const std::string& key) const {
  if (!has(key)) return std::nullopt;
  return string(key);
}

std::vector<double> YamlReader::reals(const std::string& key, std::size_t minCount, std::size_t maxCount) const {
  const cv::FileNode n = node(key);
  if (!n.isSeq()) throw error(key, "expected a sequence of numbers, found " + typeName(n));
  std::vector<double> values;
  for (const cv::FileNode& item : n) values.push_back(number(item, key));
  if (values.size() < minCount || values.size() > maxCount) {
    throw error(key, "expected " + std::to_string(minCount) +
                         (maxCount != minCount ? " to " + std::to_string(maxCount) : "") + " numbers, found " +
                         std::to_string(values.size()));
  }
  return values;
}

Eigen::MatrixXd YamlReader::matrix(const std::string& key) const {
  const cv::FileNode n = node(key);
  if (!n.isMap() || n["rows"].empty() || n["cols"].empty() || n["data"].empty()) {
    throw error(key, "expected a matrix (a map with rows, cols and data), found " + typeName(n));
  }
  const int rows = wholeNumber(n["rows"], key + ".rows");
  const int cols = wholeNumber(n["cols"], key + ".cols");
  if (rows <= 0 || cols <= 0 || rows > 64 || cols > 64) throw error(key, "expected 1 to 64 rows and columns");
  const cv::FileNode data = n["data"];
  if (!data.isSeq() || static_cast<int>(data.size()) != rows * cols) {
    throw error(key + ".data", "expected " + std::to_string(rows * cols) + " numbers (rows x cols)");
  }
  Eigen::MatrixXd m(rows, cols);
  int i = 0;
  for (const cv::FileNode& item : data) {
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
