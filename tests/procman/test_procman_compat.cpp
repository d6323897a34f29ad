// libbot2 compatibility: Aerie's bot_procman types against libbot2's own
// definitions (tests/procman/libbot2, compiled as package libbot2_ref). Same
// fingerprints, and each side decodes the other's bytes field for field, so a
// libbot2 sheriff drives Aerie's deputies and the other way round.
#include <bot_procman/discovery_t.hpp>
#include <bot_procman/info2_t.hpp>
#include <bot_procman/orders2_t.hpp>
#include <bot_procman/printf_t.hpp>
#include <gtest/gtest.h>
#include <libbot2_ref/discovery_t.hpp>
#include <libbot2_ref/info2_t.hpp>
#include <libbot2_ref/orders2_t.hpp>
#include <libbot2_ref/printf_t.hpp>

#include <vector>

namespace {

template <typename From, typename To>
To transcode(const From& m) {
  std::vector<uint8_t> buf(static_cast<size_t>(m.getEncodedSize()));
  EXPECT_EQ(m.encode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  To out;
  EXPECT_EQ(out.decode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()))
      << From::getTypeName() << " -> " << To::getTypeName();
  return out;
}

template <typename Cmd>
void fill_command(Cmd& c, int k) {
  c.exec_str = "aerie-capture --fps " + std::to_string(k);
  c.command_name = "capture" + std::to_string(k);
  c.group = "vision/stereo";
  c.auto_respawn = (k % 2) == 0;
  c.stop_signal = static_cast<int8_t>(15);
  c.stop_time_allowed = 2.5f;
  c.option_names = {"a", "b"};
  c.option_values = {"1", "two"};
  c.num_options = 2;
}

}  // namespace

TEST(ProcmanCompat, FingerprintsMatchLibbot2) {
  EXPECT_EQ(bot_procman::command2_t::getHash(), libbot2_ref::command2_t::getHash());
  EXPECT_EQ(bot_procman::sheriff_cmd2_t::getHash(), libbot2_ref::sheriff_cmd2_t::getHash());
  EXPECT_EQ(bot_procman::deputy_cmd2_t::getHash(), libbot2_ref::deputy_cmd2_t::getHash());
  EXPECT_EQ(bot_procman::info2_t::getHash(), libbot2_ref::info2_t::getHash());
  EXPECT_EQ(bot_procman::orders2_t::getHash(), libbot2_ref::orders2_t::getHash());
  EXPECT_EQ(bot_procman::printf_t::getHash(), libbot2_ref::printf_t::getHash());
  EXPECT_EQ(bot_procman::discovery_t::getHash(), libbot2_ref::discovery_t::getHash());
}

TEST(ProcmanCompat, OurInfoDecodesAsLibbot2s) {
  bot_procman::info2_t m;
  m.utime = 1234567890123;
  m.host = "air";
  m.cpu_load = 0.75f;
  m.phys_mem_total_bytes = 8LL << 30;
  m.phys_mem_free_bytes = 3LL << 30;
  m.swap_total_bytes = 1LL << 30;
  m.swap_free_bytes = 1LL << 29;
  for (int k = 0; k < 3; ++k) {
    bot_procman::deputy_cmd2_t d;
    fill_command(d.cmd, k);
    d.pid = 1000 + k;
    d.actual_runid = 7 + k;
    d.exit_code = 256 * k;
    d.cpu_usage = 0.125f * static_cast<float>(k);
    d.mem_vsize_bytes = (100LL + k) << 20;
    d.mem_rss_bytes = (10LL + k) << 20;
    d.sheriff_id = 40 + k;
    m.cmds.push_back(d);
  }
  m.ncmds = 3;
  m.option_names = {"x"};
  m.option_values = {"y"};
  m.num_options = 1;

  const auto r = transcode<bot_procman::info2_t, libbot2_ref::info2_t>(m);
  EXPECT_EQ(r.utime, m.utime);
  EXPECT_EQ(r.host, "air");
  EXPECT_EQ(r.cpu_load, 0.75f);
  EXPECT_EQ(r.phys_mem_total_bytes, m.phys_mem_total_bytes);
  EXPECT_EQ(r.phys_mem_free_bytes, m.phys_mem_free_bytes);
  EXPECT_EQ(r.swap_total_bytes, m.swap_total_bytes);
  EXPECT_EQ(r.swap_free_bytes, m.swap_free_bytes);
  ASSERT_EQ(r.ncmds, 3);
  for (int k = 0; k < 3; ++k) {
    const auto& a = m.cmds[static_cast<size_t>(k)];
    const auto& b = r.cmds[static_cast<size_t>(k)];
    EXPECT_EQ(b.cmd.exec_str, a.cmd.exec_str);
    EXPECT_EQ(b.cmd.command_name, a.cmd.command_name);
    EXPECT_EQ(b.cmd.group, a.cmd.group);
    EXPECT_EQ(b.cmd.auto_respawn, a.cmd.auto_respawn);
    EXPECT_EQ(b.cmd.stop_signal, 15);
    EXPECT_EQ(b.cmd.stop_time_allowed, 2.5f);
    EXPECT_EQ(b.cmd.option_values, a.cmd.option_values);
    EXPECT_EQ(b.pid, a.pid);
    EXPECT_EQ(b.actual_runid, a.actual_runid);
    EXPECT_EQ(b.exit_code, a.exit_code);
    EXPECT_EQ(b.cpu_usage, a.cpu_usage);
    EXPECT_EQ(b.mem_vsize_bytes, a.mem_vsize_bytes);
    EXPECT_EQ(b.mem_rss_bytes, a.mem_rss_bytes);
    EXPECT_EQ(b.sheriff_id, a.sheriff_id);
  }
  EXPECT_EQ(r.option_names, m.option_names);
  EXPECT_EQ(r.option_values, m.option_values);
}

TEST(ProcmanCompat, Libbot2OrdersDecodeAsOurs) {
  libbot2_ref::orders2_t m;
  m.utime = 987654321;
  m.host = "ground";
  m.sheriff_name = "bot-procman-sheriff";
  for (int k = 0; k < 2; ++k) {
    libbot2_ref::sheriff_cmd2_t c;
    fill_command(c.cmd, k);
    c.desired_runid = 3 + k;
    c.force_quit = static_cast<int8_t>(k);
    c.sheriff_id = 9 + k;
    m.cmds.push_back(c);
  }
  m.ncmds = 2;
  m.num_options = 0;

  const auto r = transcode<libbot2_ref::orders2_t, bot_procman::orders2_t>(m);
  EXPECT_EQ(r.utime, m.utime);
  EXPECT_EQ(r.host, "ground");
  EXPECT_EQ(r.sheriff_name, m.sheriff_name);
  ASSERT_EQ(r.ncmds, 2);
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(r.cmds[k].cmd.exec_str, m.cmds[k].cmd.exec_str);
    EXPECT_EQ(r.cmds[k].cmd.command_name, m.cmds[k].cmd.command_name);
    EXPECT_EQ(r.cmds[k].cmd.auto_respawn, m.cmds[k].cmd.auto_respawn);
    EXPECT_EQ(r.cmds[k].desired_runid, m.cmds[k].desired_runid);
    EXPECT_EQ(r.cmds[k].force_quit, m.cmds[k].force_quit);
    EXPECT_EQ(r.cmds[k].sheriff_id, m.cmds[k].sheriff_id);
  }
}

TEST(ProcmanCompat, PrintfAndDiscoveryBothWays) {
  bot_procman::printf_t p;
  p.utime = 5;
  p.deputy_name = "air";
  p.sheriff_id = 12;
  p.text = "hello\n";
  const auto lp = transcode<bot_procman::printf_t, libbot2_ref::printf_t>(p);
  EXPECT_EQ(lp.utime, 5);
  EXPECT_EQ(lp.deputy_name, "air");
  EXPECT_EQ(lp.sheriff_id, 12);
  EXPECT_EQ(lp.text, "hello\n");

  libbot2_ref::discovery_t d;
  d.utime = 77;
  d.host = "sheriff";
  d.nonce = -42;
  const auto od = transcode<libbot2_ref::discovery_t, bot_procman::discovery_t>(d);
  EXPECT_EQ(od.utime, 77);
  EXPECT_EQ(od.host, "sheriff");
  EXPECT_EQ(od.nonce, -42);
}

TEST(ProcmanCompat, DecodingTheWrongTypeFails) {
  bot_procman::printf_t p;
  p.utime = 1;
  p.deputy_name = "a";
  p.sheriff_id = 0;
  p.text = "";
  std::vector<uint8_t> buf(static_cast<size_t>(p.getEncodedSize()));
  p.encode(buf.data(), 0, static_cast<int>(buf.size()));
  libbot2_ref::discovery_t d;
  EXPECT_LT(d.decode(buf.data(), 0, static_cast<int>(buf.size())), 0);
}
