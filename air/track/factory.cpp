#include "air/track/factory.hpp"

#include <algorithm>
#include <functional>
#include <opencv2/tracking.hpp>
#include <opencv2/tracking/tracking_legacy.hpp>
#include <opencv2/video/tracking.hpp>
#include <set>
#include <stdexcept>

#include "air/track/ct/ct.hpp"
#include "air/track/dcf/dcf.hpp"
#include "air/track/eco/eco.hpp"
#ifdef AERIE_HAVE_IPSL
#include "air/track/ipsl/ipsl.hpp"
#endif
#include "air/track/mil/mil.hpp"
#include "air/track/pyramid/discriminative.hpp"

namespace aerie::track {
namespace {

// Reads keys of one tracker section and rejects any key it does not know.
class Params {
 public:
  Params(const util::Config& cfg, std::string tracker) : cfg_(cfg), tracker_(std::move(tracker)) {}
  template <typename T>
  void read(const std::string& key, T& value) {
    known_.insert(key);
    value = cfg_.get<T>(key, value);
  }
  // A size or count that sets how much is allocated or looped over per frame: bounded
  // before any allocation (a TRACK_CMD override of features=1e7 stalled tracking).
  template <typename T>
  void read_in(const std::string& key, T& value, T lo, T hi) {
    known_.insert(key);
    try {
      value = cfg_.get_in<T>(key, value, lo, hi);
    } catch (const std::runtime_error& e) {
      throw std::invalid_argument(e.what());
    }
  }
  void read_list(const std::string& key, std::vector<double>& value) {
    known_.insert(key);
    if (!cfg_.has(key)) return;
    if (cfg_.node()[key].IsScalar())
      value = {cfg_.get<double>(key, 0.0)};
    else
      value = cfg_.get<std::vector<double>>(key, value);
  }
  void check_unknown() const {
    if (!cfg_.node().IsMap()) return;
    for (const auto& kv : cfg_.node()) {
      const auto key = kv.first.as<std::string>();
      if (!known_.count(key))
        throw std::invalid_argument(cfg_.origin() + ": unknown parameter '" + key + "' for tracker '" + tracker_ + "'");
    }
  }

 private:
  const util::Config& cfg_;
  std::string tracker_;
  std::set<std::string> known_;
};

DiscriminativeParams read_discriminative(Params& in, DiscriminativeParams p) {
  in.read("channels", p.channels);
  in.read_in("max_levels", p.max_levels, 1, 8);
  in.read("min_size", p.min_size);
  in.read_in("search_radius", p.search_radius, 0.0, 200.0);
  in.read_in("coarse_radius", p.coarse_radius, 0.0, 100.0);
  in.read("pos_radius", p.pos_radius);
  in.read("neg_inner", p.neg_inner);
  in.read_in("neg_outer", p.neg_outer, 0.0, 400.0);
  in.read_in("neg_count", p.neg_count, 0, 10000);
  in.read("min_pos_radius", p.min_pos_radius);
  in.read_list("reject_ratio", p.reject_ratio);
  in.read("min_radius", p.min_radius);
  in.read_in("max_radius", p.max_radius, 0.0, 200.0);
  in.read("scale_estimation", p.scale_estimation);
  in.read("scale_step", p.scale_step);
  in.read("max_scale_change", p.max_scale_change);
  in.read("min_scale", p.min_scale);
  in.read("max_scale", p.max_scale);
  in.read("flow_prediction", p.flow_prediction);
  in.read("redetection", p.redetection);
  in.read("confidence_rate", p.confidence_rate);
  in.read_in("lost_frames", p.lost_frames, 1, 100000);
  in.read("found_confidence", p.found_confidence);
  in.read_in("redetect_stride", p.redetect_stride, 1, 1000);
  in.read("redetect_radius", p.redetect_radius);
  in.read("update_confidence", p.update_confidence);
  return p;
}

double read_density_floor(Params& in) {
  double floor = 1e-30;
  in.read("density_floor", floor);
  if (!(floor > 0)) throw std::invalid_argument("density_floor must be > 0");
  return std::log(floor);
}

// Defaults of the single-resolution trackers (the published settings, but CT with 100 compressed
// features and AMCMR-CT with 150 and learning rate 0.9 where Zhang et al. use 50 and 0.85, and
// MIL/AM3 with the colour channels: measured better, docs/results/track.md) and of the
// multi-resolution ones (the thesis uses 3 levels, coarsest radius 5 for a full-resolution 20;
// 2 levels with coarsest radius 6 measured better on the shared set, docs/results/track.md).
DiscriminativeParams single_resolution() {
  DiscriminativeParams p;
  p.max_levels = 1;
  return p;
}
DiscriminativeParams with_colour(DiscriminativeParams p) {
  p.channels = {"gray", "gradient", "color"};
  return p;
}
DiscriminativeParams multi_resolution() {
  DiscriminativeParams p;
  p.max_levels = 2;
  p.coarse_radius = 6;
  return p;
}

std::unique_ptr<Tracker> make_ct(const std::string& name, const util::Config& cfg, uint64_t seed,
                                 DiscriminativeParams defaults, int features, double learning_rate) {
  Params in(cfg, name);
  CtParams ct;
  ct.features = features;
  ct.learning_rate = learning_rate;
  in.read_in("features", ct.features, 1, 10000);
  in.read_in("min_rects", ct.min_rects, 1, 16);
  in.read_in("max_rects", ct.max_rects, 1, 16);
  in.read("learning_rate", ct.learning_rate);
  in.read("sigma_min", ct.sigma_min);
  ct.log_floor = read_density_floor(in);
  const DiscriminativeParams d = read_discriminative(in, defaults);
  in.check_unknown();
  return std::make_unique<DiscriminativeTracker>(name, d, ct_classifier_factory(ct), seed);
}

std::unique_ptr<Tracker> make_mil(const std::string& name, const util::Config& cfg, uint64_t seed,
                                  DiscriminativeParams defaults) {
  Params in(cfg, name);
  MilParams mil;
  in.read_in("features", mil.features, 1, 10000);
  in.read_in("selected", mil.selected, 1, 10000);
  in.read_in("min_rects", mil.min_rects, 1, 16);
  in.read_in("max_rects", mil.max_rects, 1, 16);
  in.read("learning_rate", mil.learning_rate);
  in.read("sigma_min", mil.sigma_min);
  mil.log_floor = read_density_floor(in);
  const DiscriminativeParams d = read_discriminative(in, defaults);
  in.check_unknown();
  return std::make_unique<DiscriminativeTracker>(name, d, mil_classifier_factory(mil), seed);
}

// The keys DCF and ECO share (their parameter structs name the fields alike).
template <typename P>
void read_correlation_filter(Params& in, P& p) {
  in.read_in("cell", p.cell, 1, 16);
  in.read_in("padding", p.padding, 0.0, 10.0);
  in.read_in("template_area", p.template_area, 64.0, 1048576.0);
  in.read("output_sigma", p.output_sigma);
  in.read("lambda", p.lambda);
  in.read("learning_rate", p.learning_rate);
  in.read("mask_scale", p.mask_scale);
  in.read_in("admm_iterations", p.admm_iterations, 0, 100);
  in.read("hist_weight", p.hist_weight);
  in.read_in("hist_bins", p.hist_bins, 2, 256);
  in.read("hist_learning_rate", p.hist_learning_rate);
  in.read("inner_padding", p.inner_padding);
  in.read_in("scales", p.scales, 1, 129);
  in.read("scale_step", p.scale_step);
  in.read("scale_sigma", p.scale_sigma);
  in.read("scale_lambda", p.scale_lambda);
  in.read("scale_learning_rate", p.scale_learning_rate);
  in.read_in("scale_model_area", p.scale_model_area, 16.0, 65536.0);
  in.read("scale_resize_once", p.scale_resize_once);
  in.read("min_scale", p.min_scale);
  in.read("max_scale", p.max_scale);
  in.read("update_confidence", p.update_confidence);
  in.read("confidence_rate", p.confidence_rate);
  in.read("redetection", p.redetection);
  in.read_in("lost_frames", p.lost_frames, 1, 100000);
  in.read("found_confidence", p.found_confidence);
}

std::unique_ptr<Tracker> make_dcf(const util::Config& cfg) {
  Params in(cfg, "dcf");
  DcfParams p;
  read_correlation_filter(in, p);
  in.read("spatial_mask", p.spatial_mask);
  in.read("admm_mu", p.admm_mu);
  in.read("admm_beta", p.admm_beta);
  in.read("admm_mu_max", p.admm_mu_max);
  in.check_unknown();
  return std::make_unique<DcfTracker>(p);
}

std::unique_ptr<Tracker> make_eco(const util::Config& cfg) {
  Params in(cfg, "eco");
  EcoParams p;
  read_correlation_filter(in, p);
  in.read_in("hog_dims", p.hog_dims, 1, 32);
  in.read_in("cn_dims", p.cn_dims, 0, 11);
  in.read_in("samples", p.samples, 1, 200);
  in.read_in("update_interval", p.update_interval, 1, 1000);
  in.read("aberrance", p.aberrance);
  in.read("joint_filter", p.joint_filter);
  in.read("reg_floor", p.reg_floor);
  in.read("reg_edge", p.reg_edge);
  in.read_in("cg_iterations", p.cg_iterations, 1, 50);
  in.read_in("init_cg_iterations", p.init_cg_iterations, 1, 200);
  in.read_in("projection_steps", p.projection_steps, 0, 20);
  in.read("projection_reg", p.projection_reg);
  in.read("temporal_reg", p.temporal_reg);
  in.read("variation_gain", p.variation_gain);
  in.read("variation_reg", p.variation_reg);
  in.read("variation_limit", p.variation_limit);
  in.read_in("newton_iterations", p.newton_iterations, 0, 50);
  in.read("colour_evidence", p.colour_evidence);
  in.read("lost_confidence", p.lost_confidence);
  in.read_in("lost_after", p.lost_after, 1, 1000);
  in.read("verify_threshold", p.verify_threshold);
  in.read_in("verify_after", p.verify_after, 1, 1000);
  in.read_in("verify_exemplars", p.verify_exemplars, 1, 100);
  in.read("verify_learn_confidence", p.verify_learn_confidence);
  in.read("verify_learn_similarity", p.verify_learn_similarity);
  in.read_in("verify_interval", p.verify_interval, 1, 100000);
  in.read_in("global_interval", p.global_interval, 0, 100000);
  in.read_in("global_pixels", p.global_pixels, 1024.0, 4194304.0);
  in.read_in("global_candidates", p.global_candidates, 1, 20);
  in.check_unknown();
  return std::make_unique<EcoTracker>(p);
}

// OpenCV's trackers behind the Aerie interface. On a failed update the box stays where it
// was and the state says lost (OTB protocol: a box for every frame).
class OpenCvTracker : public Tracker {
 public:
  using Init = std::function<void(const cv::Mat&, const cv::Rect2d&)>;
  using Update = std::function<bool(const cv::Mat&, cv::Rect2d&)>;
  OpenCvTracker(std::string name, std::function<std::pair<Init, Update>()> make)
      : name_(std::move(name)), make_(std::move(make)) {}

  std::string name() const override { return name_; }
  void init(const cv::Mat& frame, const cv::Rect2d& box) override {
    validate_init(frame, box);
    std::tie(init_, update_) = make_();
    init_(frame, box);
    box_ = box;
    size_ = frame.size();
    initial_ = box.size();
  }
  TrackState update(const cv::Mat& frame) override {
    if (!update_) throw std::invalid_argument(name_ + ": update() before init()");
    validate_update(name_, frame, size_);
    cv::Rect2d b = box_;
    const bool ok = update_(frame, b);
    TrackState s;
    if (ok && b.width > 0 && b.height > 0 && std::isfinite(b.x) && std::isfinite(b.y)) box_ = b;
    s.initial_size = initial_;
    s.pose = {box_.x + box_.width / 2, box_.y + box_.height / 2, std::sqrt(box_.area() / initial_.area()), 0.0};
    s.initial_size = cv::Size2d(box_.width, box_.height) / s.pose.scale;  // keep the aspect ratio OpenCV reports
    s.confidence = ok ? 1.0 : 0.0;
    s.lost = !ok;
    return s;
  }

 private:
  std::string name_;
  std::function<std::pair<Init, Update>()> make_;
  Init init_;
  Update update_;
  cv::Rect2d box_;
  cv::Size size_;
  cv::Size2d initial_;
};

template <typename T>
std::pair<OpenCvTracker::Init, OpenCvTracker::Update> modern(cv::Ptr<T> t) {
  return {[t](const cv::Mat& f, const cv::Rect2d& b) { t->init(f, cv::Rect(b)); },
          [t](const cv::Mat& f, cv::Rect2d& b) {
            cv::Rect r(b);
            const bool ok = t->update(f, r);
            b = r;
            return ok;
          }};
}

template <typename T>
std::pair<OpenCvTracker::Init, OpenCvTracker::Update> legacy(cv::Ptr<T> t) {
  return {[t](const cv::Mat& f, const cv::Rect2d& b) { t->init(f, b); },
          [t](const cv::Mat& f, cv::Rect2d& b) { return t->update(f, b); }};
}

using Maker = std::function<std::unique_ptr<Tracker>(const util::Config&, uint64_t)>;

const std::vector<std::pair<std::string, Maker>>& registry() {
  static const std::vector<std::pair<std::string, Maker>> r = [] {
    std::vector<std::pair<std::string, Maker>> v;
#ifdef AERIE_HAVE_IPSL
    v.emplace_back("ipsl", [](const util::Config& c, uint64_t s) -> std::unique_ptr<Tracker> {
      return std::make_unique<IpslTracker>(ipsl_params_from_config(c), s);
    });
    v.emplace_back("ipsl-mr", [](const util::Config& c, uint64_t s) -> std::unique_ptr<Tracker> {
      return std::make_unique<HierarchicalIpslTracker>(hierarchical_ipsl_params_from_config(c), s);
    });
#endif
    v.emplace_back("ct", [](const util::Config& c, uint64_t s) {
      return make_ct("ct", c, s, single_resolution(), 100, 0.85);
    });
    v.emplace_back("amcmr-ct", [](const util::Config& c, uint64_t s) {
      return make_ct("amcmr-ct", c, s, multi_resolution(), 150, 0.9);
    });
    v.emplace_back("mil", [](const util::Config& c, uint64_t s) {
      return make_mil("mil", c, s, with_colour(single_resolution()));
    });
    v.emplace_back("am3", [](const util::Config& c, uint64_t s) {
      return make_mil("am3", c, s, with_colour(multi_resolution()));
    });
    v.emplace_back("dcf", [](const util::Config& c, uint64_t) { return make_dcf(c); });
    v.emplace_back("eco", [](const util::Config& c, uint64_t) { return make_eco(c); });
    auto reference = [&v](const std::string& name, std::function<std::pair<OpenCvTracker::Init, OpenCvTracker::Update>()> f) {
      v.emplace_back(name, [name, f](const util::Config& c, uint64_t) -> std::unique_ptr<Tracker> {
        Params(c, name).check_unknown();  // OpenCV defaults only
        return std::make_unique<OpenCvTracker>(name, f);
      });
    };
    reference("opencv-mil", [] { return modern(cv::TrackerMIL::create()); });
    reference("opencv-kcf", [] { return modern(cv::TrackerKCF::create()); });
    reference("opencv-csrt", [] { return modern(cv::TrackerCSRT::create()); });
    reference("opencv-tld", [] { return legacy(cv::legacy::TrackerTLD::create()); });
    reference("opencv-medianflow", [] { return legacy(cv::legacy::TrackerMedianFlow::create()); });
    reference("opencv-boosting", [] { return legacy(cv::legacy::TrackerBoosting::create()); });
    reference("opencv-mosse", [] { return legacy(cv::legacy::TrackerMOSSE::create()); });
    return v;
  }();
  return r;
}

}  // namespace

std::vector<std::string> aerie_tracker_names() {
  std::vector<std::string> out;
  for (const auto& [name, make] : registry())
    if (name.rfind("opencv-", 0) != 0) out.push_back(name);
  return out;
}

std::vector<std::string> opencv_tracker_names() {
  std::vector<std::string> out;
  for (const auto& [name, make] : registry())
    if (name.rfind("opencv-", 0) == 0) out.push_back(name);
  return out;
}

bool is_known_tracker(const std::string& name) {
  const auto& r = registry();
  return std::any_of(r.begin(), r.end(), [&](const auto& e) { return e.first == name; });
}

std::unique_ptr<Tracker> make_tracker(const std::string& name, const util::Config& params, uint64_t seed) {
  for (const auto& [n, make] : registry())
    if (n == name) return make(params, seed);
  std::string known;
  for (const auto& [n, make] : registry()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown tracker '" + name + "' (known: " + known + ")");
}

}  // namespace aerie::track
