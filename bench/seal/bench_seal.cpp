// Micro-benchmarks of the sealed door (common/seal): seal and open one datagram at 64 B, 1 kB
// and 64 kB (64,000 B) payloads, and a 752x480 stereo pair (2 x 360,960 bytes of GRAY8) split into
// datagrams of at most 60 kB, as the link's halves would send it. CPU ns per datagram (time/
// items) and MB/s (bytes_per_second) of payload, on one core; and the operator's signature on a
// command, signed and verified.
//   aerie-bench-seal [--benchmark_filter=...] [--benchmark_format=json]
#include <benchmark/benchmark.h>

#include <algorithm>
#include <memory>
#include <vector>

#include "bench/benchmark_main.hpp"
#include "common/seal/operator.hpp"
#include "common/seal/seal.hpp"

namespace {

using namespace aerie::seal;

constexpr size_t kStereoPair = 2 * 752 * 480;  // two GRAY8 images
constexpr size_t kChunk = 60'000;               // datagram payload when a message is split

const SecretKey& key() {
  static const SecretKey k = SecretKey::generate();
  return k;
}

std::vector<uint8_t> payload(size_t n) {
  std::vector<uint8_t> p(n);
  for (size_t i = 0; i < n; ++i) p[i] = static_cast<uint8_t>(i * 31 + 7);
  return p;
}

// CPU seconds per datagram (shown as e.g. 600n), next to items_per_second.
void per_datagram(benchmark::State& state, int64_t datagrams) {
  state.counters["cpu_per_datagram"] =
      benchmark::Counter(static_cast<double>(datagrams), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

size_t arg_size(const benchmark::State& state) { return static_cast<size_t>(state.range(0)); }

void BM_Seal(benchmark::State& state) {
  const auto p = payload(arg_size(state));
  Sealer sealer(key(), Direction::AirToGround, 1, 0, 0.0);
  std::vector<uint8_t> out;
  for (auto _ : state) {
    sealer.seal_into("CAM_STEREO", p, 0.0, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations());
  per_datagram(state, state.iterations());
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(p.size()));
}
BENCHMARK(BM_Seal)->Arg(64)->Arg(1024)->Arg(64000)->ArgName("payload");

void BM_Open(benchmark::State& state) {
  const auto p = payload(arg_size(state));
  Sealer sealer(key(), Direction::AirToGround, 1, 0, 0.0);
  // Datagrams sealed beforehand, opened in order (each once: a fresh opener per lap of the pool).
  constexpr size_t kPool = 256;
  std::vector<std::vector<uint8_t>> pool;
  for (size_t i = 0; i < kPool; ++i) pool.push_back(sealer.seal("CAM_STEREO", p, 0.0));
  auto opener = std::make_unique<Opener>(key(), OpenerConfig{.direction = Direction::AirToGround});
  Opened out;
  size_t i = 0;
  for (auto _ : state) {
    if (i == kPool) {
      state.PauseTiming();
      opener = std::make_unique<Opener>(key(), OpenerConfig{.direction = Direction::AirToGround});
      i = 0;
      state.ResumeTiming();
    }
    if (!opener->open_into(pool[i++], 0.0, out)) state.SkipWithError(out.why.c_str());
    benchmark::DoNotOptimize(out.payload.data());
  }
  state.SetItemsProcessed(state.iterations());
  per_datagram(state, state.iterations());
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(p.size()));
}
BENCHMARK(BM_Open)->Arg(64)->Arg(1024)->Arg(64000)->ArgName("payload");

// One stereo pair: ceil(721,920 / 60,000) = 13 datagrams sealed, then opened.
void BM_StereoPairSealOpen(benchmark::State& state) {
  const auto frame = payload(kStereoPair);
  Sealer sealer(key(), Direction::AirToGround, 1, 0, 0.0);
  std::vector<std::vector<uint8_t>> datagrams((kStereoPair + kChunk - 1) / kChunk);
  Opened out;
  int64_t count = 0;
  auto opener = std::make_unique<Opener>(key(), OpenerConfig{.direction = Direction::AirToGround});
  for (auto _ : state) {
    for (size_t k = 0; k < datagrams.size(); ++k) {
      const size_t off = k * kChunk, n = std::min(kChunk, kStereoPair - off);
      sealer.seal_into("CAM_STEREO", std::span(frame).subspan(off, n), 0.0, datagrams[k]);
    }
    for (const auto& d : datagrams)
      if (!opener->open_into(d, 0.0, out)) state.SkipWithError(out.why.c_str());
    count += static_cast<int64_t>(datagrams.size());
  }
  state.counters["datagrams_per_pair"] = static_cast<double>(datagrams.size());
  state.SetItemsProcessed(count);
  per_datagram(state, count);
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(kStereoPair));
}
BENCHMARK(BM_StereoPairSealOpen);

// The operator's signature on one 100-byte command (common/seal/operator.hpp): the ground
// half's signing and the air half's check (Ed25519), per command.
void BM_CommandSign(benchmark::State& state) {
  const auto p = payload(100);
  const Session session = new_session();
  CommandSigner signer(OperatorKey::generate());
  for (auto _ : state) benchmark::DoNotOptimize(signer.sign(session, "PILOT_CMD", p));
  state.SetItemsProcessed(state.iterations());
  per_datagram(state, state.iterations());
}
BENCHMARK(BM_CommandSign);

void BM_CommandVerify(benchmark::State& state) {
  const auto p = payload(100);
  const Session session = new_session();
  CommandSigner signer(OperatorKey::generate());
  CommandVerifier verifier({signer.public_key()}, session);
  // Distinct counters, as a stream of commands has: each verifies once.
  std::vector<std::vector<uint8_t>> envelopes;
  for (int i = 0; i < 4096; ++i) envelopes.push_back(signer.sign(session, "PILOT_CMD", p));
  std::span<const uint8_t> body;
  std::string why;
  size_t i = 0;
  for (auto _ : state) {
    if (i == envelopes.size()) {  // a new session: the counters are fresh again
      state.PauseTiming();
      verifier = CommandVerifier({signer.public_key()}, new_session());
      for (auto& e : envelopes) e = signer.sign(verifier.session(), "PILOT_CMD", p);
      i = 0;
      state.ResumeTiming();
    }
    if (verifier.verify("PILOT_CMD", envelopes[i++], body, why) != CommandRefusal::None) state.SkipWithError(why.c_str());
  }
  state.SetItemsProcessed(state.iterations());
  per_datagram(state, state.iterations());
}
BENCHMARK(BM_CommandVerify);

}  // namespace

int main(int argc, char** argv) {
  return aerie::bench::benchmark_main(argc, argv, "aerie-bench-seal",
                                      "micro-benchmarks of the sealed door: seal and open per datagram and MB/s, a "
                                      "stereo pair, the operator's signature on a command");
}
