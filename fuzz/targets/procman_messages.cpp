// procman's orders and reports over memq:// (fuzz_support.hpp: kProcmanChannels; record format
// there): PMD_ORDERS2 (bot_procman.orders2_t) to a deputy, PMD_INFO2 (bot_procman.info2_t) to a
// sheriff that has loaded config/demo.pmd, each through the bounded decoder of a subscription.
// The deputy's orders handling runs in full (new, renamed, changed and removed commands, run
// ids, stale orders) except that nothing is started: every command is marked force_quit before
// the deputy sees it, and its command line is split as start() would (procman/command_line.hpp).
// The sheriff merges the report (adoption, run ids, restarts), derives every command's status,
// writes its table and its orders, which go to the deputy too.
#include "common/util/config.hpp"
#include "fuzz/fuzz_support.hpp"
#include "procman/command_line.hpp"
#include "procman/deputy.hpp"
#include "procman/pmd_config.hpp"
#include "procman/sheriff.hpp"

namespace {

using namespace aerie;

const procman::PmdConfig& demo() {
  static const procman::PmdConfig c = procman::load_pmd(fuzz::source_path("config/demo.pmd"));
  return c;
}

// One deputy for the process: its destructor reaps and scans /proc, too slow for every input.
// Empty orders reset it between inputs (every command absent from the orders is forgotten).
procman::Deputy& deputy() {
  static procman::Deputy d = [] {
    procman::DeputyOptions options;
    options.name = "air";
    return procman::Deputy(options, {});
  }();
  return d;
}

void obey(bot_procman::orders2_t orders, int64_t now_utime) {
  orders.host = deputy().name();
  for (auto& c : orders.cmds) {
    c.force_quit = 1;
    fuzz::refusal_ok([&] { procman::split_command_line(c.cmd.exec_str); });
  }
  deputy().handle_orders(orders, now_utime);
  deputy().report(now_utime);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::quiet();
  constexpr int64_t kStartUtime = 1'700'000'000'000'000;
  int64_t now_ms = 0;
  bot_procman::orders2_t reset{};
  reset.utime = kStartUtime;
  obey(reset, kStartUtime);

  procman::Sheriff sheriff("fuzz", false, 3.0, 1);
  sheriff.load(demo());
  bus::Bus bus("memq://");
  const auto& ch = fuzz::kProcmanChannels;
  bus.subscribe<bot_procman::orders2_t>(
      ch[0], [&](const bot_procman::orders2_t& m, const bus::ReceiveInfo&) { obey(m, kStartUtime + now_ms * 1000); });
  bus.subscribe<bot_procman::info2_t>(ch[1], [&](const bot_procman::info2_t& m, const bus::ReceiveInfo&) {
    sheriff.on_info(m, now_ms);
    for (const auto& c : sheriff.commands()) sheriff.status(c, now_ms);
    sheriff.table(now_ms);
    for (const auto& o : sheriff.orders(kStartUtime + now_ms * 1000)) obey(o, kStartUtime + now_ms * 1000);
  });
  fuzz::publish_records(bus, ch, data, size, [&] { now_ms += 500; });
  return 0;
}
