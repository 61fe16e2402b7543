#pragma once
/// \file metrics.h
/// Accuracy metrics: the paper's Sec. 4.1 error and AUC (the OPT benchmark's metric) and
/// the 5 cm / 5 deg success rate.

#include <Eigen/Core>
#include <vector>

#include "klt_contour_tracker/core/pose.h"

namespace kct {

/// delta_i of Sec. 4.1: mean distance (model units) between the model vertices placed by the
/// estimated and by the true pose.
double mean_vertex_distance(const std::vector<Eigen::Vector3d>& vertices_object,
                            const Pose& estimated, const Pose& truth);

/// Fraction (0..1) of frames whose delta is below k * diameter.
double success_rate(const std::vector<double>& deltas, double diameter, double k);

/// Area under the success curve (success in percent, k from 0 to k_max): 0..100*k_max, i.e.
/// 0..20 for the paper's k_max = 0.2. Computed exactly: (100/N) * sum_i max(0, k_max - delta_i/d).
double auc_score(const std::vector<double>& deltas, double diameter, double k_max = 0.2);

/// Fraction (0..1) of frames with translation error < max_translation (model units) and
/// rotation error < max_rotation_deg.
double success_translation_rotation(const std::vector<Pose>& estimated,
                                    const std::vector<Pose>& truth, double max_translation,
                                    double max_rotation_deg);

/// Median of a list (0 for an empty list).
double median(std::vector<double> values);

/// Nearest-rank percentile of a list: the smallest value with at least `percent` % of the list
/// at or below it (0 for an empty list). `percent` is clamped to [0, 100]: 0 gives the minimum,
/// 100 the maximum.
double percentile(std::vector<double> values, double percent);

}  // namespace kct
