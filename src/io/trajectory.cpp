// Trajectory readers and writers for the TUM, KITTI and EuRoC layouts; see trajectory.hpp.
#include "orbis/io/trajectory.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <tuple>

#include "orbis/util/enum_names.hpp"
#include "orbis/util/error.hpp"

namespace orbis {
namespace {

bool isSeparator(char c) { return c == ' ' || c == '\t' || c == ',' || c == '\r'; }

void splitFields(std::string_view line, std::vector<std::string_view>& fields) {
  fields.clear();
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && isSeparator(line[i])) ++i;
    const std::size_t begin = i;
    while (i < line.size() && !isSeparator(line[i])) ++i;
    if (i > begin) fields.push_back(line.substr(begin, i - begin));
  }
}

std::string fieldCountMessage(std::size_t expected, std::size_t found, const char* layout) {
  return "expected " + std::to_string(expected) + " numbers (" + layout + "), found " +
         std::to_string(found);
}

SE3d poseFromQuaternion(const Eigen::Vector3d& t, double qw, double qx, double qy, double qz,
                        const std::filesystem::path& file, std::size_t line) {
  const Eigen::Quaterniond q(qw, qx, qy, qz);
  if (!(q.norm() > 1e-9)) throw lineError(file.string(), line, "quaternion has zero norm");
  return SE3d(SO3d(q.normalized()), t);
}

void requireIncreasing(double previous, double current, bool havePrevious,
                       const std::filesystem::path& file, std::size_t line) {
  if (havePrevious && !(current > previous)) {
    char buf[128];
    std::snprintf(buf, sizeof buf, "timestamp %.9f is not after the previous one (%.9f)", current,
                  previous);
    throw lineError(file.string(), line, buf);
  }
}

// A text file opened for reading; a directory opens on Linux but reads as nothing, so say so.
std::ifstream openText(const std::filesystem::path& file) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) throw fileError(file.string(), "is a directory, expected a text file");
  std::ifstream in(file);
  if (!in) throw fileError(file.string(), "cannot open (missing or unreadable)");
  return in;
}

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

FilePtr openForWriting(const std::filesystem::path& file) {
  FilePtr f(std::fopen(file.c_str(), "w"));
  if (!f) throw fileError(file.string(), "cannot open for writing");
  return f;
}

}  // namespace

void forEachTextRow(const std::filesystem::path& file, const std::function<void(const TextRow&)>& visit) {
  std::ifstream in = openText(file);
  std::string text;
  std::vector<std::string_view> fields;
  std::size_t lineNumber = 0;
  while (std::getline(in, text)) {
    ++lineNumber;
    std::string_view line(text);
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string_view::npos || line[first] == '#') continue;
    splitFields(line, fields);
    if (fields.empty()) continue;  // a line of commas only
    visit(TextRow{lineNumber, fields});
  }
  if (in.bad()) throw fileError(file.string(), "read error");
}

double parseDouble(std::string_view field, const std::filesystem::path& file, std::size_t line) {
  double value = 0.0;
  const char* end = field.data() + field.size();
  const auto [ptr, ec] = std::from_chars(field.data(), end, value);
  if (ec != std::errc() || ptr != end || !std::isfinite(value))
    throw lineError(file.string(), line, "expected a finite number, found '" + std::string(field) + "'");
  return value;
}

long long parseInteger(std::string_view field, const std::filesystem::path& file, std::size_t line) {
  long long value = 0;
  const char* end = field.data() + field.size();
  const auto [ptr, ec] = std::from_chars(field.data(), end, value);
  if (ec != std::errc() || ptr != end)
    throw lineError(file.string(), line, "expected an integer, found '" + std::string(field) + "'");
  return value;
}

namespace {
constexpr EnumName<TrajectoryFormat> kTrajectoryFormatNames[] = {
    {TrajectoryFormat::Tum, "tum"}, {TrajectoryFormat::Kitti, "kitti"}, {TrajectoryFormat::Euroc, "euroc"}};
}  // namespace

TrajectoryFormat parseTrajectoryFormat(std::string_view name, const std::string& source) {
  return parseEnumName(kTrajectoryFormatNames, name, "trajectory format", source);
}

std::string_view toString(TrajectoryFormat format) { return enumName(kTrajectoryFormatNames, format); }

TrajectoryFormat detectTrajectoryFormat(const std::filesystem::path& file) {
  std::ifstream in = openText(file);
  std::string text;
  std::vector<std::string_view> fields;
  while (fields.empty() && std::getline(in, text)) {
    const auto first = text.find_first_not_of(" \t\r");
    if (first != std::string::npos && text[first] != '#') splitFields(text, fields);
  }
  // EuRoC rows are comma separated and start with integer nanoseconds; TUM rows start with
  // seconds. Either may come with either extension (evo writes EuRoC ground truth as TUM).
  const std::size_t columns = fields.size();
  const bool integerTime = columns > 0 && fields[0].find_first_not_of("0123456789") == std::string_view::npos;
  const bool commas = text.find(',') != std::string::npos;
  if (columns >= 8 && integerTime && (commas || file.extension() == ".csv")) return TrajectoryFormat::Euroc;
  if (columns == 8) return TrajectoryFormat::Tum;
  if (columns == 12) return TrajectoryFormat::Kitti;
  if (columns == 0 && file.extension() == ".csv") return TrajectoryFormat::Euroc;
  if (columns == 0) throw fileError(file.string(), "holds no data row (empty, or comments only)");
  throw fileError(file.string(), "cannot tell the trajectory format (first data row has " +
                                     std::to_string(columns) + " columns; use --format)");
}

std::vector<double> readTimestamps(const std::filesystem::path& file) {
  std::vector<double> times;
  forEachTextRow(file, [&](const TextRow& row) {
    if (row.fields.size() != 1)
      throw lineError(file.string(), row.line, fieldCountMessage(1, row.fields.size(), "timestamp"));
    const double t = parseDouble(row.fields[0], file, row.line);
    requireIncreasing(times.empty() ? 0.0 : times.back(), t, !times.empty(), file, row.line);
    times.push_back(t);
  });
  return times;
}

TimeOrder putInTimeOrder(const std::vector<double>& times, const std::vector<std::size_t>& lines) {
  TimeOrder order;
  for (std::size_t i = 1; i < times.size(); ++i) {
    if (times[i] < times[i - 1] && order.outOfOrder++ == 0) order.firstOutOfOrderLine = lines[i];
  }
  std::vector<std::size_t> sorted(times.size());
  for (std::size_t i = 0; i < sorted.size(); ++i) sorted[i] = i;
  if (order.outOfOrder > 0)
    std::stable_sort(sorted.begin(), sorted.end(), [&](std::size_t a, std::size_t b) { return times[a] < times[b]; });
  for (const std::size_t i : sorted) {
    if (!order.keep.empty() && times[i] == times[order.keep.back()]) {
      if (order.repeated++ == 0 || lines[i] < order.firstRepeatedLine) order.firstRepeatedLine = lines[i];
      continue;
    }
    order.keep.push_back(i);
  }
  return order;
}

std::vector<std::string> TimeOrder::warnings(const std::filesystem::path& file) const {
  std::vector<std::string> out;
  if (outOfOrder > 0)
    out.push_back(file.string() + ": " + std::to_string(outOfOrder) + " row(s) earlier than the row before " +
                  "(first at line " + std::to_string(firstOutOfOrderLine) + "); rows sorted by timestamp");
  if (repeated > 0)
    out.push_back(file.string() + ": " + std::to_string(repeated) + " row(s) repeat an earlier timestamp " +
                  "(first at line " + std::to_string(firstRepeatedLine) + "); kept the first of each");
  return out;
}

namespace {

// Sorts and de-duplicates a TUM or EuRoC trajectory read with the given line numbers.
Trajectory inTimeOrder(Trajectory rows, const std::vector<std::size_t>& lines, const std::filesystem::path& file,
                       std::vector<std::string>* warnings) {
  std::vector<double> times;
  times.reserve(rows.size());
  for (const StampedPose& row : rows) times.push_back(row.t);
  const TimeOrder order = putInTimeOrder(times, lines);
  for (const std::string& w : order.warnings(file)) {
    if (warnings) warnings->push_back(w);
    else std::fprintf(stderr, "warning: %s\n", w.c_str());
  }
  if (order.keep.size() == rows.size() && order.outOfOrder == 0) return rows;
  Trajectory kept;
  kept.reserve(order.keep.size());
  for (const std::size_t i : order.keep) kept.push_back(rows[i]);
  return kept;
}

}  // namespace

Trajectory readTrajectory(const std::filesystem::path& file, TrajectoryFormat format,
                          const std::filesystem::path& kittiTimesFile, std::vector<std::string>* warnings) {
  Trajectory trajectory;
  std::vector<std::size_t> lines;
  double v[12];
  auto parseAll = [&](const TextRow& row, std::size_t count) {
    for (std::size_t i = 0; i < count; ++i) v[i] = parseDouble(row.fields[i], file, row.line);
  };
  switch (format) {
    case TrajectoryFormat::Tum:
      forEachTextRow(file, [&](const TextRow& row) {
        if (row.fields.size() != 8)
          throw lineError(file.string(), row.line,
                          fieldCountMessage(8, row.fields.size(), "TUM: t tx ty tz qx qy qz qw"));
        parseAll(row, 8);
        lines.push_back(row.line);
        trajectory.push_back(
            {v[0], poseFromQuaternion({v[1], v[2], v[3]}, v[7], v[4], v[5], v[6], file, row.line)});
      });
      break;
    case TrajectoryFormat::Euroc:
      forEachTextRow(file, [&](const TextRow& row) {
        if (row.fields.size() < 8)
          throw lineError(file.string(), row.line,
                          fieldCountMessage(8, row.fields.size(),
                                            "EuRoC: t[ns], px, py, pz, qw, qx, qy, qz, ..."));
        const double t = static_cast<double>(parseInteger(row.fields[0], file, row.line)) * 1e-9;
        for (std::size_t i = 1; i < 8; ++i) v[i] = parseDouble(row.fields[i], file, row.line);
        lines.push_back(row.line);
        trajectory.push_back(
            {t, poseFromQuaternion({v[1], v[2], v[3]}, v[4], v[5], v[6], v[7], file, row.line)});
      });
      break;
    case TrajectoryFormat::Kitti: {
      forEachTextRow(file, [&](const TextRow& row) {
        if (row.fields.size() != 12)
          throw lineError(file.string(), row.line,
                          fieldCountMessage(12, row.fields.size(), "KITTI: 3x4 matrix, row-major"));
        parseAll(row, 12);
        Eigen::Matrix3d rotation;
        rotation << v[0], v[1], v[2], v[4], v[5], v[6], v[8], v[9], v[10];
        if (!(std::abs(rotation.determinant() - 1.0) < 0.1))
          throw lineError(file.string(), row.line, "the 3x3 part is not a rotation matrix");
        trajectory.push_back({static_cast<double>(trajectory.size()),
                              SE3d(SO3d(rotation), Eigen::Vector3d(v[3], v[7], v[11]))});
      });
      if (!kittiTimesFile.empty()) {
        const std::vector<double> times = readTimestamps(kittiTimesFile);
        if (times.size() != trajectory.size())
          throw fileError(kittiTimesFile.string(),
                          "has " + std::to_string(times.size()) + " timestamps but " +
                              file.string() + " has " + std::to_string(trajectory.size()) + " poses");
        for (std::size_t i = 0; i < times.size(); ++i) trajectory[i].t = times[i];
      }
      break;
    }
  }
  if (format == TrajectoryFormat::Kitti) return trajectory;
  return inTimeOrder(std::move(trajectory), lines, file, warnings);
}

Trajectory posesCovering(const Trajectory& trajectory, const Trajectory& span, double marginSeconds) {
  if (span.empty()) return trajectory;
  const double t0 = span.front().t - marginSeconds, t1 = span.back().t + marginSeconds;
  Trajectory out;
  for (const StampedPose& s : trajectory)
    if (s.t >= t0 && s.t <= t1) out.push_back(s);
  return out;
}

std::vector<std::pair<std::size_t, std::size_t>> associateTimestamps(const std::vector<double>& a,
                                                                     const std::vector<double>& b,
                                                                     double maxDt) {
  struct Candidate {
    double dt;
    std::size_t ia, ib;
  };
  std::vector<Candidate> candidates;
  // Both lists are increasing, so each a[i]'s candidates in b form a sliding window.
  std::size_t windowStart = 0;
  for (std::size_t ia = 0; ia < a.size(); ++ia) {
    while (windowStart < b.size() && b[windowStart] < a[ia] - maxDt) ++windowStart;
    for (std::size_t ib = windowStart; ib < b.size() && b[ib] <= a[ia] + maxDt; ++ib)
      candidates.push_back({std::abs(b[ib] - a[ia]), ia, ib});
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
    return std::tie(x.dt, x.ia, x.ib) < std::tie(y.dt, y.ia, y.ib);
  });
  std::vector<bool> usedA(a.size(), false), usedB(b.size(), false);
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (const Candidate& c : candidates) {
    if (usedA[c.ia] || usedB[c.ib]) continue;
    usedA[c.ia] = usedB[c.ib] = true;
    pairs.emplace_back(c.ia, c.ib);
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

void writeTrajectory(const std::filesystem::path& file, const Trajectory& trajectory,
                     TrajectoryFormat format) {
  FilePtr f = openForWriting(file);
  std::FILE* out = f.get();
  if (format == TrajectoryFormat::Tum) std::fputs("# timestamp tx ty tz qx qy qz qw\n", out);
  if (format == TrajectoryFormat::Euroc)
    std::fputs("#timestamp [ns],p_x [m],p_y [m],p_z [m],q_w [],q_x [],q_y [],q_z []\n", out);
  for (const StampedPose& sp : trajectory) {
    const Eigen::Vector3d p = sp.pose.translation();
    const Eigen::Quaterniond& q = sp.pose.so3().unitQuaternion();
    switch (format) {
      case TrajectoryFormat::Tum:
        std::fprintf(out, "%.9f %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", sp.t, p.x(), p.y(), p.z(),
                     q.x(), q.y(), q.z(), q.w());
        break;
      case TrajectoryFormat::Euroc:
        std::fprintf(out, "%lld,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", std::llround(sp.t * 1e9),
                     p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z());
        break;
      case TrajectoryFormat::Kitti: {
        const Eigen::Matrix3d r = sp.pose.rotationMatrix();
        for (int row = 0; row < 3; ++row)
          std::fprintf(out, "%.9e %.9e %.9e %.9e%c", r(row, 0), r(row, 1), r(row, 2), p[row],
                       row == 2 ? '\n' : ' ');
        break;
      }
    }
  }
  if (std::ferror(out) || std::fflush(out) != 0) throw fileError(file.string(), "write failed");
}

}  // namespace orbis
