// aerie-fiducial-board: writes the fiducial board of a track config (its "fiducial" section) as
// a printable PNG, square and centred on the board origin (config/pads/*.png).
#include <CLI/CLI.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cstdio>

#include "air/track/fiducial/fiducial.hpp"

int main(int argc, char** argv) {
  CLI::App app{"aerie-fiducial-board: renders the fiducial board of a track config (section fiducial) as a PNG"};
  std::string config, kind = "apriltag", family, out;
  int pixels = 1024;
  double side = 0;
  app.add_option("--config", config, "track config with a fiducial section (config/track_landing.yaml)")->required();
  app.add_option("--kind", kind, "apriltag or aruco (default apriltag)")->check(CLI::IsMember({"apriltag", "aruco"}));
  app.add_option("--family", family, "overrides fiducial.family (tag36h11, tagStandard41h12, DICT_4X4_50, ...)");
  app.add_option("--pixels", pixels, "side of the image in pixels (default 1024)");
  app.add_option("--side", side, "side of the image in metres (default: the tags and their quiet zone)");
  app.add_option("--out", out, "PNG to write")->required();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  try {
    const aerie::util::Config cfg = aerie::util::Config::load(config);
    YAML::Node section = YAML::Clone(cfg.section("fiducial").node());
    if (!family.empty()) section["family"] = family;
    YAML::Emitter e;
    e << section;
    const auto board = aerie::track::fiducial_board(aerie::util::Config::parse(e.c_str(), config + ":fiducial"),
                                                    aerie::track::fiducial_kind_from_string(kind));
    const aerie::track::BoardImage image = aerie::track::render_board(board, pixels, side);
    if (!cv::imwrite(out, image.image)) throw std::runtime_error(out + ": cannot write the PNG");
    std::printf("%s: %s %s, %zu tags, %d x %d px, %.4f m wide (the pad's size)\n", out.c_str(), kind.c_str(),
                board.family.c_str(), board.tags.size(), pixels, pixels, image.side_m);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "aerie-fiducial-board: %s\n", e.what());
    return 1;
  }
  return 0;
}
