#include "klt_contour_tracker/core/metrics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kct {

double mean_vertex_distance(const std::vector<Eigen::Vector3d>& vertices_object,
                            const Pose& estimated, const Pose& truth) {
  if (vertices_object.empty()) return 0.0;
  double sum = 0.0;
  for (const Eigen::Vector3d& v : vertices_object) sum += (estimated * v - truth * v).norm();
  return sum / vertices_object.size();
}

double success_rate(const std::vector<double>& deltas, double diameter, double k) {
  if (deltas.empty()) return 0.0;
  const auto passed = std::count_if(deltas.begin(), deltas.end(),
                                    [&](double d) { return d < k * diameter; });
  return static_cast<double>(passed) / deltas.size();
}

double auc_score(const std::vector<double>& deltas, double diameter, double k_max) {
  if (!(diameter > 0)) throw std::invalid_argument("auc_score: diameter must be > 0");
  if (deltas.empty()) return 0.0;
  // success(k) is a step function; its integral over [0, k_max] is the sum of the parts of
  // [0, k_max] above each frame's delta/d.
  double sum = 0.0;
  for (double d : deltas) sum += std::max(0.0, k_max - d / diameter);
  return 100.0 * sum / deltas.size();
}

double success_translation_rotation(const std::vector<Pose>& estimated,
                                    const std::vector<Pose>& truth, double max_translation,
                                    double max_rotation_deg) {
  const size_t n = std::min(estimated.size(), truth.size());
  if (n == 0) return 0.0;
  size_t passed = 0;
  for (size_t i = 0; i < n; ++i)
    if (translation_error(estimated[i], truth[i]) < max_translation &&
        rotation_error_deg(estimated[i], truth[i]) < max_rotation_deg)
      ++passed;
  return static_cast<double>(passed) / n;
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  if (values.size() % 2) return values[mid];
  const double upper = values[mid];
  return 0.5 * (upper + *std::max_element(values.begin(), values.begin() + mid));
}

double percentile(std::vector<double> values, double percent) {
  if (values.empty()) return 0.0;
  const double clamped = std::min(100.0, std::max(0.0, percent));
  // Nearest rank: ceil(p/100 * n), 1-based; at least the first value.
  const size_t rank = std::max<size_t>(1, static_cast<size_t>(std::ceil(clamped / 100.0 * values.size())));
  std::nth_element(values.begin(), values.begin() + (rank - 1), values.end());
  return values[rank - 1];
}

}  // namespace kct
