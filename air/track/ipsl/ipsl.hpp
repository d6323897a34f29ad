#pragma once
// IPSL: incremental PCA subspace learning + particle filter (Ross et al. 2008; thesis 3.1.4,
// eqs. 3.2-3.10), and the hierarchical IPSL that runs one particle filter and one subspace per
// level of an image pyramid (eqs. 3.11-3.16).
#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "air/track/ipsl/appearance.hpp"
#include "air/track/tracker.hpp"
#include "common/util/config.hpp"

namespace aerie::track {

// Diagonal of the random-walk covariance Psi (eq. 3.7): standard deviations of one step.
// x, y in pixels of the level the filter runs at; scale as a log step (s' = s * exp(n));
// theta in radians.
struct MotionSigma {
  double x = 5, y = 5, scale = 0.02, theta = 0.02;
};

// Appearance model of one IPSL (one pyramid level): observation patch, subspace update
// (eqs. 3.2-3.4) and likelihood (eqs. 3.8-3.10).
struct AppearanceParams {
  int patch_size = 32;         // observations are warped to patch_size x patch_size
  int max_basis = 16;          // k eigenvectors kept
  int block_size = 5;          // N_B observations per incremental update
  double forgetting = 0.95;    // eta in (0, 1] (eqs. 3.3, 3.4)
  bool normalize_patches = true;  // zero-mean, unit-variance patches (illumination invariance)
  // Every update block also holds the first observation: the subspace keeps the initial
  // appearance (against drift; the similarity-normalised patch of a rigid target at the right
  // pose always looks like it).
  bool anchor = true;
  ObservationParams likelihood;
  // An observation enters the next update block only when its mean robust residual
  // (ObservationScore::residual) is below this (guards the subspace against occluders).
  double update_max_residual = 0.5;
};

// Loss detection and recovery. The target is declared lost when the MAP particle's mean robust
// residual (ObservationScore::residual) exceeds `lost_residual`, or exceeds both `lost_ratio`
// times its typical value (an exponential average, rate `typical_rate`, over the tracked
// frames) and `ratio_floor` (so that tiny residuals of an easy target do not count); while
// lost the subspace is not updated and the search range grows by `growth` per frame, up to
// `max_factor` times sigma, until the target matches the frozen subspace again. After
// `max_lost_frames` lost frames in a row the appearance is taken to have changed for good: the
// tracker accepts its estimate and learns again.
struct RecoveryParams {
  double lost_residual = 0.45;
  double lost_ratio = 2.5;
  double ratio_floor = 0.15;
  double typical_rate = 0.05;
  double growth = 1.5;
  double max_factor = 6;
  int max_lost_frames = 10;
};

// The loss bookkeeping of both trackers (RecoveryParams).
class LossMonitor {
 public:
  explicit LossMonitor(const RecoveryParams& p = {}) : params_(p) {}
  void reset() { *this = LossMonitor(params_); }
  // Classifies a frame by its MAP residual: sets state.lost / state.redetected and the search
  // factor; returns whether the appearance may learn from this frame (tracked and residual
  // <= update_max_residual).
  bool observe(double residual, double update_max_residual, TrackState& state);
  double search_factor() const { return search_factor_; }
  double typical_residual() const { return typical_; }

 private:
  RecoveryParams params_;
  double typical_ = -1;  // < 0: no tracked frame yet
  double search_factor_ = 1;
  int lost_frames_ = 0;
};

struct IpslParams {
  int particles = 300;         // N_P
  MotionSigma sigma;           // Psi of eq. 3.7, full-resolution pixels
  AppearanceParams appearance;
  RecoveryParams recovery;
};

struct HierarchicalIpslParams {
  // minSize of eq. 3.11, px: N_PL = floor(log2(min(T_W, T_H) / min_size)), so the target is at
  // least 2 min_size pixels wide at the coarsest level.
  double min_size = 2.5;
  int max_levels = 3;          // cap on N_PL
  int particles = 65;          // N_P at the coarsest level; finer levels get the survivors
  double reject_ratio = 0.8;   // alpha of eq. 3.14: level p rejects floor(alpha^p * N_P^p)
  // Psi: x, y = translation step at the coarsest level (that level's pixels); theta = rotation
  // step at the level where rotation enters (1, or 0 with two levels); scale = log-scale step
  // at level 0, the only level that estimates scale.
  MotionSigma sigma{4, 4, 0.02, 0.03};
  // Bounds of the translation search range set by the critical particle (eq. 3.15) at the
  // finer levels, in each level's pixels; the rotation range is bounded to
  // [min_theta_factor, 1] * sigma.theta.
  double min_range = 0.3;
  double max_range = 1.0;
  double min_theta_factor = 0.2;
  // Scale and rotation adaptation with few fine particles: two of the particles a level draws
  // step only the parameter no coarser level estimated (rotation where it enters, scale at
  // level 0) by -/+ sigma from the propagated estimate; the others take a random step in all
  // the level's parameters.
  bool probes = true;
  // N_B at the coarsest level; finer levels follow eq. 3.16 (at least 1).
  int coarsest_block_size = 8;
  AppearanceParams appearance;  // patch_size is the level-0 side; level p uses patch_size / 2^p
  RecoveryParams recovery;
};

// Upper bounds of the counts that set the work and memory of a frame, checked by validate()
// before anything is allocated: a TRACK_CMD may override any key (docs/track_ipsl.md).
inline constexpr int kMaxParticles = 5000;        // particles (N_P; ipsl-mr: at the coarsest level)
inline constexpr int kMaxBasis = 256;             // max_basis (k)
inline constexpr int kMaxBlockSize = 256;         // block_size, coarsest_block_size (N_B)
inline constexpr int kMaxLevels = 8;              // ipsl-mr max_levels (N_PL)
inline constexpr int kMaxLostFrames = 100000;     // max_lost_frames
// particles x patch_size^2: the floats of one frame's observation matrix (eq. 3.1), 64 MiB.
inline constexpr int64_t kMaxObservationFloats = int64_t{1} << 24;

// Read the parameters from a config section (keys documented in docs/track_ipsl.md);
// absent keys keep their defaults; invalid values throw std::invalid_argument naming the key.
IpslParams ipsl_params_from_config(const util::Config& section);
HierarchicalIpslParams hierarchical_ipsl_params_from_config(const util::Config& section);
// Throw std::invalid_argument naming the field when a parameter is out of range or not finite.
void validate(const IpslParams& p);
void validate(const HierarchicalIpslParams& p);

// A particle: the similarity (x, y, s, theta) at some level's resolution.
struct Particle {
  Similarity pose;
  double log_prior = 0;       // log p(X_k | X_{k-1}): random walk (eq. 3.7) from the last estimate
  ObservationScore score;     // log p(O_k | X_k) and its terms (eqs. 3.8-3.10)
  double log_posterior() const { return score.log_likelihood + log_prior; }  // eq. 3.6
};

// Single-resolution IPSL (Ross et al. 2008): condensation over the similarity with a random
// walk (eq. 3.7), likelihood from the subspace (eqs. 3.8-3.10), MAP estimate (eq. 3.6).
class IpslTracker : public Tracker {
 public:
  IpslTracker(const IpslParams& params, uint64_t seed);
  std::string name() const override { return "ipsl"; }
  void init(const cv::Mat& frame, const cv::Rect2d& box) override;
  TrackState update(const cv::Mat& frame) override;

  const IncrementalPca& subspace() const;
  const IpslParams& params() const { return params_; }

 private:
  IpslParams params_;
  std::mt19937_64 rng_;
  std::unique_ptr<AppearanceModel> model_;
  std::vector<Particle> particles_;  // posterior of the last frame (condensation)
  std::vector<cv::Mat> pyramid_;     // octaves of the frame, sampled without aliasing
  TrackState state_;
  cv::Size frame_size_;
  LossMonitor loss_;
  bool initialised_ = false;
};

// Hierarchical IPSL (thesis 3.1.4, "Hierarchy Tracking Strategy"): N_PL levels (eq. 3.11),
// level-specific motion models (coarsest: translation, middle: + rotation, finest:
// similarity), propagation between levels (3.12) and frames (3.13), per-level rejection
// (3.14), critical-particle search ranges (3.15) and per-level block sizes (3.16).
class HierarchicalIpslTracker : public Tracker {
 public:
  HierarchicalIpslTracker(const HierarchicalIpslParams& params, uint64_t seed);
  std::string name() const override { return "ipsl-mr"; }
  void init(const cv::Mat& frame, const cv::Rect2d& box) override;
  TrackState update(const cv::Mat& frame) override;

  int num_levels() const { return static_cast<int>(levels_.size()); }
  // N_B^p of level p (eq. 3.16); level 0 is the finest.
  int block_size(int level) const;
  const IncrementalPca& subspace(int level) const;
  const HierarchicalIpslParams& params() const { return params_; }

 private:
  HierarchicalIpslParams params_;
  std::mt19937_64 rng_;
  std::vector<std::unique_ptr<AppearanceModel>> levels_;  // IPSL^p, p = 0 full resolution
  std::vector<cv::Mat> pyramid_;
  TrackState state_;
  cv::Size frame_size_;
  LossMonitor loss_;
  bool initialised_ = false;
};

}  // namespace aerie::track
