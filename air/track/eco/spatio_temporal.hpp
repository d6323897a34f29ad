#pragma once
// AutoTrack's automatic spatio-temporal regularisation (Li, Fu et al., "AutoTrack: Towards
// High-Performance Visual Tracking for UAV with Automatic Spatio-Temporal Regularization",
// CVPR 2020), on ECO's joint filter (joint_filter.hpp). The response map's change between two
// frames, both aligned on their peaks, is
//   * local (Pi, per cell): where the target's appearance was unreliable (a part occluded, lit
//     differently), the filter is regularised more: w~ = w + delta log(1 + Pi) on the target's
//     cells (their eq. 4, w SRDCF's regulariser);
//   * global (||Pi||): the temporal prior's weight theta = theta0 / (1 + log(1 + nu ||Pi||))
//     (their eq. 5's reference): a changing response lets the filter adapt faster; above a
//     limit the frame is taken as a failure and nothing is learned from it.
// One deviation, stated: AutoTrack divides the change by the previous response cell by cell,
// which is unbounded where that response is near 0 (most of the map); here both responses are
// scaled to peak 1 and Pi is their difference, and ||Pi|| its root mean square over the
// target's cells, so that delta, nu and the limit do not depend on the window's size.
#include <opencv2/core.hpp>

namespace aerie::track {

struct ResponseVariation {
  cv::Mat local;       // Pi per cell (CV_32F), the grid of the responses
  double global = 0;   // root mean square of Pi over the target's cells
};

// Pi between two responses (CV_32F, the same grid, each aligned so that its peak is at the
// grid's centre ((w - 1) / 2, (h - 1) / 2) and scaled to peak 1); the target's cells are the box
// of target_cells around that centre.
ResponseVariation response_variation(const cv::Mat& previous, const cv::Mat& current, cv::Size2d target_cells);

// theta0 / (1 + log(1 + nu global)).
double temporal_weight(double theta0, double nu, double global);

// The spatial regulariser w~^2 from SRDCF's w^2 (spatial_regulariser's, CV_32F): w + delta
// log(1 + Pi) on the target's cells, w elsewhere, squared.
cv::Mat varied_regulariser(const cv::Mat& w2, const ResponseVariation& variation, cv::Size2d target_cells, double delta);

}  // namespace aerie::track
