#pragma once
// The hostile payloads of the reliability issue (copied from ../shared/reliability/repro into
// tests/data/reliability) that bounded decoding must refuse, with the part of the reason that
// names the type, the field and the value.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <vector>

namespace aerie::test {

struct Repro {
  const char* file;
  const char* reason;
};

inline const std::vector<Repro> kWireReproducers = {
    {"track_cmd_strlen_INT_MIN.bin", "aerie.track_cmd_t.tracker: string length -2147483648 is negative"},
    {"image_metadata_key_strlen_INT_MIN.bin", "aerie.image_metadata_t.key: string length -2147483648 is negative"},
    {"stereo_left_metadata_strlen_INT_MIN.bin", "(in aerie.stereo_image_t.left.metadata[0])"},
    {"gt_pose_frame_strlen_INT_MIN.bin", "aerie.gt_pose_t.frame_id: string length -2147483648"},
    {"flc_params_id_strlen_INT_MIN.bin", "aerie.flc_params_t.controller_id: string length -2147483648"},
    {"map_query_reply_strlen_INT_MIN.bin", "aerie.map_query_t.reply_channel: string length -2147483648"},
    {"map_cmd_path_strlen_INT_MIN.bin", "aerie.map_cmd_t.path: string length -2147483648"},
    {"orders2_host_strlen_INT_MIN.bin", "bot_procman.orders2_t.host: string length -2147483648"},
    {"info2_host_strlen_INT_MIN.bin", "bot_procman.info2_t.host: string length -2147483648"},
    {"track_npoints_0x20000001_oob_read.bin", "aerie.track_level_t.u: count npoints = 536870913"},
    {"vo_depth_nbins_0x20000001_oob_read.bin", "aerie.spherical_depth_t.bin: count nbins = 536870913"},
    {"vo_depth_nrange_0x40000001_oob_read.bin", "aerie.spherical_depth_t.range: count nrange = 1073741825"},
    {"ce_progress_nelite_0x10000001_oob_read.bin", "aerie.ce_progress_t.elite_costs: count nelite = 268435457"},
    {"image_size_INT_MAX_2GiB_alloc.bin", "aerie.image_t.data: count size = 2147483647 exceeds the cap 67108864"},
    {"orders2_ncmds_16777215_cpu_amplification.bin", "bot_procman.orders2_t.cmds: count ncmds = 16777215 exceeds"},
    {"info2_ncmds_16777215_cpu_amplification.bin", "bot_procman.info2_t.cmds: count ncmds = 16777215 exceeds"},
};

inline std::filesystem::path reliability_data_dir() { return AERIE_SOURCE_DIR "/tests/data/reliability"; }

inline std::vector<uint8_t> read_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open " + p.string());
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace aerie::test
