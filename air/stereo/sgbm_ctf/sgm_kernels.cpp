// SIMD kernels of the semi-global matcher, written once against Highway and compiled
// for every target Highway can dispatch to (foreach_target re-includes this file).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "air/stereo/sgbm_ctf/sgm_kernels.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>

#include "air/stereo/sgbm_ctf/sgm_kernels.hpp"

HWY_BEFORE_NAMESPACE();
namespace aerie::stereo::kernels {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// Margin of kUnknown values around each pixel's window in the path buffers: a previous
// pixel whose window starts up to kPad - 1 disparities away is read with one unaligned load.
constexpr int kPad = kWindowStep;

void Census(const CensusArgs& a) {
  const hn::ScalableTag<uint8_t> d;
  const int n = static_cast<int>(hn::Lanes(d));
  const int nplanes = (a.nbits + 7) / 8;
  for (int y = 0; y < a.height; ++y) {
    const uint8_t* row = a.image + y * a.image_step;
    // Whole vectors; the last one overlaps its predecessor rather than leaving a scalar tail.
    const int vector_end = a.width >= n ? a.width : 0;
    for (int x0 = 0; x0 < vector_end; x0 += n) {
      const int x = std::min(x0, a.width - n);
      const auto centre = hn::LoadU(d, row + x);
      for (int p = 0; p < nplanes; ++p) {
        auto acc = hn::Zero(d);
        for (int b = 0; b < 8 && 8 * p + b < a.nbits; ++b) {
          const int j = 8 * p + b;
          const auto nb = hn::LoadU(d, row + a.dy[j] * a.image_step + a.dx[j] + x);
          acc = hn::Or(acc, hn::IfThenElseZero(hn::Lt(nb, centre), hn::Set(d, static_cast<uint8_t>(1u << b))));
        }
        hn::StoreU(acc, d, a.out + (y * nplanes + p) * a.out_step + x);
      }
    }
    for (int x = vector_end; x < a.width; ++x) {  // images narrower than a vector
      for (int p = 0; p < nplanes; ++p) {
        uint8_t acc = 0;
        for (int b = 0; b < 8 && 8 * p + b < a.nbits; ++b) {
          const int j = 8 * p + b;
          if (row[a.dy[j] * a.image_step + a.dx[j] + x] < row[x]) acc |= static_cast<uint8_t>(1u << b);
        }
        a.out[(y * nplanes + p) * a.out_step + x] = acc;
      }
    }
  }
}

void CostRow(const CostRowArgs& a) {
  const hn::CappedTag<uint8_t, kWindowStep> d;
  const int n = static_cast<int>(hn::Lanes(d));
  const auto worst = hn::Set(d, static_cast<uint8_t>(a.nbits));
  const auto lane = hn::Iota(d, 0);
  for (int x = 0; x < a.width; ++x) {
    const int o = a.offsets[x];
    uint8_t* out = a.cost + static_cast<ptrdiff_t>(x) * a.window;
    for (int k0 = 0; k0 < a.window; k0 += n) {
      // The right census is mirrored: right pixel x - d sits at width - 1 - x + d, so the
      // disparities o + k0 ... o + k0 + n - 1 are one contiguous load.
      const int first = a.width - 1 - x + o + k0;
      auto v = hn::Zero(d);
      for (int p = 0; p < a.nplanes; ++p) {
        const auto l = hn::Set(d, a.left[p * a.plane_step + x]);
        const auto r = hn::LoadU(d, a.right + p * a.plane_step + first);
        v = hn::Add(v, hn::PopulationCount(hn::Xor(l, r)));
      }
      const int last_inside = x - o - k0;  // lanes above it match outside the right image
      if (last_inside < 0)
        v = worst;
      else if (last_inside < n - 1)
        v = hn::IfThenElse(hn::Gt(lane, hn::Set(d, static_cast<uint8_t>(last_inside))), worst, v);
      hn::StoreU(v, d, out + k0);
    }
  }
}

// Smallest lane of an unsigned 16-bit vector: halves are folded down to 128 bits, where
// MinOfLanes is one instruction on SSE4 (phminposuw) and NEON (uminv).
template <class D, class V>
HWY_INLINE uint16_t MinLane(D d, V v) {
#if HWY_TARGET != HWY_SCALAR
  if constexpr (hn::MaxLanes(D()) * sizeof(uint16_t) > 16) {
    const hn::Half<D> dh;
    return MinLane(dh, hn::Min(hn::LowerHalf(dh, v), hn::UpperHalf(dh, v)));
  }
#endif
  return hn::GetLane(hn::MinOfLanes(d, v));
}

struct PassLayout {
  int stride;     // values per pixel block in a path row buffer
  size_t rowlen;  // values per path row buffer
};
PassLayout Layout(int width, int window) {
  const int stride = window + kPad;
  return {stride, static_cast<size_t>(kPad) + static_cast<size_t>(width) * stride};
}

// Path directions (ax, ay): the previous pixel on path k is (x - s ax, y - s ay) with
// s = +1 in the forward sweep and -1 in the backward one. Path 0 runs along the row.
constexpr int kDirX[4] = {1, 1, 0, -1};
constexpr int kDirY[4] = {0, 1, 1, 1};
constexpr int kDirX4[2] = {1, 0};
constexpr int kDirY4[2] = {0, 1};

template <int kDirs, bool kOneChunk>
void Pass(const PassArgs& a) {
  const hn::CappedTag<uint16_t, kWindowStep> d;
  const hn::Rebind<uint8_t, decltype(d)> d8;
  const int n = static_cast<int>(hn::Lanes(d));
  const int W = a.window, width = a.width;
  const PassLayout lay = Layout(width, W);
  const int* dir_x = kDirs == 4 ? kDirX : kDirX4;
  const int* dir_y = kDirs == 4 ? kDirY : kDirY4;

  // Scratch: per direction two path row buffers (previous, current) and their minima,
  // then a zero block (path start) and an all-unknown block (previous window too far).
  uint16_t* s = a.scratch;
  uint16_t* L[2][kDirs];
  uint16_t* M[2][kDirs];
  for (int k = 0; k < kDirs; ++k) {
    for (int b = 0; b < 2; ++b) {
      L[b][k] = s;
      std::fill(s, s + lay.rowlen, kUnknown);
      s += lay.rowlen;
      M[b][k] = s;
      s += width;
    }
  }
  uint16_t* zero = s + 1;
  std::fill(s, s + W + 2, uint16_t{0});
  s += W + 2;
  uint16_t* unknown = s + 1;
  std::fill(s, s + W + 2, kUnknown);

  const int sgn = a.forward ? 1 : -1;
  const auto vp1 = hn::Set(d, a.p1);
  int cur = 1, prv = 0;
  for (int yi = 0; yi < a.height; ++yi) {
    const int y = a.forward ? yi : a.height - 1 - yi;
    // Per direction: the previous pixel's row (offsets, path buffer, minima) or none.
    const int16_t* prow_off[kDirs];
    const uint16_t* prow_L[kDirs];
    const uint16_t* prow_M[kDirs];
    uint16_t* out_L[kDirs];
    for (int k = 0; k < kDirs; ++k) {
      const int py = y - sgn * dir_y[k];
      const int b = py == y ? cur : prv;
      prow_off[k] = py >= 0 && py < a.height ? a.offsets + static_cast<ptrdiff_t>(py) * width : nullptr;
      prow_L[k] = L[b][k] + kPad;
      prow_M[k] = M[b][k];
      out_L[k] = L[cur][k] + kPad;
    }
    const int16_t* orow = a.offsets + static_cast<ptrdiff_t>(y) * width;
    const uint8_t* crow = a.cost + static_cast<ptrdiff_t>(y) * width * W;
    uint16_t* srow = a.sum + static_cast<ptrdiff_t>(y) * width * W;
    uint16_t row_min = 0;  // path 0 keeps its minimum in a register (sequential dependency)
    for (int xi = 0; xi < width; ++xi) {
      const int x = a.forward ? xi : width - 1 - xi;
      const int o = orow[x];
      const uint8_t* c = crow + static_cast<ptrdiff_t>(x) * W;
      uint16_t* S = srow + static_cast<ptrdiff_t>(x) * W;
      auto acc = a.forward ? hn::Zero(d) : hn::LoadU(d, S);
      for (int k = 0; k < kDirs; ++k) {
        const int px = x - sgn * dir_x[k];
        const uint16_t* prev = zero;
        uint16_t minp = 0;
        if (prow_off[k] && static_cast<unsigned>(px) < static_cast<unsigned>(width)) {
          const int delta = o - prow_off[k][px];
          if (delta >= kPad || delta <= -kPad) {
            prev = unknown;  // no disparity in common: L = C + P2
          } else {
            prev = prow_L[k] + static_cast<ptrdiff_t>(px) * lay.stride + delta;
            minp = k == 0 ? row_min : prow_M[k][px];
          }
        }
        const auto vminp = hn::Set(d, minp);
        const auto vjump = hn::Set(d, static_cast<uint16_t>(minp + a.p2));
        uint16_t* out = out_L[k] + static_cast<ptrdiff_t>(x) * lay.stride;
        auto vmin = hn::Set(d, kUnknown);
        for (int k0 = 0; k0 < (kOneChunk ? 1 : W); k0 += n) {
          const auto same = hn::LoadU(d, prev + k0);
          const auto below = hn::LoadU(d, prev + k0 - 1);
          const auto above = hn::LoadU(d, prev + k0 + 1);
          auto t = hn::Min(same, hn::SaturatedAdd(hn::Min(below, above), vp1));
          t = hn::Min(t, vjump);
          const auto cost = hn::PromoteTo(d, hn::LoadU(d8, c + k0));
          const auto l = hn::Sub(hn::Add(cost, t), vminp);
          hn::StoreU(l, d, out + k0);
          vmin = hn::Min(vmin, l);
          if (kOneChunk) {
            acc = hn::Add(acc, l);
          } else if (k == 0 && a.forward) {
            hn::StoreU(l, d, S + k0);
          } else {
            hn::StoreU(hn::Add(hn::LoadU(d, S + k0), l), d, S + k0);
          }
        }
        const uint16_t m = MinLane(d, vmin);
        if (k == 0)
          row_min = m;
        else
          M[cur][k][x] = m;
      }
      if (kOneChunk) hn::StoreU(acc, d, S);
    }
    std::swap(cur, prv);
  }
}

void AggregatePass(const PassArgs& a) {
  const hn::CappedTag<uint16_t, kWindowStep> d;
  const bool one_chunk = static_cast<int>(hn::Lanes(d)) == a.window;  // the usual fine-level case
  if (a.paths == 8)
    one_chunk ? Pass<4, true>(a) : Pass<4, false>(a);
  else
    one_chunk ? Pass<2, true>(a) : Pass<2, false>(a);
}

void SelectRow(const SelectRowArgs& a) {
  const hn::CappedTag<uint16_t, kWindowStep> d;
  const hn::RebindToSigned<decltype(d)> di;
  const int n = static_cast<int>(hn::Lanes(d));
  const int W = a.window;
  const auto vmax = hn::Set(d, uint16_t{0xFFFF});
  const auto two = hn::Set(di, int16_t{2});
  // One chunk whose costs fit in 12 bits (the usual fine level): cost << 4 | lane packs the
  // winner's cost and index into one value, found by a single minimum.
  const bool packed = W == n && n == 16 && a.max_sum < 4096;
  const auto lane = hn::Iota(d, 0);
  for (int x = 0; x < a.width; ++x) {
    const int o = a.offsets[x];
    const uint16_t* s = a.sum + static_cast<ptrdiff_t>(x) * W;
    uint16_t best_cost;
    int best = 0;
    if (packed) {
      const uint16_t m = MinLane(d, hn::Or(hn::ShiftLeft<4>(hn::LoadU(d, s)), lane));
      best_cost = static_cast<uint16_t>(m >> 4);
      best = m & 15;
    } else {
      auto vmin = vmax;
      for (int k0 = 0; k0 < W; k0 += n) vmin = hn::Min(vmin, hn::LoadU(d, s + k0));
      best_cost = MinLane(d, vmin);
      for (int k0 = 0; k0 < W; k0 += n) {
        const intptr_t i = hn::FindFirstTrue(d, hn::Eq(hn::LoadU(d, s + k0), hn::Set(d, best_cost)));
        if (i >= 0) {
          best = k0 + static_cast<int>(i);
          break;
        }
      }
    }
    // Right-image winners: right pixel x - (o + k) takes the lowest cost over all left pixels.
    for (int k0 = 0; k0 < W; k0 += n) {
      const int first = x - o - k0 - (n - 1);
      const auto cost = hn::Reverse(d, hn::LoadU(d, s + k0));
      const auto disp = hn::Reverse(di, hn::Iota(di, static_cast<int16_t>(o + k0)));
      const auto held = hn::LoadU(d, a.right_cost + first);
      const auto better = hn::Lt(cost, held);
      hn::StoreU(hn::IfThenElse(better, cost, held), d, a.right_cost + first);
      const auto held_disp = hn::LoadU(di, a.right_disparity + first);
      hn::StoreU(hn::IfThenElse(hn::RebindMask(di, better), disp, held_disp), di, a.right_disparity + first);
    }
    float& out = a.disparity[x];
    if (o + best > x) {  // the match would lie left of the right image
      out = -1.f;
      continue;
    }
    if (a.uniqueness_percent > 0) {
      // Another disparity (not a neighbour of the winner) within uniqueness% of the best cost.
      auto second = vmax;
      const auto vbest = hn::Set(di, static_cast<int16_t>(best));
      for (int k0 = 0; k0 < W; k0 += n) {
        const auto near = hn::Lt(hn::Abs(hn::Sub(hn::Iota(di, static_cast<int16_t>(k0)), vbest)), two);
        second = hn::Min(second, hn::IfThenElse(hn::RebindMask(d, near), vmax, hn::LoadU(d, s + k0)));
      }
      const int sc = MinLane(d, second);
      if (sc * (100 - a.uniqueness_percent) < best_cost * 100) {
        out = -1.f;
        continue;
      }
    }
    float disp = static_cast<float>(o + best);
    if (a.subpixel && best > 0 && best < W - 1) {
      const int denom = s[best - 1] + s[best + 1] - 2 * s[best];
      if (denom > 0) disp += static_cast<float>(s[best - 1] - s[best + 1]) / (2.f * static_cast<float>(denom));
    }
    out = disp;
  }
}

// The target this copy was compiled for: dispatched like the kernels, it names the one they take.
int64_t CompiledTarget() { return HWY_TARGET; }

}  // namespace HWY_NAMESPACE
}  // namespace aerie::stereo::kernels
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace aerie::stereo::kernels {

HWY_EXPORT(Census);
HWY_EXPORT(CostRow);
HWY_EXPORT(AggregatePass);
HWY_EXPORT(SelectRow);
HWY_EXPORT(CompiledTarget);

void census(const CensusArgs& a) { HWY_DYNAMIC_DISPATCH(Census)(a); }
void cost_row(const CostRowArgs& a) { HWY_DYNAMIC_DISPATCH(CostRow)(a); }
void aggregate_pass(const PassArgs& a) { HWY_DYNAMIC_DISPATCH(AggregatePass)(a); }
void select_row(const SelectRowArgs& a) { HWY_DYNAMIC_DISPATCH(SelectRow)(a); }

size_t pass_scratch_size(int width, int window, int paths) {
  const int ndirs = paths / 2;
  const size_t rowlen = static_cast<size_t>(kWindowStep) + static_cast<size_t>(width) * (window + kWindowStep);
  return static_cast<size_t>(ndirs) * 2 * (rowlen + width) + 2 * (window + 2);
}

const char* target_name() { return hwy::TargetName(HWY_DYNAMIC_DISPATCH(CompiledTarget)()); }

}  // namespace aerie::stereo::kernels
#endif  // HWY_ONCE
