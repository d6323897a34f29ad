// A stand-in air node for the split-deployment test: publishes small camera images
// (utime = wall clock at "exposure") at a fixed rate and a status heartbeat with its
// hop times, until SIGINT/SIGTERM. Counts what it hears on an up-link channel.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <thread>

#include "common/bus/bus.hpp"
#include "common/bus/node.hpp"
#include "common/bus/status.hpp"
#include "common/image/image_message.hpp"
#include "common/util/cli.hpp"
#include "common/util/time.hpp"

int main(int argc, char** argv) {
  using namespace aerie;
  CLI::App app{"split_talker: test publisher for the split deployment"};
  util::CommonOptions common;
  double rate_hz = 30;
  std::string channel = "CAM_LEFT", uplink = "TRACK_CMD";
  app.add_option("--rate", rate_hz, "images per second");
  app.add_option("--channel", channel, "image channel");
  util::add_common_options(app, common, false);
  CLI11_PARSE(app, argc, argv);
  util::init_logging("split_talker", common.log_level);
  bus::Bus bus(common.lcm_url);
  bus::StatusReporter status(bus, "talker");
  bus.subscribe_raw(uplink, [&](const uint8_t*, size_t, const bus::ReceiveInfo&) { status.count("uplink_messages"); });
  cv::Mat img(120, 160, CV_8UC1);
  int64_t seq = 0;
  auto next = std::chrono::steady_clock::now();
  bus::install_stop_handlers();
  spdlog::info("talking on {} at {} Hz", channel, rate_hz);
  while (!bus::stop_requested()) {
    img.setTo(cv::Scalar(20));
    cv::circle(img, {static_cast<int>(20 + seq % 120), 60}, 15, cv::Scalar(230), -1);
    const int64_t exposure = util::wall_utime();
    const auto msg = image::to_message(img, exposure, seq++);
    bus.publish(channel, msg);
    status.count("published");
    status.mark_hop(exposure, exposure, util::wall_utime());
    status.tick();
    next += std::chrono::microseconds(static_cast<int64_t>(1e6 / rate_hz));
    while (std::chrono::steady_clock::now() < next && !bus::stop_requested())
      bus.handle(std::max<int>(1, static_cast<int>(std::chrono::duration_cast<std::chrono::milliseconds>(
                                                       next - std::chrono::steady_clock::now()).count())));
  }
  spdlog::info("published {} images", seq);
  status.publish_now();
  return 0;
}
