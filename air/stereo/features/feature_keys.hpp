#pragma once
// The `features.*` keys of a VO config (config/vo.yaml, config/mono.yaml): one list for the
// stereo and the monocular front end.
#include "air/stereo/features/features.hpp"
#include "common/util/key_reader.hpp"

namespace aerie::stereo {

inline void read_feature_keys(util::KeyReader& rd, FeatureParams& f) {
  rd("features.buckets_x", f.buckets_x);
  rd("features.buckets_y", f.buckets_y);
  rd("features.margin_x", f.margin_x);
  rd("features.margin_y", f.margin_y);
  rd("features.max_per_bucket", f.max_per_bucket);
  rd("features.fast_threshold", f.fast_threshold);
  rd("features.min_fast_threshold", f.min_fast_threshold);
  rd("features.smoothing_sigma", f.smoothing_sigma);
  rd("features.subpixel", f.subpixel);
  rd("features.patch_size", f.patch_size);
  rd("features.descriptor_bits", f.descriptor_bits);
  rd("features.pattern_seed", f.pattern_seed);
}

}  // namespace aerie::stereo
