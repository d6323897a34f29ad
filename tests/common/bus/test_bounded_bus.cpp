// What ../shared/reliability/check.sh checks against the running nodes, in process: a node-style
// subscriber on memq:// counts each crafted payload as malformed, names the field in its last
// error, and still receives the next valid message of the channel.
#include <gtest/gtest.h>

#include <aerie/ce_progress_t.hpp>
#include <aerie/flc_params_t.hpp>
#include <aerie/gt_pose_t.hpp>
#include <aerie/image_t.hpp>
#include <aerie/map_cmd_t.hpp>
#include <aerie/map_query_t.hpp>
#include <aerie/spherical_depth_t.hpp>
#include <aerie/stereo_image_t.hpp>
#include <aerie/track_cmd_t.hpp>
#include <aerie/track_t.hpp>
#include <bot_procman/info2_t.hpp>
#include <bot_procman/orders2_t.hpp>

#include "common/bus/bus.hpp"
#include "tests/common/bus/reliability_data.hpp"

namespace {

template <typename Msg>
void expect_survives(const std::string& channel, const std::string& file) {
  SCOPED_TRACE(file + " on " + channel);
  const auto crafted = aerie::test::read_bytes(aerie::test::reliability_data_dir() / file);
  aerie::bus::Bus bus("memq://");
  int delivered = 0;
  auto& sub = bus.subscribe<Msg>(channel, [&](const Msg&, const aerie::bus::ReceiveInfo&) { ++delivered; });
  bus.publish_raw(channel, crafted.data(), static_cast<unsigned>(crafted.size()));
  bus.publish(channel, Msg{});
  while (bus.handle(0) > 0) {
  }
  EXPECT_EQ(sub.counters().received, 2);
  EXPECT_EQ(sub.counters().malformed, 1);
  EXPECT_EQ(delivered, 1);
  const auto& repro = *std::find_if(aerie::test::kWireReproducers.begin(), aerie::test::kWireReproducers.end(),
                                    [&](const auto& r) { return file == r.file; });
  EXPECT_NE(sub.last_error().find(repro.reason), std::string::npos) << sub.last_error();
}

}  // namespace

TEST(BoundedBus, CraftedPayloadsAreCountedAndTheNextMessageArrives) {
  expect_survives<aerie::track_cmd_t>("TRACK_CMD", "track_cmd_strlen_INT_MIN.bin");
  expect_survives<aerie::image_t>("CAM_LEFT", "image_metadata_key_strlen_INT_MIN.bin");
  expect_survives<aerie::image_t>("CAM_LEFT", "image_size_INT_MAX_2GiB_alloc.bin");
  expect_survives<aerie::stereo_image_t>("CAM_STEREO", "stereo_left_metadata_strlen_INT_MIN.bin");
  expect_survives<aerie::gt_pose_t>("GT_POSE", "gt_pose_frame_strlen_INT_MIN.bin");
  expect_survives<aerie::flc_params_t>("FLC_PARAMS", "flc_params_id_strlen_INT_MIN.bin");
  expect_survives<aerie::map_query_t>("MAP_QUERY", "map_query_reply_strlen_INT_MIN.bin");
  expect_survives<aerie::map_cmd_t>("MAP_CMD", "map_cmd_path_strlen_INT_MIN.bin");
  expect_survives<aerie::track_t>("TRACK", "track_npoints_0x20000001_oob_read.bin");
  expect_survives<aerie::spherical_depth_t>("VO_DEPTH", "vo_depth_nbins_0x20000001_oob_read.bin");
  expect_survives<aerie::spherical_depth_t>("VO_DEPTH", "vo_depth_nrange_0x40000001_oob_read.bin");
  expect_survives<aerie::ce_progress_t>("CE_PROGRESS", "ce_progress_nelite_0x10000001_oob_read.bin");
  expect_survives<bot_procman::orders2_t>("PMD_ORDERS2", "orders2_host_strlen_INT_MIN.bin");
  expect_survives<bot_procman::orders2_t>("PMD_ORDERS2", "orders2_ncmds_16777215_cpu_amplification.bin");
  expect_survives<bot_procman::info2_t>("PMD_INFO2", "info2_host_strlen_INT_MIN.bin");
  expect_survives<bot_procman::info2_t>("PMD_INFO2", "info2_ncmds_16777215_cpu_amplification.bin");
}
