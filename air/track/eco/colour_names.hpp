#pragma once
// Colour names (van de Weijer et al., "Learning color names for real-world applications",
// TIP 2009; as tracking features: Danelljan et al., CVPR 2014): per pixel, the probability of
// each of the 11 basic colour terms of English (Berlin & Kay 1969).
//
// The learned mapping of van de Weijer et al. (the "w2c" table, trained on Google images) is
// not in any Debian package and nothing is downloaded at build time. Aerie models each term by
// its focal colour instead: p(n | c) is proportional to exp(-|Lab(c) - Lab(n)|^2 / (2 sigma^2)),
// with Lab(n) the CIELAB value of the term's focal colour (docs/track.md). Like w2c the mapping
// is a 32 x 32 x 32 lookup table over RGB (8 levels per entry).
#include <array>
#include <opencv2/core.hpp>
#include <vector>

namespace aerie::track {

constexpr int kColourNames = 11;  // black, blue, brown, grey, green, orange, pink, purple, red, white, yellow

// The focal colour of each term, sRGB (B, G, R as OpenCV stores it).
const std::array<cv::Vec3b, kColourNames>& focal_colours();

// p(n | c) for an 8-bit BGR colour: the lookup table's entry of its 8-level bin (sums to 1).
const float* colour_name_probabilities(const cv::Vec3b& bgr);

// p(n | c) computed directly for an arbitrary BGR colour (the table's reference).
std::array<float, kColourNames> colour_name_model(const cv::Vec3f& bgr);

// Per cell of cell x cell pixels, the mean of the 11 probabilities over its pixels: 11
// CV_32F maps of floor(rows / cell) x floor(cols / cell) (the FHOG grid). bgr: CV_8UC3.
std::vector<cv::Mat> colour_names(const cv::Mat& bgr, int cell);

}  // namespace aerie::track
