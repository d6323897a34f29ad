#pragma once
// A box file (OTB layout: "x,y,w,h" per frame, NaN for no box, as aerie-log export writes a
// track) scored against a ground truth of the same layout, frame i against frame i, with the
// one-pass metrics of metrics.hpp (success AUC, precision at 20 px, mean centre error).
#include <filesystem>
#include <string>

#include "air/track/eval/metrics.hpp"

namespace aerie::track::eval {

struct BoxFileScore {
  Score score;
  int rows = 0;     // rows of each file (one per frame)
  int missing = 0;  // frames with a ground-truth box but no predicted one (NaN rows: scored as failures)
};

// Throws std::runtime_error naming the files when their row counts differ (a skipped frame
// dropped from the box file would shift every box after it) or a file is malformed.
BoxFileScore score_box_file(const std::filesystem::path& boxes, const std::filesystem::path& groundtruth);

// The score as a JSON object (figures, counts, and both curves with their thresholds).
std::string to_json(const BoxFileScore& s);

}  // namespace aerie::track::eval
