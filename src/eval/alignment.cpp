// Timestamp association and Umeyama alignment; see orbis/eval/alignment.hpp.
#include "orbis/eval/alignment.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "orbis/util/enum_names.hpp"
#include "orbis/util/error.hpp"

namespace orbis::eval {

std::vector<PosePair> associateByTime(const Trajectory& groundTruth, const Trajectory& estimate,
                                      double maxDt) {
  std::vector<double> estimateTimes, groundTruthTimes;
  for (const StampedPose& sp : estimate) estimateTimes.push_back(sp.t);
  for (const StampedPose& sp : groundTruth) groundTruthTimes.push_back(sp.t);
  std::vector<PosePair> pairs;
  for (const auto& [e, g] : associateTimestamps(estimateTimes, groundTruthTimes, maxDt))
    pairs.push_back({g, e});
  return pairs;
}

std::vector<PosePair> associateByIndex(const Trajectory& groundTruth, const Trajectory& estimate) {
  if (groundTruth.size() != estimate.size())
    throw Error("evaluation", "",
                "frame-for-frame pairing needs equal lengths; ground truth has " +
                    std::to_string(groundTruth.size()) + " poses, estimate " +
                    std::to_string(estimate.size()));
  std::vector<PosePair> pairs(groundTruth.size());
  for (std::size_t i = 0; i < pairs.size(); ++i) pairs[i] = {i, i};
  return pairs;
}

namespace {
constexpr EnumName<Alignment> kAlignmentNames[] = {
    {Alignment::SE3, "se3"}, {Alignment::Sim3, "sim3"}, {Alignment::None, "none"}};
}  // namespace

Alignment parseAlignment(std::string_view name, const std::string& source) {
  return parseEnumName(kAlignmentNames, name, "alignment", source);
}

std::string_view toString(Alignment alignment) { return enumName(kAlignmentNames, alignment); }

Sim3d umeyamaAlignment(const Eigen::Matrix3Xd& source, const Eigen::Matrix3Xd& target, bool estimateScale) {
  const Eigen::Index n = source.cols();
  if (n == 0 || target.cols() != n) return Sim3d();
  const Eigen::Vector3d sourceMean = source.rowwise().mean();
  const Eigen::Vector3d targetMean = target.rowwise().mean();
  const Eigen::Matrix3Xd sourceCentred = source.colwise() - sourceMean;
  const Eigen::Matrix3Xd targetCentred = target.colwise() - targetMean;
  const double invN = 1.0 / static_cast<double>(n);
  const Eigen::Matrix3d covariance = invN * targetCentred * sourceCentred.transpose();

  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
  // Reflection guard: flip the smallest singular direction when U V^T would be a reflection.
  Eigen::Vector3d signs(1.0, 1.0, 1.0);
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) signs.z() = -1.0;
  const Eigen::Matrix3d rotation = svd.matrixU() * signs.asDiagonal() * svd.matrixV().transpose();

  double scale = 1.0;
  if (estimateScale) {
    const double sourceVariance = invN * sourceCentred.squaredNorm();
    if (sourceVariance > 0.0) scale = svd.singularValues().dot(signs) / sourceVariance;
    if (!(scale > 0.0)) scale = 1.0;  // all source points coincide, or degenerate geometry
  }
  const Eigen::Vector3d translation = targetMean - scale * rotation * sourceMean;
  return Sim3d(scale, SO3d(rotation), translation);
}

Sim3d alignTrajectories(const Trajectory& groundTruth, const Trajectory& estimate,
                        const std::vector<PosePair>& pairs, Alignment alignment) {
  if (alignment == Alignment::None || pairs.empty()) return Sim3d();
  Eigen::Matrix3Xd source(3, static_cast<Eigen::Index>(pairs.size()));
  Eigen::Matrix3Xd target(3, static_cast<Eigen::Index>(pairs.size()));
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    source.col(static_cast<Eigen::Index>(i)) = estimate[pairs[i].estimate].pose.translation();
    target.col(static_cast<Eigen::Index>(i)) = groundTruth[pairs[i].groundTruth].pose.translation();
  }
  return umeyamaAlignment(source, target, alignment == Alignment::Sim3);
}

SE3d applySimilarity(const Sim3d& similarity, const SE3d& pose) {
  return SE3d(similarity.so3() * pose.so3(), similarity * pose.translation());
}

}  // namespace orbis::eval
