#include "air/track/dcf/fhog.hpp"

#include <opencv2/core/hal/hal.hpp>
#include <opencv2/core/hal/intrin.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

// Row by row, with OpenCV's universal intrinsics (cv::v_float32: SSE2 4 lanes on the x86-64
// baseline) where the work is per pixel or per cell, and one scalar pass for the voting
// scatter. Every float operation is the scalar original's, in the same order (no fused
// multiply-add on the baseline), so the features are those of the scalar version up to the
// last bits of the arctangent (tests/air/track/fhog_reference.hpp, compared in test_dcf.cpp).
namespace aerie::track {
namespace {

constexpr int kSigned = 18, kUnsigned = 9;
constexpr float kTruncate = 0.2f;

// The same code over one float or a vector of them: `over(n, f)` calls f(Lanes, x) with x
// stepping by Lanes::n, vectors first, then single floats for the tail.
struct One {
  using V = float;
  static constexpr int n = 1;
  static V load(const float* p) { return *p; }
  static void store(float* p, V v) { *p = v; }
  static V all(float s) { return s; }
  static V min(V a, V b) { return std::min(a, b); }
  static V sqrt(V a) { return std::sqrt(a); }
};
#if CV_SIMD
struct Many {
  using V = cv::v_float32;
  static constexpr int n = cv::v_float32::nlanes;
  static V load(const float* p) { return cv::vx_load(p); }
  static void store(float* p, V v) { cv::v_store(p, v); }
  static V all(float s) { return cv::vx_setall_f32(s); }
  static V min(V a, V b) { return cv::v_min(a, b); }
  static V sqrt(V a) { return cv::v_sqrt(a); }
};
#endif

template <class F>
void over(int n, F&& f) {
  int x = 0;
#if CV_SIMD
  for (; x + Many::n <= n; x += Many::n) f(Many{}, x);
#endif
  for (; x < n; ++x) f(One{}, x);
}

// Gradient of row y at columns [0, n) with [-1 0 1] differences (replicated border): dx, dy
// and magnitude of the channel of largest magnitude (the first on ties), all exact integers
// before the square root.
void gradient_row(const cv::Mat& img, int y, int n, float* mag, float* dx, float* dy) {
  const int w = img.cols, cn = img.channels();
  const uchar* up = img.ptr<uchar>(std::max(y - 1, 0));
  const uchar* row = img.ptr<uchar>(y);
  const uchar* down = img.ptr<uchar>(std::min(y + 1, img.rows - 1));
  auto one = [&](int x) {
    const int l = cn * std::max(x - 1, 0), r = cn * std::min(x + 1, w - 1);
    int best = -1, gx = 0, gy = 0;
    for (int c = 0; c < cn; ++c) {
      const int ax = row[r + c] - row[l + c], ay = down[cn * x + c] - up[cn * x + c];
      if (ax * ax + ay * ay > best) {
        best = ax * ax + ay * ay;
        gx = ax;
        gy = ay;
      }
    }
    dx[x] = static_cast<float>(gx);
    dy[x] = static_cast<float>(gy);
    mag[x] = std::sqrt(static_cast<float>(best));
  };
  one(0);
  int x = 1;
#if CV_SIMD
  using namespace cv;
  constexpr int nb = v_uint8::nlanes, nf = v_float32::nlanes;
  // float(a - b) of nb bytes in four float vectors.
  auto diff = [](const v_uint8& a, const v_uint8& b, v_float32 out[4]) {
    v_uint16 a0, a1, b0, b1;
    v_expand(a, a0, a1);
    v_expand(b, b0, b1);
    v_int32 d[4];
    v_expand(v_reinterpret_as_s16(a0) - v_reinterpret_as_s16(b0), d[0], d[1]);
    v_expand(v_reinterpret_as_s16(a1) - v_reinterpret_as_s16(b1), d[2], d[3]);
    for (int q = 0; q < 4; ++q) out[q] = v_cvt_f32(d[q]);
  };
  for (; x + nb < w && x < n; x += nb) {
    v_float32 fx[3][4], fy[3][4];
    if (cn == 1) {
      diff(vx_load(row + x + 1), vx_load(row + x - 1), fx[0]);
      diff(vx_load(down + x), vx_load(up + x), fy[0]);
    } else {
      v_uint8 l[3], r[3], u[3], d[3];
      v_load_deinterleave(row + 3 * (x - 1), l[0], l[1], l[2]);
      v_load_deinterleave(row + 3 * (x + 1), r[0], r[1], r[2]);
      v_load_deinterleave(up + 3 * x, u[0], u[1], u[2]);
      v_load_deinterleave(down + 3 * x, d[0], d[1], d[2]);
      for (int c = 0; c < 3; ++c) {
        diff(r[c], l[c], fx[c]);
        diff(d[c], u[c], fy[c]);
      }
    }
    for (int q = 0; q < 4; ++q) {
      v_float32 best = fx[0][q] * fx[0][q] + fy[0][q] * fy[0][q], bx = fx[0][q], by = fy[0][q];
      for (int c = 1; c < cn; ++c) {
        const v_float32 m = fx[c][q] * fx[c][q] + fy[c][q] * fy[c][q];
        const v_float32 stronger = m > best;
        best = v_select(stronger, m, best);
        bx = v_select(stronger, fx[c][q], bx);
        by = v_select(stronger, fy[c][q], by);
      }
      v_store(dx + x + q * nf, bx);
      v_store(dy + x + q * nf, by);
      v_store(mag + x + q * nf, v_sqrt(best));
    }
  }
#endif
  for (; x < n; ++x) one(x);
}

// Each pixel's 8 votes: bilinear in the 2 x 2 nearest cell centres (wy0, wy1 of the row, wx0,
// wx1 of the column) times linear in the 2 nearest of the 18 signed orientation bins o0, o1,
// in the scalar version's product order; and where they go in the histogram planes.
struct Votes {
  std::vector<float> v[8];  // [j][i][bin]: (wy_j m) wx_i wo_bin
  std::vector<int> at0, at1;  // o0 * plane + column of the left cell, the same for o1
  explicit Votes(int n) : at0(n + 16), at1(n + 16) {
    for (auto& a : v) a.resize(n + 16);
  }
};

void votes_row(const float* mag, const float* ang, float wy0, float wy1, const float* wx0, const float* wx1,
               const int* col, int plane, int n, Votes& out) {
  const float bins_per_rad = kSigned / float(2 * CV_PI);
  int x = 0;
#if CV_SIMD
  using namespace cv;
  const v_int32 bins = vx_setall_s32(kSigned), zero = vx_setzero_s32(), one = vx_setall_s32(1);
  for (; x + v_float32::nlanes <= n; x += v_float32::nlanes) {
    const v_float32 o = vx_load(ang + x) * vx_setall_f32(bins_per_rad);
    v_int32 o0 = v_trunc(o);
    const v_float32 wo1 = o - v_cvt_f32(o0), wo0 = vx_setall_f32(1.f) - wo1;
    o0 = o0 - v_select(o0 >= bins, bins, zero);  // o0 %= 18 (o0 <= 18)
    v_int32 o1 = o0 + one;
    o1 = o1 - v_select(o1 >= bins, bins, zero);
    const v_int32 planes = vx_setall_s32(plane), c = vx_load(col + x);
    v_store(&out.at0[x], o0 * planes + c);
    v_store(&out.at1[x], o1 * planes + c);
    const v_float32 m = vx_load(mag + x), cy[2] = {vx_setall_f32(wy0) * m, vx_setall_f32(wy1) * m};
    const v_float32 cx[2] = {vx_load(wx0 + x), vx_load(wx1 + x)};
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        const v_float32 w = cy[j] * cx[i];
        v_store(&out.v[4 * j + 2 * i][x], w * wo0);
        v_store(&out.v[4 * j + 2 * i + 1][x], w * wo1);
      }
  }
#endif
  for (; x < n; ++x) {
    const float o = ang[x] * bins_per_rad;
    int o0 = static_cast<int>(o);
    const float wo1 = o - o0, wo0 = 1 - wo1;
    o0 %= kSigned;
    out.at0[x] = o0 * plane + col[x];
    out.at1[x] = (o0 + 1) % kSigned * plane + col[x];
    const float cy[2] = {wy0 * mag[x], wy1 * mag[x]}, cx[2] = {wx0[x], wx1[x]};
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        const float w = cy[j] * cx[i];
        out.v[4 * j + 2 * i][x] = w * wo0;
        out.v[4 * j + 2 * i + 1][x] = w * wo1;
      }
  }
}

}  // namespace

std::vector<cv::Mat> fhog(const cv::Mat& image, int cell) {
  if (image.empty()) throw std::invalid_argument("fhog: empty image");
  if (image.type() != CV_8UC1 && image.type() != CV_8UC3)
    throw std::invalid_argument("fhog: image must be 8-bit gray or BGR");
  if (cell < 1) throw std::invalid_argument("fhog: cell size must be >= 1");
  const int ny = image.rows / cell, nx = image.cols / cell;
  if (nx < 1 || ny < 1) throw std::invalid_argument("fhog: image smaller than one cell");
  const int n = nx * cell;

  // Orientation histograms, one plane per signed bin with a border of one cell all round
  // (the votes of the outer half-cells land there and are dropped).
  const int stride = nx + 2;
  const size_t plane = static_cast<size_t>(ny + 2) * stride;
  std::vector<float> hist(plane * kSigned, 0.f);
  const float inv_cell = 1.f / cell;
  std::vector<int> col(n);  // padded column of each pixel's left cell
  std::vector<float> wx0(n), wx1(n);
  for (int x = 0; x < n; ++x) {
    const float xc = (x + 0.5f) * inv_cell - 0.5f;
    const int x0 = static_cast<int>(std::floor(xc));
    wx1[x] = xc - x0;
    wx0[x] = 1 - wx1[x];
    col[x] = x0 + 1;
  }
  std::vector<float> mag(image.cols + 16), ang(image.cols + 16), dx(image.cols + 16), dy(image.cols + 16);
  Votes votes(n);
  for (int y = 0; y < ny * cell; ++y) {
    gradient_row(image, y, n, mag.data(), dx.data(), dy.data());
    cv::hal::fastAtan32f(dy.data(), dx.data(), ang.data(), n, false);  // as cv::cartToPolar
    const float yc = (y + 0.5f) * inv_cell - 0.5f;
    const int y0 = static_cast<int>(std::floor(yc));
    const float wy1 = yc - y0, wy0 = 1 - wy1;
    votes_row(mag.data(), ang.data(), wy0, wy1, wx0.data(), wx1.data(), col.data(), static_cast<int>(plane), n, votes);
    float* top = hist.data() + static_cast<size_t>(y0 + 1) * stride;
    const float* v[8];
    for (int k = 0; k < 8; ++k) v[k] = votes.v[k].data();
    for (int x = 0; x < n; ++x) {
      float* h0 = top + votes.at0[x];
      float* h1 = top + votes.at1[x];
      h0[0] += v[0][x];
      h1[0] += v[1][x];
      h0[1] += v[2][x];
      h1[1] += v[3][x];
      h0[stride] += v[4][x];
      h1[stride] += v[5][x];
      h0[stride + 1] += v[6][x];
      h1[stride + 1] += v[7][x];
    }
  }
  auto bin = [&](int o, int y) { return hist.data() + o * plane + static_cast<size_t>(y + 1) * stride + 1; };

  // Energy of each cell's contrast-insensitive histogram, for the block norms, with a
  // replicated border of one cell.
  std::vector<float> energy(plane, 0.f);
  for (int y = 0; y < ny; ++y) {
    float* e = energy.data() + static_cast<size_t>(y + 1) * stride + 1;
    for (int o = 0; o < kUnsigned; ++o)
      over(nx, [&](auto l, int x) {
        using L = decltype(l);
        const auto u = L::load(bin(o, y) + x) + L::load(bin(o + kUnsigned, y) + x);
        L::store(e + x, L::load(e + x) + u * u);
      });
    e[-1] = e[0];
    e[nx] = e[nx - 1];
  }
  std::copy_n(energy.begin() + stride, stride, energy.begin());
  std::copy_n(energy.begin() + static_cast<ptrdiff_t>(ny) * stride, stride,
              energy.begin() + static_cast<ptrdiff_t>(ny + 1) * stride);

  std::vector<cv::Mat> out(kFhogChannels);
  for (auto& m : out) m.create(ny, nx, CV_32F);
  std::vector<float> norm[4], texture[4];
  for (int b = 0; b < 4; ++b) {
    norm[b].resize(nx);
    texture[b].resize(nx);
  }
  for (int y = 0; y < ny; ++y) {
    // The four 2x2 blocks that contain each cell (replicated at the border).
    const float* e = energy.data() + static_cast<size_t>(y + 1) * stride + 1;
    int k = 0;
    for (int dy : {-1, 1})
      for (int dx : {-1, 1}) {
        float* nb = norm[k++].data();
        over(nx, [&](auto l, int x) {
          using L = decltype(l);
          const auto s = L::load(e + x) + L::load(e + dy * stride + x) + L::load(e + dx + x) +
                         L::load(e + dy * stride + dx + x);
          L::store(nb + x, L::all(1.f) / L::sqrt(s + L::all(1e-4f)));
        });
      }
    for (auto& t : texture) std::fill(t.begin(), t.end(), 0.f);
    const float *n0 = norm[0].data(), *n1 = norm[1].data(), *n2 = norm[2].data(), *n3 = norm[3].data();
    float *t0 = texture[0].data(), *t1 = texture[1].data(), *t2 = texture[2].data(), *t3 = texture[3].data();
    // Signed channels: each truncated at 0.2 under each of the four norms, summed; the texture
    // channels sum them over the orientations.
    for (int o = 0; o < kSigned; ++o) {
      float* dst = out[o].ptr<float>(y);
      over(nx, [&](auto l, int x) {
        using L = decltype(l);
        const auto h = L::load(bin(o, y) + x), cap = L::all(kTruncate);
        const auto v0 = L::min(h * L::load(n0 + x), cap), v1 = L::min(h * L::load(n1 + x), cap),
                   v2 = L::min(h * L::load(n2 + x), cap), v3 = L::min(h * L::load(n3 + x), cap);
        L::store(t0 + x, L::load(t0 + x) + v0);
        L::store(t1 + x, L::load(t1 + x) + v1);
        L::store(t2 + x, L::load(t2 + x) + v2);
        L::store(t3 + x, L::load(t3 + x) + v3);
        L::store(dst + x, L::all(0.5f) * (((L::all(0.f) + v0) + v1) + v2 + v3));
      });
    }
    for (int o = 0; o < kUnsigned; ++o) {
      float* dst = out[kSigned + o].ptr<float>(y);
      over(nx, [&](auto l, int x) {
        using L = decltype(l);
        const auto h = L::load(bin(o, y) + x) + L::load(bin(o + kUnsigned, y) + x), cap = L::all(kTruncate);
        const auto v0 = L::min(h * L::load(n0 + x), cap), v1 = L::min(h * L::load(n1 + x), cap),
                   v2 = L::min(h * L::load(n2 + x), cap), v3 = L::min(h * L::load(n3 + x), cap);
        L::store(dst + x, L::all(0.5f) * (((L::all(0.f) + v0) + v1) + v2 + v3));
      });
    }
    for (int b = 0; b < 4; ++b) {
      float* dst = out[kSigned + kUnsigned + b].ptr<float>(y);
      over(nx, [&](auto l, int x) {
        using L = decltype(l);
        L::store(dst + x, L::all(0.2357f) * L::load(texture[b].data() + x));
      });
    }
  }
  return out;
}

}  // namespace aerie::track
