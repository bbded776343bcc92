#include "evio/estimator/frontend/haste_options.h"

#include <cmath>

#include "evio/core/error.h"

namespace evio::estimator {

HasteVariant parseHasteVariant(const std::string& name) {
  if (name == "haste_correlation") return HasteVariant::kCorrelation;
  if (name == "haste_correlation_star") return HasteVariant::kCorrelationStar;
  if (name == "haste_difference") return HasteVariant::kDifference;
  if (name == "haste_difference_star") return HasteVariant::kDifferenceStar;
  throw Error("variant: must be haste_correlation, haste_correlation_star, haste_difference or "
              "haste_difference_star (got '" + name + "')");
}

int HasteOptions::windowSize() const {
  return 1 + 2 * static_cast<int>(std::floor(window_factor * patch_size_px * patch_size_px / 2.0));
}

void HasteOptions::validate() const {
  parseHasteVariant(variant);
  requireField(patch_size_px >= 5 && patch_size_px % 2 == 1 && patch_size_px <= 101, "patch_size_px",
               "must be odd and in [5, 101]");
  requireInRange("window_factor", window_factor, 0.01, 1.0);
  requireField(windowSize() >= 3, "window_factor", "gives a window of fewer than 3 events");
  requireInRange("margin", margin, 0.0, 1.0);
  requireInRange("template_update", template_update, 0.0, 10.0);
  requireInRange("step_px", step_px, 0.01, 10.0);
  requireInRange("step_deg", step_deg, 0.01, 45.0);
  requireField(max_features >= 1 && max_features <= 4096, "max_features", "must be in [1, 4096]");
  requireField(min_features >= 0 && min_features <= max_features, "min_features", "must be in [0, max_features]");
  requirePositive("harris_quality_level", harris_quality_level);
  requirePositive("harris_k", harris_k);
  requireField(harris_block_size >= 1 && harris_block_size <= 101, "harris_block_size", "must be in [1, 101]");
  requireNonNegative("min_distance_px", min_distance_px);
  requireField(history_events >= 0 && history_events <= (1 << 24), "history_events", "must be in [0, 16777216]");
  requireInRange("seed_timeout_s", seed_timeout_s, 1e-6, 1e6);
  requireInRange("lost_border_px", lost_border_px, 0.0, 1000.0);
  requireInRange("error_time_s", error_time_s, 0.0, 60.0);
  requireInRange("position_sigma_px", position_sigma_px, 0.0, 100.0);
}

}  // namespace evio::estimator
