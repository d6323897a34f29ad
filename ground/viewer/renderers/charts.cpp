#include "ground/viewer/renderers/charts.hpp"

#include <aerie/control_cmd_t.hpp>
#include <aerie/link_stats_t.hpp>
#include <aerie/pose_t.hpp>
#include <aerie/track_t.hpp>
#include <vtkAxis.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkContextActor.h>
#include <vtkContextScene.h>
#include <vtkDoubleArray.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkRenderer.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>

#include <cmath>

#include "common/bus/bus.hpp"
#include "ground/viewer/viewer.hpp"

namespace aerie::viewer {

ChartRenderer::ChartRenderer(std::string name, ChartSlot slot, std::string title, std::string x_label,
                             std::string y_label, std::vector<Series> series, std::string y2_label)
    : Renderer(std::move(name)),
      slot_(slot),
      title_(std::move(title)),
      x_label_(std::move(x_label)),
      y_label_(std::move(y_label)),
      y2_label_(std::move(y2_label)),
      series_(std::move(series)) {}

void ChartRenderer::attach(Layout& layout) {
  draws_in(layout.chart(slot_));
  chart_ = vtkSmartPointer<vtkChartXY>::New();
  chart_->SetTitle(title_);
  chart_->GetTitleProperties()->SetFontSize(12);
  chart_->GetAxis(vtkAxis::BOTTOM)->SetTitle(x_label_);
  chart_->GetAxis(vtkAxis::LEFT)->SetTitle(y_label_);
  chart_->GetAxis(vtkAxis::RIGHT)->SetTitle(y2_label_);
  for (int a : {vtkAxis::BOTTOM, vtkAxis::LEFT, vtkAxis::RIGHT}) {
    chart_->GetAxis(a)->GetTitleProperties()->SetFontSize(10);
    chart_->GetAxis(a)->GetLabelProperties()->SetFontSize(9);
  }
  chart_->SetShowLegend(true);
  chart_->GetLegend()->SetLabelSize(9);
  table_ = vtkSmartPointer<vtkTable>::New();
  auto x = vtkSmartPointer<vtkDoubleArray>::New();
  x->SetName(x_label_.c_str());
  table_->AddColumn(x);
  for (const auto& s : series_) {
    auto col = vtkSmartPointer<vtkDoubleArray>::New();
    col->SetName(s.name.c_str());
    table_->AddColumn(col);
  }
  actor_ = vtkSmartPointer<vtkContextActor>::New();
  actor_->GetScene()->AddItem(chart_);
  layout.chart(slot_)->AddActor(actor_);
}

void ChartRenderer::push(double x, std::vector<double> y) { data_.push({x, std::move(y)}); }

void ChartRenderer::push_at_utime(int64_t utime, std::vector<double> y) {
  int64_t expected = 0;
  t0_.compare_exchange_strong(expected, utime);
  latest_utime_ = std::max<int64_t>(latest_utime_, utime);
  push(static_cast<double>(utime - t0_) * 1e-6, std::move(y));
}

bool ChartRenderer::update() {
  std::vector<Sample> samples;
  if (!data_.snapshot_if_newer(seen_, samples)) return false;
  if (samples.size() < 2) return false;  // a line needs two points
  table_->SetNumberOfRows(static_cast<vtkIdType>(samples.size()));
  for (size_t r = 0; r < samples.size(); ++r) {
    table_->SetValue(static_cast<vtkIdType>(r), 0, samples[r].x);
    for (size_t c = 0; c < series_.size(); ++c)
      table_->SetValue(static_cast<vtkIdType>(r), static_cast<vtkIdType>(c + 1),
                       c < samples[r].y.size() ? samples[r].y[c] : std::nan(""));
  }
  table_->Modified();
  if (chart_->GetNumberOfPlots() == 0 && !samples.empty()) {
    for (size_t c = 0; c < series_.size(); ++c) {
      vtkPlot* plot = chart_->AddPlot(vtkChart::LINE);
      plot->SetInputData(table_, 0, static_cast<vtkIdType>(c + 1));
      plot->SetColor(series_[c].rgb[0], series_[c].rgb[1], series_[c].rgb[2], 255);
      plot->SetWidth(2.0);
      if (series_[c].right_axis) chart_->SetPlotCorner(plot, 1);
    }
  }
  chart_->RecalculateBounds();
  shown_ = samples.size();
  return true;
}

void ChartRenderer::on_enabled(bool on) {
  if (actor_) actor_->SetVisibility(on);
}

// ---------------------------------------------------------------- charts
HeadingChart::HeadingChart(std::string channel)
    : ChartRenderer("chart-heading", ChartSlot::Heading, "Heading", "t [s]", "deg",
                    {{"heading", {230, 80, 20}}, {"reference", {40, 40, 200}}}),
      channel_(std::move(channel)) {}

void HeadingChart::subscribe(bus::Bus& bus) {
  bus.subscribe<aerie::control_cmd_t>(channel_, [this](const aerie::control_cmd_t& m, const bus::ReceiveInfo&) {
    push_at_utime(m.utime, {m.heading_deg, m.heading_ref_deg});
  });
}

TrackerChart::TrackerChart(std::string channel)
    : ChartRenderer("chart-tracker", ChartSlot::Tracker, "Tracker", "t [s]", "confidence",
                    {{"confidence", {200, 30, 30}}, {"frames/s", {30, 120, 30}, true}}, "frames/s"),
      channel_(std::move(channel)) {}

void TrackerChart::subscribe(bus::Bus& bus) {
  bus.subscribe<aerie::track_t>(channel_, [this](const aerie::track_t& m, const bus::ReceiveInfo&) {
    // Frames per second the tracker sustains: from its processing time per frame.
    const double fps = m.processing_ms > 0 ? 1000.0 / m.processing_ms : 0.0;
    push_at_utime(m.utime, {m.confidence, fps});
  });
}

VoFeatureChart::VoFeatureChart(std::string channel)
    : ChartRenderer("chart-vo", ChartSlot::VoFeatures, "VO features", "t [s]", "count",
                    {{"3D", {30, 90, 200}}, {"2D", {220, 140, 20}}, {"inliers", {60, 160, 60}}}),
      channel_(std::move(channel)) {}

void VoFeatureChart::subscribe(bus::Bus& bus) {
  bus.subscribe<aerie::pose_t>(channel_, [this](const aerie::pose_t& m, const bus::ReceiveInfo&) {
    push_at_utime(m.utime, {double(m.features_3d), double(m.features_2d), double(m.inliers)});
  });
}

namespace {
std::vector<Series> latency_series(const std::vector<std::string>& channels) {
  static const std::array<unsigned char, 3> palette[] = {
      {200, 30, 30}, {30, 120, 200}, {30, 150, 60}, {200, 120, 0}, {120, 0, 160}, {90, 90, 90}};
  std::vector<Series> s;
  for (size_t i = 0; i < channels.size(); ++i) s.push_back({channels[i], palette[i % 6]});
  s.push_back({"link p50", {0, 0, 0}});
  s.push_back({"link p99", {140, 140, 140}});
  return s;
}
}  // namespace

LatencyChart::LatencyChart(std::vector<std::string> channels)
    : ChartRenderer("chart-latency", ChartSlot::Latency, "Latency", "t [s]", "ms", latency_series(channels)),
      channels_(std::move(channels)),
      last_ms_(channels_.size()) {}

void LatencyChart::subscribe(bus::Bus& bus) {
  for (size_t i = 0; i < channels_.size(); ++i) {
    bus.subscribe_raw(channels_[i], [this, i](const uint8_t* data, size_t size, const bus::ReceiveInfo& info) {
      const auto utime = bus::peek_utime(data, size);
      if (!utime) throw std::invalid_argument("message too short to hold a utime");
      if (*utime <= 0) return;  // no source frame (e.g. a controller hovering without input)
      // On the source's own clock (tools/latency/source_clock.hpp): dataset stamps are
      // measured from the frame's first arrival, never as receive time minus a 2015 stamp.
      std::optional<latency::Measured> m;
      {
        std::lock_guard lock(arrivals_m_);
        m = latency::measure(arrivals_, channels_[i], *utime, info.recv_utime);
        if (m && m->source_clock && !source_clock_) {
          chart_title_ = "Latency from arrival on " + m->reference + " (dataset time)";
          source_clock_ = true;
        }
      }
      if (!m) return;  // the frame's first arrival on another clock: the reference
      last_ms_[i] = m->ms;
      std::vector<double> y;
      for (const auto& v : last_ms_) y.push_back(v);
      y.push_back(link_p50_);
      y.push_back(link_p99_);
      push_at_utime(*utime, std::move(y));
    });
  }
  bus.subscribe<aerie::link_stats_t>("LINK_STATS", [this](const aerie::link_stats_t& m, const bus::ReceiveInfo&) {
    if (m.ndirections > 0) {
      link_p50_ = m.directions[0].delay_p50_ms;
      link_p99_ = m.directions[0].delay_p99_ms;
    }
  });
}

bool LatencyChart::update() {
  if (source_clock_ && !titled_) {
    std::lock_guard lock(arrivals_m_);
    chart()->SetTitle(chart_title_);
    titled_ = true;
  }
  return ChartRenderer::update();
}

CeCostChart::CeCostChart(std::string channel)
    : ChartRenderer("chart-ce-cost", ChartSlot::CeCost, "CE best cost", "iteration", "cost",
                    {{"stage 1", {200, 30, 30}}, {"stage 2", {30, 90, 200}}}),
      channel_(std::move(channel)) {}

void CeCostChart::subscribe(bus::Bus& bus) {
  bus.subscribe<aerie::ce_progress_t>(channel_, [this](const aerie::ce_progress_t& m, const bus::ReceiveInfo&) {
    if (m.iteration <= 1 && m.stage <= 1) clear();  // a new optimisation run
    const double nan = std::nan("");
    push(m.iteration, {m.stage <= 1 ? m.best_cost : nan, m.stage >= 2 ? m.best_cost : nan});
  });
}

CePdfChart::CePdfChart(std::string channel, int curves)
    : ChartRenderer("chart-ce-pdf", ChartSlot::CePdf, "CE sampling PDF", "value", "density", {}),
      channel_(std::move(channel)),
      curves_(curves) {}

void CePdfChart::subscribe(bus::Bus& bus) {
  bus.subscribe<aerie::ce_progress_t>(channel_, [this](const aerie::ce_progress_t& m, const bus::ReceiveInfo&) {
    if (m.nparams != static_cast<int32_t>(m.mean.size()) || m.mean.size() != m.sigma.size())
      throw std::invalid_argument("ce_progress_t: parameter arrays of different lengths");
    if (m.iteration <= 1) progress_.clear();
    progress_.push(m);
  });
}

bool CePdfChart::on_key(const std::string& key) {
  if (key != "n") return false;
  ++parameter_;
  dirty_ = true;
  return true;
}

bool CePdfChart::update() {
  std::vector<aerie::ce_progress_t> all;
  if (!progress_.snapshot_if_newer(seen_, all) && !dirty_) return false;
  dirty_ = false;
  if (all.empty()) return false;
  const auto& last = all.back();
  if (last.nparams == 0) return false;
  const size_t p = parameter_ % static_cast<size_t>(last.nparams);
  parameter_name_ = last.names[p];
  chart()->SetTitle("CE PDF: " + parameter_name_ + " ('n': next)");
  // One curve per iteration for the last `curves_` iterations, on a common x range.
  const size_t first = all.size() > static_cast<size_t>(curves_) ? all.size() - curves_ : 0;
  double lo = 1e300, hi = -1e300;
  for (size_t i = first; i < all.size(); ++i) {
    if (all[i].nparams <= static_cast<int32_t>(p)) continue;
    lo = std::min(lo, all[i].mean[p] - 3.5 * all[i].sigma[p]);
    hi = std::max(hi, all[i].mean[p] + 3.5 * all[i].sigma[p]);
  }
  if (!(hi > lo)) return false;
  auto table = vtkSmartPointer<vtkTable>::New();
  auto x = vtkSmartPointer<vtkDoubleArray>::New();
  x->SetName("value");
  table->AddColumn(x);
  const int n = 200;
  table->SetNumberOfRows(n);
  chart()->ClearPlots();
  for (size_t i = first; i < all.size(); ++i) {
    auto col = vtkSmartPointer<vtkDoubleArray>::New();
    col->SetName(("it " + std::to_string(all[i].iteration)).c_str());
    col->SetNumberOfValues(n);
    table->AddColumn(col);
  }
  for (int r = 0; r < n; ++r) {
    const double v = lo + (hi - lo) * r / (n - 1);
    table->SetValue(r, 0, v);
    for (size_t i = first; i < all.size(); ++i) {
      const double m = all[i].mean[p], s = std::max(all[i].sigma[p], 1e-12);
      table->SetValue(r, static_cast<vtkIdType>(i - first + 1),
                      std::exp(-0.5 * (v - m) * (v - m) / (s * s)) / (s * std::sqrt(2 * M_PI)));
    }
  }
  for (size_t i = first; i < all.size(); ++i) {
    vtkPlot* plot = chart()->AddPlot(vtkChart::LINE);
    plot->SetInputData(table, 0, static_cast<vtkIdType>(i - first + 1));
    // Older iterations fade from light to dark blue.
    const double f = all.size() - first > 1 ? double(i - first) / double(all.size() - first - 1) : 1.0;
    plot->SetColor(static_cast<unsigned char>(180 * (1 - f)), static_cast<unsigned char>(180 * (1 - f)), 220, 255);
    plot->SetWidth(i + 1 == all.size() ? 2.5f : 1.0f);
  }
  chart()->RecalculateBounds();
  return true;
}

void add_default_charts(Viewer& viewer) {
  viewer.add(std::make_unique<HeadingChart>());
  viewer.add(std::make_unique<TrackerChart>());
  viewer.add(std::make_unique<VoFeatureChart>());
  viewer.add(std::make_unique<LatencyChart>());
  viewer.add(std::make_unique<CeCostChart>());
  viewer.add(std::make_unique<CePdfChart>());
}

}  // namespace aerie::viewer
