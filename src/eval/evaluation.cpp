#include "elo/eval/evaluation.hpp"

#include <cmath>
#include <limits>

namespace elo {
namespace {

// The RMSE over the union of samples of several RMSEs, each weighted by its sample count; parts
// without samples (NaN) are left out.
template <typename Part, typename Rmse, typename Count>
double pooledRmse(const std::vector<Part>& parts, Rmse rmse_of, Count count_of) {
  double squares = 0.0;
  double samples = 0.0;
  for (const Part& part : parts) {
    if (count_of(part) > 0) {
      squares += std::pow(rmse_of(part), 2) * static_cast<double>(count_of(part));
      samples += static_cast<double>(count_of(part));
    }
  }
  return samples > 0.0 ? std::sqrt(squares / samples) : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

TrajectoryEvaluation evaluateTrajectory(const std::string& name, const std::vector<Eigen::Isometry3d>& ground_truth,
                                        const std::vector<Eigen::Isometry3d>& estimate,
                                        const std::vector<double>& segment_lengths, size_t start_step,
                                        const std::vector<FrameRange>& excluded_frames) {
  TrajectoryEvaluation evaluation;
  evaluation.name = name;
  const std::vector<SegmentError> segments = kittiSegmentErrors(ground_truth, estimate, segment_lengths, start_step);
  evaluation.segments = segmentsClearOf(segments, excluded_frames);
  evaluation.segments_left_out = segments.size() - evaluation.segments.size();
  evaluation.frames = ground_truth.size();
  const std::vector<double> distances = trajectoryDistances(ground_truth);
  evaluation.length_m = distances.empty() ? 0.0 : distances.back();
  evaluation.drift = averageDrift(evaluation.segments);
  evaluation.components = segmentComponents(ground_truth, estimate, evaluation.segments);
  evaluation.breakdown = averageBreakdown(evaluation.components);
  evaluation.rpe = relativePoseError(ground_truth, estimate);
  evaluation.ate = absoluteTrajectoryError(ground_truth, estimate);
  return evaluation;
}

TrajectoryEvaluation poolEvaluations(const std::string& name, const std::vector<TrajectoryEvaluation>& sequences) {
  TrajectoryEvaluation pooled;
  pooled.name = name;
  for (const TrajectoryEvaluation& sequence : sequences) {
    pooled.frames += sequence.frames;
    pooled.length_m += sequence.length_m;
    pooled.segments.insert(pooled.segments.end(), sequence.segments.begin(), sequence.segments.end());
    pooled.segments_left_out += sequence.segments_left_out;
    pooled.components.insert(pooled.components.end(), sequence.components.begin(), sequence.components.end());
    pooled.rpe.pairs += sequence.rpe.pairs;
    pooled.ate.frames += sequence.ate.frames;
  }
  pooled.drift = averageDrift(pooled.segments);
  pooled.breakdown = averageBreakdown(pooled.components);
  pooled.rpe.translation_rmse_m = pooledRmse(
      sequences, [](const auto& s) { return s.rpe.translation_rmse_m; }, [](const auto& s) { return s.rpe.pairs; });
  pooled.rpe.rotation_rmse_deg = pooledRmse(
      sequences, [](const auto& s) { return s.rpe.rotation_rmse_deg; }, [](const auto& s) { return s.rpe.pairs; });
  pooled.ate.translation_rmse_m = pooledRmse(
      sequences, [](const auto& s) { return s.ate.translation_rmse_m; }, [](const auto& s) { return s.ate.frames; });
  return pooled;
}

}  // namespace elo
