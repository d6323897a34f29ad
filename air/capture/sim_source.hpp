#pragma once
// The simulator (common/sim) as a frame source: a stereo rig flying a scripted
// trajectory through the textured room, with exact ground truth per frame: the
// left camera pose (GT_POSE) and the helipad's image box (GT_TRACK).
#include <memory>

#include "air/capture/frame_source.hpp"
#include "air/capture/source_factory.hpp"
#include "common/sim/simulation.hpp"

namespace aerie::capture {

class SimSource final : public FrameSource {
 public:
  // width/height: rendered size (0 = the rig's default 376x240); fps: frame rate.
  // Throws std::invalid_argument for an unknown trajectory name.
  SimSource(const SimSourceOptions& options, int width, int height, bool color, double fps);

  std::string describe() const override;
  bool stereo() const override { return true; }
  cv::Size size() const override;
  std::optional<camera::RectifiedStereo> rectified() const override;
  int64_t frame_count() const override { return sim_->frame_count(); }
  void seek(int64_t index) override { sim_->seek(static_cast<int>(index)); }
  bool next(Frame& frame) override;

 private:
  SimSourceOptions opt_;
  std::unique_ptr<sim::StereoSimulation> sim_;
};

}  // namespace aerie::capture
