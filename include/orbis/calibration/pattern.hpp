// orbis/calibration/pattern.hpp — calibration targets: what `--pattern` names, where their
// corners are, how they look, and finding them in an image.
//
// Contract: parsePattern() reads `chessboard:COLSxROWS:SQUARE` (inner corners across and down,
// square side in metres) or `charuco:COLSxROWS:SQUARE:MARKER[:DICT]` (squares across and down,
// as OpenCV and the printing sites count them; marker side in metres; DICT an OpenCV aruco
// dictionary name such as DICT_5X5_100, the default DICT_4X4_50) and throws orbis::Error naming
// `source` for anything else. objectPoint(id) is corner id's position on the board (z = 0,
// metres, x along the columns, y down the rows). drawTarget() renders the board as printed (white
// quiet zone of one square round it) for the synthetic calibration views. detectPattern() finds
// the corners in a grey image with subpixel refinement (chessboard: OpenCV's
// findChessboardCornersSB, whose corners are already subpixel; ChArUco: markers, then the
// interpolated chessboard corners refined by cornerSubPix), or nothing; a ChArUco view keeps only
// boards seen with at least 6 corners, and partly covered boards are fine.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace orbis::calibration {

enum class PatternKind { Chessboard, Charuco };

struct CalibrationPattern {
  PatternKind kind = PatternKind::Chessboard;
  int cols = 9, rows = 6;      // chessboard: inner corners; ChArUco: squares
  double square = 0.025;       // metres
  double marker = 0.0;         // ChArUco marker side, metres
  std::string dictionary = "DICT_4X4_50";

  // Corners the board has: chessboard cols x rows; ChArUco (cols-1) x (rows-1).
  int cornerCount() const;
  int cornersAcross() const { return kind == PatternKind::Chessboard ? cols : cols - 1; }
  Eigen::Vector3d objectPoint(int id) const;
  // The board's outer size in metres (squares, without the quiet zone).
  Eigen::Vector2d boardSize() const;
  std::string describe() const;  // the --pattern text that gives this pattern back
};

CalibrationPattern parsePattern(std::string_view text, const std::string& source = "argument --pattern");

// The printed board: 8-bit grey, `pixelsPerSquare` per square, a white margin of one square all
// round; board point (x, y) in metres is at pixel ((x / square + 1) * pixelsPerSquare - 0.5, ...).
cv::Mat drawTarget(const CalibrationPattern& pattern, int pixelsPerSquare);

struct PatternDetection {
  std::vector<cv::Point2f> corners;  // pixels
  std::vector<int> ids;              // corner ids (objectPoint), one per corner
};

std::optional<PatternDetection> detectPattern(const cv::Mat& gray, const CalibrationPattern& pattern);

}  // namespace orbis::calibration
