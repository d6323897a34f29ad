#include "air/mono/mono_config.hpp"

#include <stdexcept>

#include "air/stereo/features/feature_keys.hpp"

namespace aerie::mono {

MonoParams mono_params_from_config(const util::Config& cfg, const std::vector<std::string>& other_sections) {
  MonoParams p;
  util::KeyReader rd(cfg);
  stereo::read_feature_keys(rd, p.features);

  std::string mode = p.tracking == TrackingMode::Klt ? "klt" : "brief";
  rd("tracking.mode", mode);
  if (mode != "klt" && mode != "brief")
    throw std::runtime_error(cfg.origin() + ": tracking.mode must be klt or brief, not '" + mode + "'");
  p.tracking = mode == "klt" ? TrackingMode::Klt : TrackingMode::Brief;
  rd("tracking.klt_window", p.klt_window);
  rd("tracking.klt_levels", p.klt_levels);
  rd("tracking.klt_max_error", p.klt_max_error);
  rd("tracking.min_track_distance_px", p.min_track_distance_px);
  rd("tracking.max_distance", p.matching.max_distance);
  rd("tracking.ratio", p.matching.ratio);
  rd("tracking.search_radius", p.matching.search_radius);

  rd("init.ransac_px", p.init.ransac_px);
  rd("init.sigma_px", p.init.sigma_px);
  rd("init.homography_ratio", p.init.homography_ratio);
  rd("init.min_parallax_deg", p.init.min_parallax_deg);
  rd("init.reprojection_px", p.init.reprojection_px);
  rd("init.min_points", p.init.min_points);
  rd("init.ambiguity", p.init.ambiguity);

  rd("pnp.iterations", p.pnp_iterations);
  rd("pnp.ransac_px", p.pnp_ransac_px);
  rd("pnp.huber_px", p.pnp_huber_px);
  rd("pnp.lost_min_inliers", p.lost_min_inliers);

  rd("keyframes.min_tracked_ratio", p.keyframe_min_tracked_ratio);
  rd("keyframes.parallax_deg", p.keyframe_parallax_deg);
  rd("keyframes.min_landmarks", p.keyframe_min_landmarks);
  rd("keyframes.reprojection_px", p.triangulation_reprojection_px);

  rd("ba.enabled", p.ba.enabled);
  rd("ba.window", p.ba.window);
  rd("ba.max_iterations", p.ba.max_iterations);
  rd("ba.huber_px", p.ba.huber_px);
  rd("ba.outlier_px", p.ba.outlier_px);
  std::string apply = p.ba_synchronous ? "synchronous" : "next_keyframe";
  rd("ba.apply", apply);
  if (apply != "next_keyframe" && apply != "synchronous")
    throw std::runtime_error(cfg.origin() + ": ba.apply must be next_keyframe or synchronous, not '" + apply + "'");
  p.ba_synchronous = apply == "synchronous";

  rd("input.min_contrast", p.min_contrast);
  rd("input.max_skipped_frames", p.max_skipped_frames);

  rd.check_unknown(other_sections);
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(cfg.origin() + ": " + e.what());
  }
  return p;
}

}  // namespace aerie::mono
