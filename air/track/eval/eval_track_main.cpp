// aerie-eval-track BOXES GROUNDTRUTH: a tracker's box file scored against a ground truth, both
// in the OTB layout (one "x,y,w,h" row per frame, NaN for none), with the benchmark's own
// one-pass metrics (metrics.hpp): success AUC, precision at 20 px, mean centre location error.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <fstream>
#include <iostream>

#include "air/track/eval/box_file_score.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Score a tracker's box file against a ground truth (OTB x,y,w,h rows): success AUC, P@20, CLE",
               "aerie-eval-track"};
  std::string boxes, groundtruth, json;
  app.add_option("BOXES", boxes, "Box file, one x,y,w,h row per frame (NaN: no box), e.g. aerie-log export's TRACK.txt")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("GROUNDTRUTH", groundtruth, "Ground truth of the same frames (e.g. the sequence's groundtruth.txt)")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--json", json, "Also write the figures and both curves as JSON to this file");
  app.footer("Row i of BOXES is scored against row i of GROUNDTRUTH; frames whose ground truth is NaN or empty are "
             "left out, a NaN box on a frame with ground truth scores IoU 0 and the ground truth's diagonal as "
             "centre error. AUC is the mean of the success curve at IoU > 0, 0.05, ..., 1, so boxes equal to the "
             "ground truth give 20/21 = 0.9524. Exit status: 0 scored, 1 unreadable or mismatched files, 2 usage.");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);  // prints the help or the error
    return rc == 0 ? 0 : 2;
  }
  try {
    const auto s = aerie::track::eval::score_box_file(boxes, groundtruth);
    std::printf("frames scored      %d of %d rows (rows with a ground-truth box)\n", s.score.frames, s.rows);
    std::printf("frames without box %d (scored as failures)\n", s.missing);
    std::printf("success AUC        %.4f\n", s.score.auc);
    std::printf("precision @ 20 px  %.4f\n", s.score.precision20);
    std::printf("mean CLE           %.2f px\n", s.score.mean_centre_error);
    if (!json.empty()) {
      std::ofstream out(json);
      out << to_json(s) << "\n";
      if (!out) throw std::runtime_error(json + ": cannot write");
    }
  } catch (const std::exception& e) {
    std::cerr << "aerie-eval-track: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
