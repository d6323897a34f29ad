#pragma once
// SIMD kernels of the semi-global matcher (Highway, dispatched at run time to the best
// of SSSE3/SSE4/AVX2/AVX-512 here and NEON/SVE on the ARM air computer). Plain data in,
// plain data out; sgm.cpp owns the buffers and the layout described here.
//
// Disparity windows: pixel (x, y) considers the disparities [o(x,y), o(x,y) + W) with W a
// multiple of kWindowStep; the cost volume and the aggregated volume hold W values per pixel.
#include <cstddef>
#include <cstdint>

namespace aerie::stereo::kernels {

inline constexpr int kWindowStep = 16;  // W and the SIMD chunk size are multiples of this
inline constexpr uint16_t kUnknown = 0x3FFF;  // L of a disparity outside the previous window

struct CensusArgs {
  const uint8_t* image;  // image(0,0) of a frame padded by the census radius on every side
  ptrdiff_t image_step;
  int width, height;
  const int16_t* dx;  // neighbour offsets, nbits of them (bit b of plane p = neighbour 8p + b)
  const int16_t* dy;
  int nbits;
  uint8_t* out;  // row y, plane p, pixel x at out[(y * nplanes + p) * out_step + x]
  ptrdiff_t out_step;
};
// Census transform (Zabih & Woodfill 1994): bit set where the neighbour is darker than the centre.
void census(const CensusArgs& a);

struct CostRowArgs {
  const uint8_t* left;   // census of row y, plane 0, pixel 0 (planes plane_step apart)
  const uint8_t* right;  // same layout but mirrored (pixel x at width - 1 - x), readable up to
                         // index width + max disparity
  ptrdiff_t plane_step;
  int nplanes, nbits, width, window;
  const int16_t* offsets;  // o(x) of the row
  uint8_t* cost;           // width * window: Hamming distance, nbits where x - d < 0
};
void cost_row(const CostRowArgs& a);

struct PassArgs {
  const uint8_t* cost;     // [y][x][window]
  const int16_t* offsets;  // [y][x]
  uint16_t* sum;           // [y][x][window]: written by the forward pass, added by the backward pass
  int width, height, window;
  bool forward;
  int paths;               // 4 (along rows and columns) or 8 (and the diagonals)
  uint16_t p1, p2;
  uint16_t* scratch;        // pass_scratch_size() values
};
size_t pass_scratch_size(int width, int window, int paths);
// Path costs L_r(p, d) = C(p, d) + min(L_r(p-r, d), L_r(p-r, d +- 1) + P1, min_k L_r(p-r, k) + P2)
// - min_k L_r(p-r, k) (Hirschmueller 2008) over a restricted, per-pixel disparity window.
void aggregate_pass(const PassArgs& a);

struct SelectRowArgs {
  const uint16_t* sum;     // aggregated costs of the row, [x][window]
  const int16_t* offsets;
  int width, window;
  int uniqueness_percent;
  float* disparity;        // out: winner-takes-all disparity (subpixel if asked), -1 invalid
  bool subpixel;
  // Right-image winners for the left-right check: best cost and disparity of right pixel xr,
  // valid from index -(max disparity + window) (caller pads) and initialised to 0xFFFF / -1.
  uint16_t* right_cost;
  int16_t* right_disparity;
  uint16_t max_sum;        // bound of an aggregated cost (paths * (census bits + P2))
};
void select_row(const SelectRowArgs& a);

// Name of the instruction set the kernels dispatch to on this machine (e.g. "AVX2").
const char* target_name();

}  // namespace aerie::stereo::kernels
