// Evaluation plots: the figure is built once as a list of primitives, then rendered to PNG
// (OpenCV) or SVG (text), so both outputs show the same picture. See orbis/eval/plot.hpp.
#include "orbis/eval/plot.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <variant>

#include "orbis/util/error.hpp"
#include "orbis/util/image_file.hpp"

namespace orbis::eval {
namespace {

struct Colour {
  unsigned char r, g, b;
};
constexpr Colour kBlack{0, 0, 0}, kGrid{225, 225, 225}, kGroundTruth{110, 110, 110}, kEstimate{31, 119, 180},
    kError{214, 39, 40}, kStart{44, 160, 44};

struct Polyline {
  std::vector<std::array<double, 2>> points;  // canvas pixels, y down
  Colour colour;
  double width;
};
enum class Anchor { Start, Middle, End };
struct Text {
  double x, y;  // baseline position
  std::string text;
  double size;  // pixel height
  Colour colour;
  Anchor anchor;
};
struct Dot {
  double x, y, radius;
  Colour colour;
};
using Primitive = std::variant<Polyline, Text, Dot>;

constexpr int kWidth = 1400, kHeight = 700;

// A data-to-canvas mapping for one panel.
struct Panel {
  double left, top, width, height;  // canvas pixels
  double xMin, xMax, yMin, yMax;    // data
  double px(double x) const { return left + (x - xMin) / (xMax - xMin) * width; }
  double py(double y) const { return top + height - (y - yMin) / (yMax - yMin) * height; }
};

double niceStep(double range, int targetTicks) {
  const double raw = range / targetTicks;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * magnitude >= raw) return m * magnitude;
  return 10.0 * magnitude;
}

std::string formatTick(double value, double step) {
  const int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, std::abs(value) < step * 1e-6 ? 0.0 : value);
  return buf;
}

void drawAxes(std::vector<Primitive>& out, const Panel& p, const std::string& xLabel,
              const std::string& yLabel) {
  const double xStep = niceStep(p.xMax - p.xMin, 6), yStep = niceStep(p.yMax - p.yMin, 6);
  for (double x = std::ceil(p.xMin / xStep) * xStep; x <= p.xMax + 1e-9 * xStep; x += xStep) {
    out.push_back(Polyline{{{p.px(x), p.top}, {p.px(x), p.top + p.height}}, kGrid, 1});
    out.push_back(Text{p.px(x), p.top + p.height + 20, formatTick(x, xStep), 13, kBlack, Anchor::Middle});
  }
  for (double y = std::ceil(p.yMin / yStep) * yStep; y <= p.yMax + 1e-9 * yStep; y += yStep) {
    out.push_back(Polyline{{{p.left, p.py(y)}, {p.left + p.width, p.py(y)}}, kGrid, 1});
    out.push_back(Text{p.left - 9, p.py(y) + 4, formatTick(y, yStep), 13, kBlack, Anchor::End});
  }
  const double l = p.left, t = p.top, r = p.left + p.width, b = p.top + p.height;
  out.push_back(Polyline{{{l, t}, {r, t}, {r, b}, {l, b}, {l, t}}, kBlack, 1});
  out.push_back(Text{l + p.width / 2, b + 44, xLabel, 15, kBlack, Anchor::Middle});
  out.push_back(Text{l, t - 8, yLabel, 15, kBlack, Anchor::Start});
}

void addLegend(std::vector<Primitive>& out, double x, double y, Colour colour, const std::string& label) {
  out.push_back(Polyline{{{x, y - 5}, {x + 24, y - 5}}, colour, 3});
  out.push_back(Text{x + 30, y, label, 14, kBlack, Anchor::Start});
}

// Picks the two world axes of largest extent, in axis order (x before y before z).
std::array<int, 2> topViewAxes(const Trajectory& trajectory) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector3d hi = -lo;
  for (const StampedPose& sp : trajectory) {
    lo = lo.cwiseMin(sp.pose.translation());
    hi = hi.cwiseMax(sp.pose.translation());
  }
  const Eigen::Vector3d extent = hi - lo;
  int smallest = 0;
  extent.minCoeff(&smallest);
  // Near ties (a straight drive) drop y, the camera's down axis: the view from above is x-z.
  if (extent.y() <= extent[smallest] + 0.05 * extent.maxCoeff()) smallest = 1;
  if (smallest == 0) return {1, 2};
  if (smallest == 1) return {0, 2};
  return {0, 1};
}

void drawTopView(std::vector<Primitive>& out, const EvaluationPlot& plot, double left, double top,
                 double size) {
  const Trajectory& reference = plot.groundTruth.empty() ? plot.estimate : plot.groundTruth;
  const auto [a, b] = topViewAxes(reference);
  double minA = std::numeric_limits<double>::max(), maxA = -minA, minB = minA, maxB = -minA;
  for (const Trajectory* traj : {&plot.groundTruth, &plot.estimate})
    for (const StampedPose& sp : *traj) {
      const Eigen::Vector3d p = sp.pose.translation();
      minA = std::min(minA, p[a]), maxA = std::max(maxA, p[a]);
      minB = std::min(minB, p[b]), maxB = std::max(maxB, p[b]);
    }
  // Equal scale on both axes: grow the shorter range about its centre to the longer one.
  const double range = std::max({maxA - minA, maxB - minB, 1e-6}) * 1.08;
  const double centreA = 0.5 * (minA + maxA), centreB = 0.5 * (minB + maxB);
  const Panel panel{left,
                    top,
                    size,
                    size,
                    centreA - range / 2,
                    centreA + range / 2,
                    centreB - range / 2,
                    centreB + range / 2};
  static constexpr const char* kAxisNames[] = {"x [m]", "y [m]", "z [m]"};
  drawAxes(out, panel, kAxisNames[a], kAxisNames[b]);
  for (const auto& [traj, colour] :
       {std::pair{&plot.groundTruth, kGroundTruth}, std::pair{&plot.estimate, kEstimate}}) {
    Polyline line{{}, colour, colour.r == kEstimate.r ? 1.5 : 2.5};
    for (const StampedPose& sp : *traj) {
      const Eigen::Vector3d p = sp.pose.translation();
      line.points.push_back({panel.px(p[a]), panel.py(p[b])});
    }
    if (!line.points.empty()) out.push_back(line);
  }
  if (!reference.empty()) {
    const Eigen::Vector3d start = reference.front().pose.translation();
    out.push_back(Dot{panel.px(start[a]), panel.py(start[b]), 5, kStart});
  }
  addLegend(out, left + 10, top + 22, kGroundTruth, "ground truth");
  addLegend(out, left + 10, top + 42, kEstimate, "estimate (aligned)");
  out.push_back(Dot{left + 22, top + 57, 5, kStart});
  out.push_back(Text{left + 40, top + 62, "start", 14, kBlack, Anchor::Start});
}

void drawErrorOverTime(std::vector<Primitive>& out, const EvaluationPlot& plot, double left, double top,
                       double width, double height) {
  const double t0 = !plot.groundTruth.empty()  ? plot.groundTruth.front().t
                    : !plot.errorTimes.empty() ? plot.errorTimes.front()
                                               : 0.0;
  double tMax = 1e-6, eMax = 1e-9;
  for (std::size_t i = 0; i < plot.errorTimes.size(); ++i) {
    tMax = std::max(tMax, plot.errorTimes[i] - t0);
    eMax = std::max(eMax, plot.errors[i]);
  }
  const double tMin = std::min(0.0, plot.errorTimes.empty() ? 0.0 : plot.errorTimes.front() - t0);
  const Panel panel{left, top, width, height, tMin, tMax, 0.0, eMax * 1.08};
  drawAxes(out, panel, "time [s]", plot.errorLabel);
  Polyline line{{}, kError, 1.5};
  for (std::size_t i = 0; i < plot.errorTimes.size() && i < plot.errors.size(); ++i)
    line.points.push_back({panel.px(plot.errorTimes[i] - t0), panel.py(plot.errors[i])});
  if (!line.points.empty()) out.push_back(line);
  if (plot.errorReference) {
    const double y = panel.py(*plot.errorReference);
    for (double x = panel.left; x < panel.left + panel.width; x += 12)  // dashed
      out.push_back(Polyline{{{x, y}, {std::min(x + 6, panel.left + panel.width), y}}, kBlack, 1});
    // Labelled above the panel, where the curve cannot hide it.
    const double right = panel.left + panel.width;
    out.push_back(Polyline{{{right - 190, panel.top - 13}, {right - 184, panel.top - 13}}, kBlack, 1});
    out.push_back(Polyline{{{right - 178, panel.top - 13}, {right - 172, panel.top - 13}}, kBlack, 1});
    out.push_back(Text{right, panel.top - 8, plot.errorReferenceLabel, 14, kBlack, Anchor::End});
  }
}

std::vector<Primitive> buildFigure(const EvaluationPlot& plot) {
  std::vector<Primitive> out;
  out.push_back(Text{kWidth / 2.0, 30, plot.title, 18, kBlack, Anchor::Middle});
  drawTopView(out, plot, 80, 80, 540);
  drawErrorOverTime(out, plot, 760, 80, 600, 540);
  return out;
}

std::string svgEscape(const std::string& s) {
  std::string r;
  for (char c : s) {
    if (c == '<')
      r += "&lt;";
    else if (c == '>')
      r += "&gt;";
    else if (c == '&')
      r += "&amp;";
    else if (c == '"')
      r += "&quot;";
    else
      r += c;
  }
  return r;
}

std::string svgColour(Colour c) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", c.r, c.g, c.b);
  return buf;
}

void writeSvg(const std::filesystem::path& file, const std::vector<Primitive>& figure) {
  std::ofstream out(file);
  if (!out) throw fileError(file.string(), "cannot open for writing");
  out << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << kWidth << "\" height=\"" << kHeight
      << "\" viewBox=\"0 0 " << kWidth << ' ' << kHeight << "\" font-family=\"sans-serif\">\n"
      << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  char buf[64];
  for (const Primitive& primitive : figure) {
    if (const auto* line = std::get_if<Polyline>(&primitive)) {
      out << "<polyline fill=\"none\" stroke=\"" << svgColour(line->colour) << "\" stroke-width=\""
          << line->width << "\" stroke-linejoin=\"round\" points=\"";
      for (const auto& p : line->points) {
        std::snprintf(buf, sizeof buf, "%.2f,%.2f ", p[0], p[1]);
        out << buf;
      }
      out << "\"/>\n";
    } else if (const auto* text = std::get_if<Text>(&primitive)) {
      static constexpr const char* kAnchors[] = {"start", "middle", "end"};
      out << "<text x=\"" << text->x << "\" y=\"" << text->y << "\" font-size=\"" << text->size
          << "\" fill=\"" << svgColour(text->colour) << "\" text-anchor=\""
          << kAnchors[static_cast<int>(text->anchor)] << "\">" << svgEscape(text->text) << "</text>\n";
    } else if (const auto* dot = std::get_if<Dot>(&primitive)) {
      out << "<circle cx=\"" << dot->x << "\" cy=\"" << dot->y << "\" r=\"" << dot->radius << "\" fill=\""
          << svgColour(dot->colour) << "\"/>\n";
    }
  }
  out << "</svg>\n";
  if (!out.flush()) throw fileError(file.string(), "write failed");
}

void writePng(const std::filesystem::path& file, const std::vector<Primitive>& figure) {
  // Drawn at 2x with 4-bit sub-pixel coordinates, then shrunk: smooth lines and legible text.
  constexpr int kSuper = 2, kShift = 4;
  constexpr double kFixed = kSuper * (1 << kShift);
  cv::Mat canvas(kHeight * kSuper, kWidth * kSuper, CV_8UC3, cv::Scalar(255, 255, 255));
  auto bgr = [](Colour c) { return cv::Scalar(c.b, c.g, c.r); };
  for (const Primitive& primitive : figure) {
    if (const auto* line = std::get_if<Polyline>(&primitive)) {
      std::vector<cv::Point> points;
      for (const auto& p : line->points)
        points.emplace_back(static_cast<int>(std::lround(p[0] * kFixed)),
                            static_cast<int>(std::lround(p[1] * kFixed)));
      cv::polylines(canvas, points, false, bgr(line->colour),
                    std::max(1, static_cast<int>(std::lround(line->width * kSuper))), cv::LINE_AA, kShift);
    } else if (const auto* text = std::get_if<Text>(&primitive)) {
      const double scale = text->size * kSuper / 22.0;  // FONT_HERSHEY_SIMPLEX is ~22 px at scale 1
      int baseline = 0;
      const cv::Size size = cv::getTextSize(text->text, cv::FONT_HERSHEY_SIMPLEX, scale, kSuper, &baseline);
      double x = text->x * kSuper;
      if (text->anchor == Anchor::Middle) x -= size.width / 2.0;
      if (text->anchor == Anchor::End) x -= size.width;
      cv::putText(canvas, text->text, cv::Point(static_cast<int>(x), static_cast<int>(text->y * kSuper)),
                  cv::FONT_HERSHEY_SIMPLEX, scale, bgr(text->colour), kSuper, cv::LINE_AA);
    } else if (const auto* dot = std::get_if<Dot>(&primitive)) {
      cv::circle(canvas,
                 cv::Point(static_cast<int>(std::lround(dot->x * kFixed)),
                           static_cast<int>(std::lround(dot->y * kFixed))),
                 static_cast<int>(std::lround(dot->radius * kFixed)), bgr(dot->colour), cv::FILLED,
                 cv::LINE_AA, kShift);
    }
  }
  cv::Mat image;
  cv::resize(canvas, image, cv::Size(kWidth, kHeight), 0, 0, cv::INTER_AREA);
  writeImageFile(file, image);
}

}  // namespace

void writeEvaluationPlot(const std::filesystem::path& file, const EvaluationPlot& plot) {
  const std::string extension = file.extension().string();
  if (extension != ".png" && extension != ".svg")
    throw fileError(file.string(), "plot file must end in .png or .svg");
  const std::vector<Primitive> figure = buildFigure(plot);
  if (extension == ".svg")
    writeSvg(file, figure);
  else
    writePng(file, figure);
}

}  // namespace orbis::eval
