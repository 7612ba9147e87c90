// orbis eval ate|rpe|kitti GT EST — scores an estimated trajectory against ground truth.
#include <cstdio>
#include <string>
#include <vector>

#include "command.hpp"
#include "orbis/eval/metrics.hpp"
#include "orbis/eval/plot.hpp"
#include "orbis/io/trajectory.hpp"
#include "orbis/util/error.hpp"
#include "orbis/util/json.hpp"

namespace orbis::cli {
namespace {

void writeStats(JsonWriter& json, const eval::ErrorStatistics& s) {
  json.field("rmse", s.rmse)
      .field("mean", s.mean)
      .field("median", s.median)
      .field("max", s.max)
      .field("min", s.min)
      .field("std", s.std);
}

void printStats(const char* heading, const eval::ErrorStatistics& s, const char* unit) {
  std::printf("%s\n", heading);
  std::printf("  rmse    %12.6f %s\n  mean    %12.6f %s\n  median  %12.6f %s\n", s.rmse, unit, s.mean, unit,
              s.median, unit);
  std::printf("  max     %12.6f %s\n  min     %12.6f %s\n  std     %12.6f %s\n", s.max, unit, s.min, unit,
              s.std, unit);
}

// The picture shows the matched estimate aligned; without an alignment asked for, SE(3) is used.
Trajectory alignedForPicture(const Trajectory& gt, const Trajectory& est,
                             const std::vector<eval::PosePair>& pairs, eval::Alignment align) {
  const Sim3d alignment =
      eval::alignTrajectories(gt, est, pairs, align == eval::Alignment::None ? eval::Alignment::SE3 : align);
  Trajectory aligned;
  for (const auto& pair : pairs)
    aligned.push_back({est[pair.estimate].t, eval::applySimilarity(alignment, est[pair.estimate].pose)});
  return aligned;
}

void plot(const std::string& file, std::string title, const Trajectory& gt, Trajectory aligned,
          std::vector<double> times, std::vector<double> errors, std::string errorLabel, double level,
          const char* levelFormat) {
  eval::EvaluationPlot picture;
  picture.title = std::move(title);
  picture.groundTruth = posesCovering(gt, aligned, 1.0);
  picture.estimate = std::move(aligned);
  picture.errorTimes = std::move(times);
  picture.errors = std::move(errors);
  picture.errorLabel = std::move(errorLabel);
  picture.errorReference = level;
  char label[64];
  std::snprintf(label, sizeof label, levelFormat, level);
  picture.errorReferenceLabel = label;
  eval::writeEvaluationPlot(file, picture);
  std::fprintf(stderr, "plot written to %s\n", file.c_str());
}

int runEval(const std::vector<std::string>& args) {
  ArgParser parser("orbis eval ate|rpe|kitti GT EST [options]",
                   "Scores the estimated trajectory EST against the ground truth GT.\n"
                   "  ate    absolute trajectory error after alignment (position error, metres)\n"
                   "  rpe    relative pose error over a delta in frames or metres\n"
                   "  kitti  KITTI odometry t_rel (%) and r_rel (deg/100 m) over 100..800 m segments");
  parser.positional("metric", "ate, rpe or kitti")
      .positional("GT", "ground-truth trajectory file")
      .positional("EST", "estimated trajectory file")
      .option("--format", "F", "tum, kitti or euroc for both files (default: detected per file)")
      .option("--align", "A", "se3, sim3 or none (default: se3 for ate, none for rpe and kitti)")
      .option("--max-dt", "S", "largest timestamp difference of an associated pair, seconds", "0.02")
      .option("--delta", "N", "rpe: distance between the two poses of a pair", "1")
      .option("--delta-unit", "U", "rpe: frames or m", "frames")
      .flag("--json", "print one JSON object on standard output instead of a table")
      .option("--gt-times", "FILE", "timestamps for a KITTI-format GT (times.txt); default: frame index")
      .option("--est-times", "FILE", "timestamps for a KITTI-format EST; default: frame index")
      .option("--plot", "FILE",
              "draw the estimate over the ground truth and the error over time (.png or .svg)");
  if (!parser.parse(args)) return 0;

  const std::string metric = parser.pos(0);
  if (metric != "ate" && metric != "rpe" && metric != "kitti")
    throw Error("argument metric", "", "expected ate, rpe or kitti, got '" + metric + "'");
  const std::string gtPath = parser.pos(1), estPath = parser.pos(2);
  const auto formatOf = [&](const std::string& path) {
    const auto f = parser.getOptional("--format");
    return f ? parseTrajectoryFormat(*f, "argument --format") : detectTrajectoryFormat(path);
  };
  const TrajectoryFormat gtFormat = formatOf(gtPath), estFormat = formatOf(estPath);
  const Trajectory gt = readTrajectory(gtPath, gtFormat, parser.getOptional("--gt-times").value_or(""));
  const Trajectory est = readTrajectory(estPath, estFormat, parser.getOptional("--est-times").value_or(""));
  const auto alignName = parser.getOptional("--align");
  const eval::Alignment align = alignName         ? eval::parseAlignment(*alignName, "argument --align")
                                : metric == "ate" ? eval::Alignment::SE3
                                                  : eval::Alignment::None;
  const double maxDt = parser.getDouble("--max-dt");
  if (!(maxDt >= 0)) throw Error("argument --max-dt", "", "expects a non-negative number of seconds");
  const bool asJson = parser.has("--json");
  const auto plotFile = parser.getOptional("--plot");
  JsonWriter json;
  json.beginObject().field("metric", metric).field("align", eval::toString(align));
  char title[256];

  if (metric == "ate") {
    eval::AteOptions options;
    options.alignment = align;
    options.maxDt = maxDt;
    const eval::AteResult ate = eval::computeAte(gt, est, options);
    if (asJson) {
      writeStats(json, ate.stats);
      json.field("matched", ate.stats.count).field("scale", ate.alignment.scale());
    } else {
      std::printf("ATE, %s alignment, max dt %.3f s: %zu matched poses (%zu estimated, %zu ground truth)\n",
                  std::string(eval::toString(align)).c_str(), maxDt, ate.stats.count, est.size(), gt.size());
      printStats("position error:", ate.stats, "m");
      if (align == eval::Alignment::Sim3) std::printf("  scale   %12.6f\n", ate.alignment.scale());
    }
    if (plotFile) {
      std::snprintf(title, sizeof title, "ATE (%s): RMSE %.4f m over %zu poses",
                    std::string(eval::toString(align)).c_str(), ate.stats.rmse, ate.stats.count);
      std::vector<double> times;
      for (const auto& pair : ate.pairs) times.push_back(gt[pair.groundTruth].t);
      plot(*plotFile, title, gt, ate.alignedEstimate, times, ate.errors, "position error [m]", ate.stats.rmse,
           "RMSE %.4f m");
    }
  } else if (metric == "rpe") {
    eval::RpeOptions options;
    options.delta = parser.getDouble("--delta");
    const std::string unit = parser.get("--delta-unit");
    if (unit != "frames" && unit != "m")
      throw Error("argument --delta-unit", "", "expected frames or m, got '" + unit + "'");
    options.unit = unit == "m" ? eval::DeltaUnit::Metres : eval::DeltaUnit::Frames;
    options.alignment = align;
    options.maxDt = maxDt;
    const eval::RpeResult rpe = eval::computeRpe(gt, est, options);
    if (asJson) {
      writeStats(json, rpe.translation);
      json.field("matched", rpe.matched)
          .field("pairs", rpe.translation.count)
          .field("delta", options.delta)
          .field("delta_unit", unit);
      json.key("rotation_deg").beginObject();
      writeStats(json, rpe.rotationDegrees);
      json.endObject();
    } else {
      std::printf("RPE, delta %g %s, %s alignment: %zu pairs from %zu matched poses\n", options.delta,
                  unit.c_str(), std::string(eval::toString(align)).c_str(), rpe.translation.count,
                  rpe.matched);
      printStats("translation error:", rpe.translation, "m");
      printStats("rotation error:", rpe.rotationDegrees, "deg");
    }
    if (plotFile) {
      std::snprintf(title, sizeof title, "RPE (delta %g %s): translation RMSE %.4f m over %zu pairs",
                    options.delta, unit.c_str(), rpe.translation.rmse, rpe.translation.count);
      plot(*plotFile, title, gt, alignedForPicture(gt, est, eval::associateByTime(gt, est, maxDt), align),
           rpe.times, rpe.translationErrors, "relative translation error [m]", rpe.translation.rmse,
           "RMSE %.4f m");
    }
  } else {
    // KITTI pairs frame for frame; files with real timestamps are associated first.
    const bool byIndex = gt.size() == est.size() &&
                         (gtFormat == TrajectoryFormat::Kitti || estFormat == TrajectoryFormat::Kitti);
    const std::vector<eval::PosePair> pairs =
        byIndex ? eval::associateByIndex(gt, est) : eval::associateByTime(gt, est, maxDt);
    const Sim3d alignment = eval::alignTrajectories(gt, est, pairs, align);
    std::vector<SE3d> gtPoses, estPoses;
    for (const auto& pair : pairs) {
      gtPoses.push_back(gt[pair.groundTruth].pose);
      estPoses.push_back(eval::applySimilarity(alignment, est[pair.estimate].pose));
    }
    const eval::KittiResult kitti = eval::computeKittiMetric(gtPoses, estPoses);
    if (asJson) {
      json.field("t_rel", kitti.translationPercent)
          .field("r_rel", kitti.rotationDegPer100m)
          .field("segments", kitti.segments.size())
          .field("matched", pairs.size());
      json.key("per_length").beginArray();
      for (const auto& l : kitti.perLength)
        json.beginObject()
            .field("length", l.length)
            .field("segments", l.segments)
            .field("t_rel", l.translationPercent)
            .field("r_rel", l.rotationDegPer100m)
            .endObject();
      json.endArray();
    } else {
      std::printf("KITTI odometry metric: %zu segments from %zu poses\n", kitti.segments.size(),
                  pairs.size());
      std::printf("  t_rel %10.4f %%\n  r_rel %10.4f deg/100 m\n", kitti.translationPercent,
                  kitti.rotationDegPer100m);
      std::printf("  %8s %9s %10s %14s\n", "length", "segments", "t_rel [%]", "r_rel [deg/100m]");
      for (const auto& l : kitti.perLength)
        std::printf("  %6.0f m %9zu %10.4f %14.4f\n", l.length, l.segments, l.translationPercent,
                    l.rotationDegPer100m);
    }
    if (plotFile) {
      std::snprintf(title, sizeof title, "KITTI: t_rel %.3f %%, r_rel %.4f deg/100 m over %zu segments",
                    kitti.translationPercent, kitti.rotationDegPer100m, kitti.segments.size());
      std::vector<double> times, errors;
      for (const auto& s : kitti.segments) {
        times.push_back(gt[pairs[s.firstFrame].groundTruth].t);
        errors.push_back(100.0 * s.translationError);
      }
      plot(*plotFile, title, gt, alignedForPicture(gt, est, pairs, align), times, errors,
           "segment translation error [%]", kitti.translationPercent, "t_rel %.3f %%");
    }
  }
  if (asJson) std::printf("%s\n", json.endObject().str().c_str());
  return 0;
}

}  // namespace

ORBIS_REGISTER_COMMAND("eval", "score a trajectory: ATE, RPE or the KITTI odometry metric", runEval);

}  // namespace orbis::cli
