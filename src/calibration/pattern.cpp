// Calibration targets; see orbis/calibration/pattern.hpp.
#include "orbis/calibration/pattern.hpp"

#include <cmath>
#include <cstdio>
#include <utility>

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "orbis/util/error.hpp"

namespace orbis::calibration {

namespace {

struct DictionaryName {
  const char* name;
  cv::aruco::PREDEFINED_DICTIONARY_NAME id;
  int codes;  // markers the dictionary holds
};
constexpr DictionaryName kDictionaries[] = {
    {"DICT_4X4_50", cv::aruco::DICT_4X4_50, 50},       {"DICT_4X4_100", cv::aruco::DICT_4X4_100, 100},
    {"DICT_4X4_250", cv::aruco::DICT_4X4_250, 250},     {"DICT_4X4_1000", cv::aruco::DICT_4X4_1000, 1000},
    {"DICT_5X5_50", cv::aruco::DICT_5X5_50, 50},       {"DICT_5X5_100", cv::aruco::DICT_5X5_100, 100},
    {"DICT_5X5_250", cv::aruco::DICT_5X5_250, 250},     {"DICT_5X5_1000", cv::aruco::DICT_5X5_1000, 1000},
    {"DICT_6X6_50", cv::aruco::DICT_6X6_50, 50},       {"DICT_6X6_100", cv::aruco::DICT_6X6_100, 100},
    {"DICT_6X6_250", cv::aruco::DICT_6X6_250, 250},     {"DICT_6X6_1000", cv::aruco::DICT_6X6_1000, 1000},
    {"DICT_7X7_50", cv::aruco::DICT_7X7_50, 50},       {"DICT_7X7_100", cv::aruco::DICT_7X7_100, 100},
    {"DICT_7X7_250", cv::aruco::DICT_7X7_250, 250},     {"DICT_7X7_1000", cv::aruco::DICT_7X7_1000, 1000},
    {"DICT_ARUCO_ORIGINAL", cv::aruco::DICT_ARUCO_ORIGINAL, 1024}};

const DictionaryName* findDictionary(std::string_view name) {
  for (const DictionaryName& d : kDictionaries)
    if (name == d.name) return &d;
  return nullptr;
}

cv::Ptr<cv::aruco::CharucoBoard> charucoBoard(const CalibrationPattern& p) {
  return cv::aruco::CharucoBoard::create(p.cols, p.rows, static_cast<float>(p.square), static_cast<float>(p.marker),
                                         cv::aruco::getPredefinedDictionary(findDictionary(p.dictionary)->id));
}

std::vector<std::string> split(std::string_view text, char separator) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (true) {
    const std::size_t end = text.find(separator, start);
    parts.emplace_back(text.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start));
    if (end == std::string_view::npos) return parts;
    start = end + 1;
  }
}

std::optional<double> parseReal(const std::string& text) {
  try {
    std::size_t used = 0;
    const double v = std::stod(text, &used);
    if (used == text.size() && std::isfinite(v)) return v;
  } catch (const std::exception&) {
  }
  return std::nullopt;
}

}  // namespace

int CalibrationPattern::cornerCount() const {
  return kind == PatternKind::Chessboard ? cols * rows : (cols - 1) * (rows - 1);
}

Eigen::Vector3d CalibrationPattern::objectPoint(int id) const {
  const int across = cornersAcross();
  return {(id % across + 1) * square, (id / across + 1) * square, 0.0};
}

Eigen::Vector2d CalibrationPattern::boardSize() const {
  const int squaresAcross = kind == PatternKind::Chessboard ? cols + 1 : cols;
  const int squaresDown = kind == PatternKind::Chessboard ? rows + 1 : rows;
  return {squaresAcross * square, squaresDown * square};
}

std::string CalibrationPattern::describe() const {
  char text[160];
  if (kind == PatternKind::Chessboard) {
    std::snprintf(text, sizeof text, "chessboard:%dx%d:%g", cols, rows, square);
  } else {
    std::snprintf(text, sizeof text, "charuco:%dx%d:%g:%g:%s", cols, rows, square, marker, dictionary.c_str());
  }
  return text;
}

CalibrationPattern parsePattern(std::string_view text, const std::string& source) {
  const std::string usage =
      "expected chessboard:COLSxROWS:SQUARE (inner corners, square in metres, e.g. chessboard:9x6:0.025) or "
      "charuco:COLSxROWS:SQUARE:MARKER[:DICT] (squares, metres, e.g. charuco:8x6:0.04:0.03:DICT_5X5_100), got '" +
      std::string(text) + "'";
  const std::vector<std::string> parts = split(text, ':');
  CalibrationPattern p;
  if (parts[0] == "chessboard" && parts.size() == 3) {
    p.kind = PatternKind::Chessboard;
  } else if (parts[0] == "charuco" && (parts.size() == 4 || parts.size() == 5)) {
    p.kind = PatternKind::Charuco;
  } else {
    throw Error(source, "", usage);
  }
  const std::vector<std::string> size = split(parts[1], 'x');
  if (size.size() != 2) throw Error(source, "", usage);
  const double cols = parseReal(size[0]).value_or(-1), rows = parseReal(size[1]).value_or(-1);
  const double square = parseReal(parts[2]).value_or(-1);
  if (cols != std::floor(cols) || rows != std::floor(rows) || cols < 0 || rows < 0 || cols > 200 || rows > 200)
    throw Error(source, "", usage);
  p.cols = static_cast<int>(cols);
  p.rows = static_cast<int>(rows);
  p.square = square;
  const int minimum = p.kind == PatternKind::Chessboard ? 2 : 3;
  if (p.cols < minimum || p.rows < minimum)
    throw Error(source, "", "the pattern needs at least " + std::to_string(minimum) + "x" + std::to_string(minimum) +
                                (p.kind == PatternKind::Chessboard ? " inner corners" : " squares") + ": " + usage);
  if (!(p.square > 0 && p.square < 10))
    throw Error(source, "", "the square side is in metres and must lie in (0, 10): " + usage);
  if (p.kind == PatternKind::Charuco) {
    const auto marker = parseReal(parts[3]);
    if (!marker || !(*marker > 0 && *marker < p.square))
      throw Error(source, "", "the ChArUco marker side must be positive and smaller than the square: " + usage);
    p.marker = *marker;
    if (parts.size() == 5) {
      if (!findDictionary(parts[4])) throw Error(source, "", "unknown aruco dictionary '" + parts[4] + "' (e.g. DICT_4X4_50, DICT_5X5_100, DICT_6X6_250)");
      p.dictionary = parts[4];
    }
    const int markers = (p.cols * p.rows) / 2;
    const int codes = findDictionary(p.dictionary)->codes;
    if (markers > codes)
      throw Error(source, "", "the board needs " + std::to_string(markers) + " markers but " + p.dictionary + " has " +
                                  std::to_string(codes) + ": choose a larger dictionary");
  }
  return p;
}

cv::Mat drawTarget(const CalibrationPattern& pattern, int pixelsPerSquare) {
  const Eigen::Vector2d size = pattern.boardSize() / pattern.square;
  const int squaresAcross = static_cast<int>(std::lround(size.x())), squaresDown = static_cast<int>(std::lround(size.y()));
  const cv::Size image((squaresAcross + 2) * pixelsPerSquare, (squaresDown + 2) * pixelsPerSquare);
  cv::Mat target;
  if (pattern.kind == PatternKind::Charuco) {
    charucoBoard(pattern)->draw(image, target, pixelsPerSquare, 1);
    return target;
  }
  target = cv::Mat(image, CV_8UC1, cv::Scalar(255));
  for (int j = 0; j < squaresDown; ++j)
    for (int i = 0; i < squaresAcross; ++i)
      if ((i + j) % 2 == 0)
        target(cv::Rect((i + 1) * pixelsPerSquare, (j + 1) * pixelsPerSquare, pixelsPerSquare, pixelsPerSquare))
            .setTo(0);
  return target;
}

std::optional<PatternDetection> detectPattern(const cv::Mat& gray, const CalibrationPattern& pattern) {
  PatternDetection d;
  if (pattern.kind == PatternKind::Chessboard) {
    const cv::Size size(pattern.cols, pattern.rows);
    bool found = cv::findChessboardCornersSB(gray, size, d.corners, cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_ACCURACY);
    if (!found) {
      // The classic detector, refined to subpixel: it finds some strongly distorted boards SB misses.
      found = cv::findChessboardCorners(gray, size, d.corners,
                                        cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE);
      if (found)
        cv::cornerSubPix(gray, d.corners, cv::Size(5, 5), cv::Size(-1, -1),
                         cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 40, 0.001));
    }
    if (!found || static_cast<int>(d.corners.size()) != pattern.cornerCount()) return std::nullopt;
    d.ids.resize(d.corners.size());
    for (std::size_t i = 0; i < d.ids.size(); ++i) d.ids[i] = static_cast<int>(i);
    return d;
  }
  const cv::Ptr<cv::aruco::CharucoBoard> board = charucoBoard(pattern);
  std::vector<std::vector<cv::Point2f>> markerCorners;
  std::vector<int> markerIds;
  cv::aruco::detectMarkers(gray, board->dictionary, markerCorners, markerIds);
  if (markerIds.size() < 2) return std::nullopt;
  cv::aruco::interpolateCornersCharuco(markerCorners, markerIds, gray, board, d.corners, d.ids);
  if (d.ids.size() < 6) return std::nullopt;
  cv::cornerSubPix(gray, d.corners, cv::Size(3, 3), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 40, 0.001));
  return d;
}

}  // namespace orbis::calibration
