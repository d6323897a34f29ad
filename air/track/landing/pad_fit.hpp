#pragma once
// The pad pose's building blocks (pad_pose.cpp), shared with the user's pad designs
// (pad_design.cpp): not part of the library's interface.
#include <opencv2/core.hpp>

#include <array>
#include <optional>

#include "air/track/landing/pad_pose.hpp"

namespace aerie::track::detail {

using Quad = std::array<cv::Point2f, 4>;

// Sub-pixel sides of a dark quad on a brighter ground (pad_pose.cpp, refine_sides): robust lines
// through the strongest dark-to-bright steps outwards along the middle 70 % of each side.
bool refine_dark_quad(const cv::Mat& gray, Quad& q, double reach_fraction);
void make_clockwise(Quad& q);
// The quad's corners clear of the image border by options.border_margin_px.
bool in_image(const Quad& q, const cv::Mat& gray, const PadOptions& options);
// IPPE + Levenberg-Marquardt pose of the rectangle (-hx, hy), (hx, hy), (hx, -hy), (-hx, -hy)
// seen at q; nullopt over options.max_reprojection_px. Its yaw is left modulo pi.
std::optional<PadObservation> rectangle_pose(const Quad& q, double hx, double hy, const camera::CameraModel& camera,
                                             const PadOptions& options);
// The quad warped to a side x side top view, q[0] at its top left, q[1] at its top right (CV_32F).
cv::Mat top_view(const cv::Mat& gray, const Quad& q, int side);
double correlation(const cv::Mat& a, const cv::Mat& b);  // normalised, same-size images
cv::Rect window_in(const cv::Rect2d& search, const cv::Mat& gray);
// Throws std::invalid_argument naming `who` on an empty frame or unusable intrinsics.
void check_frame(const char* who, const cv::Mat& gray, const camera::CameraModel& camera);

}  // namespace aerie::track::detail
