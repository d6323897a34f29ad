#include "air/track/ipsl/ipsl.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "air/track/pyramid/pyramid.hpp"

namespace aerie::track {

// ---------------------------------------------------------------------------------------------
// Parameters

namespace {

void require(bool ok, const std::string& what, const std::string& field, double value) {
  if (!ok) throw std::invalid_argument(what + ": " + field + " = " + std::to_string(value) + " is out of range");
}

// A count in [lo, hi] (the documented range, docs/track_ipsl.md).
void require_in(int value, int lo, int hi, const std::string& what, const std::string& field) {
  if (value < lo || value > hi)
    throw std::invalid_argument(what + ": " + field + " = " + std::to_string(value) + " is outside [" +
                                std::to_string(lo) + ", " + std::to_string(hi) + "]");
}

void validate_common(const std::string& what, const MotionSigma& s, const AppearanceParams& a,
                     const RecoveryParams& r) {
  for (auto [name, v] : {std::pair{"sigma.x", s.x}, {"sigma.y", s.y}, {"sigma.scale", s.scale},
                         {"sigma.theta", s.theta}})
    require(std::isfinite(v) && v >= 0, what, name, v);
  require(a.patch_size >= 4 && a.patch_size <= 256, what, "patch_size", a.patch_size);
  require_in(a.max_basis, 1, kMaxBasis, what, "max_basis");
  require_in(a.block_size, 1, kMaxBlockSize, what, "block_size");
  require(std::isfinite(a.forgetting) && a.forgetting > 0 && a.forgetting <= 1, what, "forgetting", a.forgetting);
  const auto& l = a.likelihood;
  require(std::isfinite(l.robust_scale) && l.robust_scale > 0, what, "robust_scale", l.robust_scale);
  require(std::isfinite(l.to_temperature) && l.to_temperature > 0, what, "to_temperature", l.to_temperature);
  require(std::isfinite(l.within_weight) && l.within_weight >= 0, what, "within_weight", l.within_weight);
  require(std::isfinite(l.within_epsilon) && l.within_epsilon > 0, what, "within_epsilon", l.within_epsilon);
  require(std::isfinite(a.update_max_residual) && a.update_max_residual >= 0, what, "update_max_residual",
          a.update_max_residual);
  require(std::isfinite(r.lost_residual) && r.lost_residual >= 0, what, "lost_residual", r.lost_residual);
  require(std::isfinite(r.lost_ratio) && r.lost_ratio >= 1, what, "lost_ratio", r.lost_ratio);
  require(std::isfinite(r.ratio_floor) && r.ratio_floor >= 0, what, "ratio_floor", r.ratio_floor);
  require(std::isfinite(r.typical_rate) && r.typical_rate > 0 && r.typical_rate <= 1, what, "typical_rate",
          r.typical_rate);
  require(std::isfinite(r.growth) && r.growth >= 1, what, "recovery_growth", r.growth);
  require_in(r.max_lost_frames, 0, kMaxLostFrames, what, "max_lost_frames");
  require(std::isfinite(r.max_factor) && r.max_factor >= 1, what, "recovery_max_factor", r.max_factor);
}

void read_common(const util::Config& c, MotionSigma& s, AppearanceParams& a, RecoveryParams& r) {
  s.x = c.get("sigma.x", s.x);
  s.y = c.get("sigma.y", s.y);
  s.scale = c.get("sigma.scale", s.scale);
  s.theta = c.get("sigma.theta", s.theta);
  a.patch_size = c.get("patch_size", a.patch_size);
  a.max_basis = c.get("max_basis", a.max_basis);
  a.block_size = c.get("block_size", a.block_size);
  a.forgetting = c.get("forgetting", a.forgetting);
  a.normalize_patches = c.get("normalize_patches", a.normalize_patches);
  a.anchor = c.get("anchor", a.anchor);
  a.likelihood.robust_scale = c.get("robust_scale", a.likelihood.robust_scale);
  a.likelihood.to_temperature = c.get("to_temperature", a.likelihood.to_temperature);
  a.likelihood.within_weight = c.get("within_weight", a.likelihood.within_weight);
  a.likelihood.within_epsilon = c.get("within_epsilon", a.likelihood.within_epsilon);
  a.update_max_residual = c.get("update_max_residual", a.update_max_residual);
  r.lost_residual = c.get("lost_residual", r.lost_residual);
  r.lost_ratio = c.get("lost_ratio", r.lost_ratio);
  r.ratio_floor = c.get("ratio_floor", r.ratio_floor);
  r.typical_rate = c.get("typical_rate", r.typical_rate);
  r.growth = c.get("recovery_growth", r.growth);
  r.max_lost_frames = c.get("max_lost_frames", r.max_lost_frames);
  r.max_factor = c.get("recovery_max_factor", r.max_factor);
}

std::string config_name(const util::Config& c, const char* tracker) { return tracker + (" (" + c.origin() + ")"); }

// particles in [1, kMaxParticles], and their observation matrix (particles x patch_size^2
// floats) within kMaxObservationFloats; patch_size itself is checked by validate_common.
void require_particles(const std::string& what, int particles, int patch_size) {
  require_in(particles, 1, kMaxParticles, what, "particles");
  const int64_t floats = int64_t{particles} * patch_size * patch_size;
  if (patch_size >= 4 && patch_size <= 256 && floats > kMaxObservationFloats)
    throw std::invalid_argument(what + ": particles x patch_size^2 = " + std::to_string(particles) + " x " +
                                std::to_string(patch_size) + "^2 is larger than " +
                                std::to_string(kMaxObservationFloats) + " observation values per frame");
}

}  // namespace

void validate(const IpslParams& p) {
  const std::string what = "ipsl parameters";
  validate_common(what, p.sigma, p.appearance, p.recovery);
  require_particles(what, p.particles, p.appearance.patch_size);
}

void validate(const HierarchicalIpslParams& p) {
  const std::string what = "ipsl-mr parameters";
  require(std::isfinite(p.min_size) && p.min_size >= 1, what, "min_size", p.min_size);
  validate_common(what, p.sigma, p.appearance, p.recovery);
  require_in(p.max_levels, 1, kMaxLevels, what, "max_levels");
  require((p.appearance.patch_size >> (p.max_levels - 1)) >= 4, what,
          "max_levels (patch_size / 2^(max_levels-1) must be >= 4)", p.max_levels);
  require_particles(what, p.particles, p.appearance.patch_size);
  require(std::isfinite(p.reject_ratio) && p.reject_ratio >= 0 && p.reject_ratio < 1, what, "reject_ratio",
          p.reject_ratio);
  require(std::isfinite(p.min_range) && p.min_range >= 0, what, "min_range", p.min_range);
  require(std::isfinite(p.max_range) && p.max_range >= p.min_range, what, "max_range", p.max_range);
  require(std::isfinite(p.min_theta_factor) && p.min_theta_factor >= 0 && p.min_theta_factor <= 1, what,
          "min_theta_factor", p.min_theta_factor);
  require_in(p.coarsest_block_size, 1, kMaxBlockSize, what, "coarsest_block_size");
}

// The parameters read from `c`, validated; an error names the config section.
template <typename Params>
Params validated(const Params& p, const util::Config& c, const char* tracker) {
  try {
    validate(p);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(config_name(c, tracker) + ": " + e.what());
  }
  return p;
}

IpslParams ipsl_params_from_config(const util::Config& c) {
  IpslParams p;
  p.particles = c.get("particles", p.particles);
  read_common(c, p.sigma, p.appearance, p.recovery);
  return validated(p, c, "ipsl");
}

HierarchicalIpslParams hierarchical_ipsl_params_from_config(const util::Config& c) {
  HierarchicalIpslParams p;
  p.min_size = c.get("min_size", p.min_size);
  p.max_levels = c.get("max_levels", p.max_levels);
  p.particles = c.get("particles", p.particles);
  p.reject_ratio = c.get("reject_ratio", p.reject_ratio);
  p.min_range = c.get("min_range", p.min_range);
  p.max_range = c.get("max_range", p.max_range);
  p.min_theta_factor = c.get("min_theta_factor", p.min_theta_factor);
  p.coarsest_block_size = c.get("coarsest_block_size", p.coarsest_block_size);
  p.probes = c.get("probes", p.probes);
  read_common(c, p.sigma, p.appearance, p.recovery);
  return validated(p, c, "ipsl-mr");
}

// ---------------------------------------------------------------------------------------------
// Shared machinery of both trackers

namespace {

void check_update(const cv::Mat& frame, bool initialised, const cv::Size& size, const std::string& name) {
  if (!initialised) throw std::invalid_argument(name + " update: called before init");
  validate_update(name, frame, size);
}

Similarity box_centre(const cv::Rect2d& box) { return {box.x + box.width / 2, box.y + box.height / 2, 1, 0}; }

// The state at init: the box itself, fully confident.
TrackState initial_state(const cv::Rect2d& box) {
  TrackState s;
  s.pose = box_centre(box);
  s.initial_size = box.size();
  s.confidence = 1;
  return s;
}

// Octave of the frame pyramid to sample from so that the target spans about patch_size pixels
// (bilinear sampling of a much larger region would alias).
int sampling_octave(const cv::Size2d& template_size, double scale, int patch_size) {
  const double ratio = scale * std::sqrt(template_size.area()) / patch_size;
  return ratio < 2 ? 0 : static_cast<int>(std::floor(std::log2(ratio)));
}

void build_pyramid(const cv::Mat& frame, int depth, std::vector<cv::Mat>& pyr) {
  const cv::Mat gray = to_gray(frame);
  cv::buildPyramid(gray, pyr, depth);
}

// The observations of `poses` (full-resolution pixels, the continuous coordinates of TrackState)
// at pyramid level `level`: one column per pose. pyrDown maps index i to 2i, so the index
// coordinate at level l is (x - 0.5) / 2^l; this is eqs. 3.12/3.13 (x^p = x^0 / 2^p).
Eigen::MatrixXf observe(const std::vector<cv::Mat>& pyr, int level, const std::vector<Particle>& particles,
                        const cv::Size2d& template_size, int patch_size, bool normalize) {
  const double f = std::ldexp(1.0, -level);
  const cv::Size2d t(template_size.width * f, template_size.height * f);
  const int dim = patch_size * patch_size;
  Eigen::MatrixXf out(dim, static_cast<Eigen::Index>(particles.size()));
  for (size_t i = 0; i < particles.size(); ++i) {
    const auto& p = particles[i].pose;
    float* col = out.col(static_cast<Eigen::Index>(i)).data();
    warp_patch(pyr[level], {(p.x - 0.5) * f, (p.y - 0.5) * f, p.scale, p.theta}, t, patch_size, col);
    if (normalize) normalize_patch(col, dim);
  }
  return out;
}

// Keeps a pose inside the image and its scale within sane bounds (a target side of at least
// 4 pixels, at most twice the image).
void clamp_pose(Similarity& s, const cv::Size& image, const cv::Size2d& template_size) {
  s.x = std::clamp(s.x, 0.0, static_cast<double>(image.width));
  s.y = std::clamp(s.y, 0.0, static_cast<double>(image.height));
  const double lo = 4.0 / std::min(template_size.width, template_size.height);
  const double hi = 2.0 * std::max(image.width, image.height) / std::max(template_size.width, template_size.height);
  s.scale = std::clamp(s.scale, lo, std::max(lo, hi));
}

// One random-walk step (eq. 3.7) with standard deviations `sigma` (x, y in full-resolution
// pixels, scale as a log step); a zero sigma leaves that parameter alone.
void random_walk(Similarity& s, const MotionSigma& sigma, std::mt19937_64& rng) {
  std::normal_distribution<double> n01;
  auto step = [&](double sd) { return sd > 0 ? sd * n01(rng) : 0.0; };
  s.x += step(sigma.x);
  s.y += step(sigma.y);
  s.scale *= std::exp(step(sigma.scale));
  s.theta += step(sigma.theta);
}

// log p(X_k | X_{k-1}) of eq. 3.6 under the random walk of eq. 3.7, up to a constant.
double log_motion_prior(const Similarity& x, const Similarity& prev, const MotionSigma& psi) {
  double lp = 0;
  auto term = [&](double d, double sd) {
    if (sd > 0) lp -= 0.5 * (d / sd) * (d / sd);
  };
  term(x.x - prev.x, psi.x);
  term(x.y - prev.y, psi.y);
  term(std::log(x.scale / prev.scale), psi.scale);
  term(x.theta - prev.theta, psi.theta);
  return lp;
}

// Systematic resampling: indices of `n` particles drawn in proportion to exp(log_weight).
std::vector<size_t> resample(const std::vector<double>& log_weights, size_t n, std::mt19937_64& rng) {
  const double top = *std::max_element(log_weights.begin(), log_weights.end());
  std::vector<double> cdf(log_weights.size());
  double sum = 0;
  for (size_t i = 0; i < log_weights.size(); ++i) cdf[i] = sum += std::exp(log_weights[i] - top);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const double step = sum / n;
  double pos = u01(rng) * step;
  std::vector<size_t> idx(n);
  size_t j = 0;
  for (size_t i = 0; i < n; ++i, pos += step) {
    while (j + 1 < cdf.size() && cdf[j] < pos) ++j;
    idx[i] = j;
  }
  return idx;
}

void score_particles(const AppearanceModel& model, const Eigen::MatrixXf& obs, std::vector<Particle>& particles) {
  std::vector<ObservationScore> scores;
  model.score(obs, scores);
  for (size_t i = 0; i < particles.size(); ++i) particles[i].score = scores[i];
}

LevelStats level_stats(int level, const std::vector<Particle>& particles, int rejected, double radius) {
  LevelStats st;
  st.level = level;
  st.evaluated = static_cast<int>(particles.size());
  st.rejected = rejected;
  st.search_radius = static_cast<float>(radius);
  st.samples.reserve(particles.size());
  st.scores.reserve(particles.size());
  for (const auto& p : particles) {
    st.samples.emplace_back(static_cast<float>(p.pose.x), static_cast<float>(p.pose.y));
    st.scores.push_back(static_cast<float>(p.log_posterior()));
  }
  return st;
}

// The MAP particle becomes the estimate (eq. 3.6).
void set_estimate(TrackState& state, const Particle& map) {
  const auto& p = map.pose;
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.scale) || !std::isfinite(p.theta))
    throw std::runtime_error("ipsl: the estimated state is not finite");
  state.pose = p;
  state.confidence = std::clamp(1.0 - map.score.residual, 0.0, 1.0);
}

size_t best_index(const std::vector<Particle>& particles) {
  size_t best = 0;
  for (size_t i = 1; i < particles.size(); ++i)
    if (particles[i].log_posterior() > particles[best].log_posterior()) best = i;
  return best;
}

}  // namespace

bool LossMonitor::observe(double residual, double update_max_residual, TrackState& state) {
  const bool was_lost = state.lost;
  state.lost = residual > params_.lost_residual ||
               (typical_ >= 0 && residual > params_.lost_ratio * typical_ && residual > params_.ratio_floor);
  lost_frames_ = state.lost ? lost_frames_ + 1 : 0;
  if (lost_frames_ > params_.max_lost_frames) {  // the appearance changed for good: learn it
    state.lost = false;
    lost_frames_ = 0;
    typical_ = residual;
  }
  state.redetected = was_lost && !state.lost;
  search_factor_ = state.lost ? std::min(search_factor_ * params_.growth, params_.max_factor) : 1.0;
  if (state.lost) return false;
  typical_ = typical_ < 0 ? residual : typical_ + params_.typical_rate * (residual - typical_);
  return residual <= update_max_residual;
}

// ---------------------------------------------------------------------------------------------
// IPSL (single resolution)

IpslTracker::IpslTracker(const IpslParams& params, uint64_t seed) : params_(params), rng_(seed) { validate(params); }

const IncrementalPca& IpslTracker::subspace() const {
  if (!model_) throw std::logic_error("ipsl: subspace() before init");
  return model_->pca();
}

void IpslTracker::init(const cv::Mat& frame, const cv::Rect2d& box) {
  validate_init(frame, box);
  frame_size_ = frame.size();
  const auto& a = params_.appearance;
  state_ = initial_state(box);
  build_pyramid(frame, sampling_octave(box.size(), 1, a.patch_size), pyramid_);
  model_ = std::make_unique<AppearanceModel>(a.patch_size * a.patch_size, a.max_basis, a.forgetting, a.block_size,
                                             a.likelihood, a.anchor);
  particles_.assign(params_.particles, Particle{state_.pose, 0, {}});
  const Eigen::MatrixXf first = observe(pyramid_, static_cast<int>(pyramid_.size()) - 1, {particles_.front()},
                                        state_.initial_size, a.patch_size, a.normalize_patches);
  model_->init(first.col(0));
  loss_ = LossMonitor(params_.recovery);
  initialised_ = true;
}

TrackState IpslTracker::update(const cv::Mat& frame) {
  check_update(frame, initialised_, frame_size_, name());
  const auto& a = params_.appearance;
  const int octave = sampling_octave(state_.initial_size, state_.pose.scale, a.patch_size);
  build_pyramid(frame, octave, pyramid_);

  // Condensation: resample by the last likelihoods, then one random-walk step (eq. 3.7).
  std::vector<double> log_w(particles_.size());
  for (size_t i = 0; i < particles_.size(); ++i) log_w[i] = particles_[i].score.log_likelihood;
  const auto parents = resample(log_w, params_.particles, rng_);
  MotionSigma sigma = params_.sigma;
  sigma.x *= loss_.search_factor();
  sigma.y *= loss_.search_factor();
  std::vector<Particle> next(parents.size());
  for (size_t i = 0; i < parents.size(); ++i) {
    next[i].pose = particles_[parents[i]].pose;
    random_walk(next[i].pose, sigma, rng_);
    clamp_pose(next[i].pose, frame_size_, state_.initial_size);
    next[i].log_prior = log_motion_prior(next[i].pose, state_.pose, sigma);
  }
  particles_ = std::move(next);

  // Likelihood (eqs. 3.8-3.10) and MAP estimate (eq. 3.6).
  const Eigen::MatrixXf obs = observe(pyramid_, octave, particles_, state_.initial_size, a.patch_size,
                                      a.normalize_patches);
  score_particles(*model_, obs, particles_);
  const size_t map = best_index(particles_);
  set_estimate(state_, particles_[map]);
  if (loss_.observe(particles_[map].score.residual, a.update_max_residual, state_))
    model_->add(obs.col(static_cast<Eigen::Index>(map)));
  state_.levels = {level_stats(0, particles_, 0, sigma.x)};
  return state_;
}

// ---------------------------------------------------------------------------------------------
// Hierarchical IPSL

HierarchicalIpslTracker::HierarchicalIpslTracker(const HierarchicalIpslParams& params, uint64_t seed)
    : params_(params), rng_(seed) {
  validate(params);
}

int HierarchicalIpslTracker::block_size(int level) const { return levels_.at(level)->block_size(); }

const IncrementalPca& HierarchicalIpslTracker::subspace(int level) const { return levels_.at(level)->pca(); }

void HierarchicalIpslTracker::init(const cv::Mat& frame, const cv::Rect2d& box) {
  validate_init(frame, box);
  frame_size_ = frame.size();
  const auto& a = params_.appearance;
  state_ = initial_state(box);

  // eq. 3.11, capped by max_levels.
  const int n_levels = std::min(params_.max_levels, pyramid::num_levels(box.width, box.height, params_.min_size));
  // eq. 3.16: N_B^{p-1} = floor(N_B^p / log2(1 + p)), from the coarsest level down.
  std::vector<int> block(n_levels);
  block[n_levels - 1] = params_.coarsest_block_size;
  for (int p = n_levels - 1; p >= 1; --p) block[p - 1] = std::max(1, pyramid::next_block_size(block[p], p));

  const int octave = sampling_octave(box.size(), 1, a.patch_size);
  build_pyramid(frame, n_levels - 1 + octave, pyramid_);
  levels_.clear();
  const std::vector<Particle> at_init{Particle{state_.pose, 0, {}}};
  for (int p = 0; p < n_levels; ++p) {
    const int patch = a.patch_size >> p;
    levels_.push_back(
        std::make_unique<AppearanceModel>(patch * patch, a.max_basis, a.forgetting, block[p], a.likelihood, a.anchor));
    levels_[p]->init(observe(pyramid_, p + octave, at_init, box.size(), patch, a.normalize_patches).col(0));
  }
  loss_ = LossMonitor(params_.recovery);
  initialised_ = true;
}

TrackState HierarchicalIpslTracker::update(const cv::Mat& frame) {
  check_update(frame, initialised_, frame_size_, name());
  const auto& a = params_.appearance;
  const int n_levels = num_levels();
  const int coarsest = n_levels - 1;
  const int octave = sampling_octave(state_.initial_size, state_.pose.scale, a.patch_size);
  build_pyramid(frame, coarsest + octave, pyramid_);

  // Level-specific motion models: coarsest = translation, middle = + rotation, finest = similarity.
  auto estimates_rotation = [&](int p) { return p < coarsest || n_levels == 1; };

  // Search ranges at the level being processed, in that level's pixels (x, y) and radians.
  double range_x = params_.sigma.x * loss_.search_factor(), range_y = params_.sigma.y * loss_.search_factor();
  double range_theta = estimates_rotation(coarsest) ? params_.sigma.theta : 0;

  // eq. 3.13: the last estimate seeds the coarsest level; particle 0 is the zero-motion hypothesis.
  std::vector<Particle> particles(params_.particles, Particle{state_.pose, 0, {}});
  auto step_sigma = [&](int p) {
    const double f = std::ldexp(1.0, p);  // level p pixels -> full-resolution pixels
    return MotionSigma{range_x * f, range_y * f, p == 0 ? params_.sigma.scale : 0.0, range_theta};
  };
  {
    const MotionSigma s = step_sigma(coarsest);
    for (size_t i = 1; i < particles.size(); ++i) {
      random_walk(particles[i].pose, s, rng_);
      clamp_pose(particles[i].pose, frame_size_, state_.initial_size);
    }
  }
  // Psi of eq. 3.7 for the prior of eq. 3.6: the coarsest level's translation range, rotation
  // and scale steps.
  const double coarsest_px = std::ldexp(1.0, coarsest);
  const MotionSigma psi{range_x * coarsest_px, range_y * coarsest_px, params_.sigma.scale, params_.sigma.theta};
  const Similarity previous = state_.pose;

  std::vector<LevelStats> stats;
  Eigen::MatrixXf obs;
  for (int p = coarsest;; --p) {
    const int patch = a.patch_size >> p;
    obs = observe(pyramid_, p + octave, particles, state_.initial_size, patch, a.normalize_patches);
    score_particles(*levels_[p], obs, particles);
    for (auto& q : particles) q.log_prior = log_motion_prior(q.pose, previous, psi);
    // Rank by the posterior of eq. 3.6 (stable: ties keep their order, for determinism).
    std::vector<size_t> order(particles.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&](size_t i, size_t j) { return particles[i].log_posterior() > particles[j].log_posterior(); });
    if (p == 0) {  // the finest level: the MAP particle is the estimate (eq. 3.6)
      stats.push_back(level_stats(0, particles, 0, range_x));
      const auto map = static_cast<Eigen::Index>(order.front());
      set_estimate(state_, particles[map]);
      if (loss_.observe(particles[map].score.residual, a.update_max_residual, state_)) {
        levels_[0]->add(obs.col(map));
        const std::vector<Particle> estimate{particles[map]};
        for (int q = 1; q < n_levels; ++q)
          levels_[q]->add(
              observe(pyramid_, q + octave, estimate, state_.initial_size, a.patch_size >> q, a.normalize_patches)
                  .col(0));
      }
      break;
    }

    // eq. 3.14: reject N_R^p = alpha^p N_P^p particles, the worst by weight.
    const int n = static_cast<int>(particles.size());
    const int rejected = pyramid::num_rejected(params_.reject_ratio, p, n);
    stats.push_back(level_stats(p, particles, rejected, range_x));
    const Particle& best = particles[order.front()];
    // eq. 3.15: the critical particle (best rejected) sets the next level's search range,
    // sigma^{p-1} = 2 H^p (H in level-p pixels, sigma in level-(p-1) pixels).
    const double level_px = std::ldexp(1.0, p);
    const double lo = params_.min_range, hi = params_.max_range;
    const double theta_lo = params_.min_theta_factor * params_.sigma.theta, theta_hi = params_.sigma.theta;
    if (rejected > 0) {
      const Particle& critical = particles[order[n - rejected]];
      range_x = std::clamp(pyramid::next_search_range(std::abs(critical.pose.x - best.pose.x) / level_px), lo, hi);
      range_y = std::clamp(pyramid::next_search_range(std::abs(critical.pose.y - best.pose.y) / level_px), lo, hi);
      range_theta =
          estimates_rotation(p)
              ? std::clamp(pyramid::next_search_range(std::abs(critical.pose.theta - best.pose.theta)), theta_lo,
                           theta_hi)
              : params_.sigma.theta;  // rotation enters at level p - 1
    } else {
      range_x = range_y = hi;
      range_theta = params_.sigma.theta;
    }

    // eq. 3.12: the level's estimate (its MAP particle) seeds level p - 1, which draws as many
    // particles as survived the rejection, with that level's motion model and search range.
    // Particle 0 is the estimate itself; with `probes`, particles 1 and 2 step only the
    // parameter that no coarser level estimated (rotation where it enters, scale at level 0) by
    // -/+ one sigma; the others take a full random step of the level's motion model.
    const MotionSigma s = step_sigma(p - 1);
    std::vector<Particle> next(n - rejected, Particle{best.pose, 0, {}});
    size_t first_random = 1;
    if (params_.probes && next.size() >= 3) {
      if (p - 1 == 0 && s.scale > 0) {
        next[1].pose.scale *= std::exp(-s.scale);
        next[2].pose.scale *= std::exp(s.scale);
        first_random = 3;
      } else if (!estimates_rotation(p) && s.theta > 0) {
        next[1].pose.theta -= s.theta;
        next[2].pose.theta += s.theta;
        first_random = 3;
      }
    }
    for (size_t r = first_random; r < next.size(); ++r) {
      random_walk(next[r].pose, s, rng_);
      clamp_pose(next[r].pose, frame_size_, state_.initial_size);
    }
    particles = std::move(next);
  }
  state_.levels = std::move(stats);
  return state_;
}

}  // namespace aerie::track
