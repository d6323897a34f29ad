#pragma once
// Felzenszwalb's HOG ("FHOG", Felzenszwalb et al., PAMI 2010, sec. 6.2; the variant of
// Dollar's toolbox used by KCF, DSST and Staple): per cell of cell x cell pixels, 18
// contrast-sensitive + 9 contrast-insensitive orientation channels, each normalised by the
// four 2x2-cell blocks around the cell and truncated at 0.2, plus 4 texture channels.
#include <opencv2/core.hpp>
#include <vector>

namespace aerie::track {

constexpr int kFhogChannels = 31;

// image: 8-bit gray or BGR (the gradient of a colour pixel is that of its strongest channel).
// Returns kFhogChannels CV_32F maps of floor(rows / cell) x floor(cols / cell) cells.
// Throws std::invalid_argument for an empty image, another type, a cell < 1 or an image under
// one cell.
std::vector<cv::Mat> fhog(const cv::Mat& image, int cell);

}  // namespace aerie::track
