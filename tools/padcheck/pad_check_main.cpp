// aerie-pad-check: finds a round pad design in real frames at known altitudes and prints the
// per-frame table and the coefficient of variation of diameter x altitude (docs/track.md).
#include <CLI/CLI.hpp>

#include <cstdio>
#include <fstream>
#include <iostream>

#include "tools/padcheck/pad_check.hpp"

int main(int argc, char** argv) {
  CLI::App app{"aerie-pad-check: the pad's drawing found in real frames; diameter (px) x altitude per frame and its "
               "coefficient of variation (no intrinsics needed)"};
  std::string pad, mask_path, images, altitude_csv, out_csv;
  double size_m = 1.0;
  int held_out_every = 2;
  aerie::track::RoundOptions opt;
  app.add_option("--pad", pad, "the pad's drawing (PNG; an SVG rasterised: rsvg-convert -b white -w 1024 pad.svg -o pad.png)")
      ->required();
  app.add_option("--size-m", size_m, "the drawing's width in metres (default 1; the CV does not depend on it)");
  app.add_option("--mask", mask_path, "mask of the frames' size, black where the view is blocked (the drone's legs)");
  app.add_option("--images", images, "folder of the frames")->required();
  app.add_option("--altitude", altitude_csv, "CSV: a header line, then image,altitude_m per frame")->required();
  app.add_option("--out", out_csv, "write the per-frame table as CSV");
  app.add_option("--held-out-every", held_out_every,
                 "every N-th frame is held out of the tuning part (default 2; 0: none)")->check(CLI::NonNegativeNumber);
  app.add_option("--threshold-c", opt.threshold_c, "adaptive threshold offset, grey levels (default 12)");
  app.add_option("--min-score", opt.min_score, "least correlation of the ring's inside with the drawing (default 0.5)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  try {
    using namespace aerie::padcheck;
    const aerie::track::PadDesign design = aerie::track::load_pad_design(pad, size_m);
    if (design.outline != aerie::track::PadDesign::Outline::Round)
      throw std::invalid_argument("pad image '" + pad + "': aerie-pad-check needs a round design (a dark ring)");
    const auto frames = check_frames(design, read_mask(mask_path), images, read_altitudes(altitude_csv), opt, held_out_every);
    print_table(std::cout, frames);
    if (!out_csv.empty()) {
      std::ofstream out(out_csv);
      write_csv(out, frames);
      if (!out) throw std::runtime_error(out_csv + ": write failed");
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "aerie-pad-check: %s\n", e.what());
    return 1;
  }
  return 0;
}
