#include "air/stereo/vo/vo_config.hpp"

#include <algorithm>
#include <stdexcept>

#include "air/stereo/features/feature_keys.hpp"

namespace aerie::stereo {

VoParams vo_params_from_config(const util::Config& cfg, const std::vector<std::string>& other_sections) {
  VoParams p;
  util::KeyReader rd(cfg);
  SgmParams& s = p.depth.sgm;
  rd("depth.num_disparities", s.num_disparities);
  rd("depth.p1", s.p1);
  rd("depth.p2", s.p2);
  rd("depth.census_width", s.census_width);
  rd("depth.census_height", s.census_height);
  rd("depth.paths", s.paths);
  rd("depth.uniqueness_percent", s.uniqueness_percent);
  rd("depth.lr_max_diff", s.lr_max_diff);
  rd("depth.subpixel", s.subpixel);
  rd("depth.speckle_window", s.speckle_window);
  rd("depth.speckle_range", s.speckle_range);
  rd("depth.fine_window", p.depth.fine_window);
  rd("depth.every", p.depth_every);
  rd("depth.scale", p.depth_scale);
  rd("depth.refine_radius", p.refine_radius);
  rd("depth.refine_half_window", p.refine_half_window);
  rd("depth.max_depth_m", p.max_depth_m);

  read_feature_keys(rd, p.features);

  rd("matching.max_distance", p.matching.max_distance);
  rd("matching.ratio", p.matching.ratio);
  rd("matching.search_radius", p.matching.search_radius);
  rd("matching.predicted_search_radius", p.predicted_search_radius);
  rd("matching.mutual", p.matching.mutual);
  rd("matching.klt_window", p.klt_window);

  MotionParams& m = p.motion;
  rd("motion.ransac_iterations", m.ransac_iterations);
  rd("motion.ransac_threshold_px", m.ransac_threshold_px);
  rd("motion.inlier_threshold_px", m.inlier_threshold_px);
  rd("motion.inlier_threshold_2d_px", m.inlier_threshold_2d_px);
  rd("motion.huber_px", m.huber_px);
  rd("motion.weight_2d", m.weight_2d);
  rd("motion.max_iterations", m.max_iterations);
  rd("motion.rounds", m.rounds);
  rd("motion.min_3d", m.min_3d);
  rd("motion.lost_min_inliers", p.lost_min_inliers);

  rd("keyframes.min_tracked", p.keyframe_min_tracked);
  rd("keyframes.translation_m", p.keyframe_translation_m);
  rd("keyframes.rotation_deg", p.keyframe_rotation_deg);

  rd("ba.enabled", p.ba.enabled);
  rd("ba.window", p.ba.window);
  rd("ba.max_iterations", p.ba.max_iterations);
  rd("ba.huber_px", p.ba.huber_px);
  rd("ba.outlier_px", p.ba.outlier_px);
  rd("ba.min_observations", p.ba.min_observations);
  rd("ba.max_depth_m", p.ba.max_depth_m);
  rd("ba.synchronous", p.ba_synchronous);
  std::string apply = p.ba_next_keyframe ? "next_keyframe" : "when_ready";
  rd("ba.apply", apply);
  if (apply != "next_keyframe" && apply != "when_ready")
    throw std::runtime_error(cfg.origin() + ": ba.apply must be next_keyframe or when_ready, not '" + apply + "'");
  p.ba_next_keyframe = apply == "next_keyframe";

  rd.check_unknown(other_sections);
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(cfg.origin() + ": " + e.what());
  }
  return p;
}

}  // namespace aerie::stereo
