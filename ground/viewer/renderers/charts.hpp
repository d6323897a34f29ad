#pragma once
// Chart renderers (VTK charts, one per chart slot of the layout). Time axes are message
// time (utime) in seconds since the first message the chart saw, so replays follow
// log time rather than the wall clock.
#include <aerie/ce_progress_t.hpp>
#include <vtkChartXY.h>
#include <vtkContextActor.h>
#include <vtkSmartPointer.h>
#include <vtkTable.h>

#include <array>
#include <atomic>
#include <mutex>
#include <string>
#include <vector>

#include "ground/viewer/latest.hpp"
#include "ground/viewer/layout.hpp"
#include "ground/viewer/renderer.hpp"
#include "tools/latency/source_clock.hpp"


namespace aerie::viewer {

class Viewer;

struct Series {
  std::string name;
  std::array<unsigned char, 3> rgb;
  bool right_axis = false;  // plotted against the right-hand y axis
};

// A line chart of samples (x, y_0 .. y_n-1).
class ChartRenderer : public Renderer {
 public:
  struct Sample {
    double x;
    std::vector<double> y;
  };
  ChartRenderer(std::string name, ChartSlot slot, std::string title, std::string x_label, std::string y_label,
                std::vector<Series> series, std::string y2_label = "");
  void attach(Layout& layout) override;
  bool update() override;
  int64_t latest_utime() const override { return latest_utime_; }
  size_t samples_shown() const { return shown_; }

 protected:
  void on_enabled(bool on) override;
  // LCM thread: a sample stamped with message time.
  void push_at_utime(int64_t utime, std::vector<double> y);
  void push(double x, std::vector<double> y);
  void clear() { data_.clear(); }
  vtkChartXY* chart() const { return chart_; }

 private:
  ChartSlot slot_;
  std::string title_, x_label_, y_label_, y2_label_;
  std::vector<Series> series_;
  History<Sample> data_{3000};
  uint64_t seen_ = 0;
  size_t shown_ = 0;
  std::atomic<int64_t> t0_{0}, latest_utime_{0};
  vtkSmartPointer<vtkContextActor> actor_;
  vtkSmartPointer<vtkChartXY> chart_;
  vtkSmartPointer<vtkTable> table_;
};

// CTRL_CMD: measured heading and its reference (deg).
class HeadingChart : public ChartRenderer {
 public:
  explicit HeadingChart(std::string channel = "CTRL_CMD");
  void subscribe(bus::Bus& bus) override;

 private:
  std::string channel_;
};

// TRACK: tracker confidence (left axis) and frames per second (right axis).
class TrackerChart : public ChartRenderer {
 public:
  explicit TrackerChart(std::string channel = "TRACK");
  void subscribe(bus::Bus& bus) override;

 private:
  std::string channel_;
  int64_t last_utime_ = 0;
};

// VO_POSE: features used with depth (3D) and without (2D).
class VoFeatureChart : public ChartRenderer {
 public:
  explicit VoFeatureChart(std::string channel = "VO_POSE");
  void subscribe(bus::Bus& bus) override;

 private:
  std::string channel_;
};

// Per-channel latency (receive time - source utime, ms) of the result channels, and the
// link emulator's achieved delay (LINK_STATS, first direction, p50/p99). Messages stamped
// by another clock (recorded data) follow tools/latency/source_clock.hpp: their latency is
// measured from their frame's first arrival, and the title says so.
class LatencyChart : public ChartRenderer {
 public:
  explicit LatencyChart(std::vector<std::string> channels = {"CAM_STEREO", "TRACK", "VO_POSE", "CTRL_CMD"});
  void subscribe(bus::Bus& bus) override;
  bool update() override;
  bool source_clock() const { return source_clock_; }

 private:
  std::vector<std::string> channels_;
  std::vector<std::atomic<double>> last_ms_;
  std::atomic<double> link_p50_{0}, link_p99_{0};
  std::mutex arrivals_m_;
  latency::FrameArrivals arrivals_;
  std::atomic<bool> source_clock_{false};
  std::string chart_title_;  // set once by the LCM thread (under source_clock_), read after it
  bool titled_ = false;
};

// CE_PROGRESS: best cost per iteration.
class CeCostChart : public ChartRenderer {
 public:
  explicit CeCostChart(std::string channel = "CE_PROGRESS");
  void subscribe(bus::Bus& bus) override;

 private:
  std::string channel_;
};

// CE_PROGRESS: the evolving Gaussian PDF of one parameter, one curve per iteration
// (thesis Figs. 5.16-5.25). 'n' selects the next parameter.
class CePdfChart : public ChartRenderer {
 public:
  explicit CePdfChart(std::string channel = "CE_PROGRESS", int curves = 8);
  void subscribe(bus::Bus& bus) override;
  bool update() override;
  bool on_key(const std::string& key) override;
  const std::string& parameter() const { return parameter_name_; }

 private:
  std::string channel_;
  int curves_;
  History<aerie::ce_progress_t> progress_{400};
  uint64_t seen_ = 0;
  size_t parameter_ = 0;
  std::string parameter_name_;
  bool dirty_ = false;
};

void add_default_charts(Viewer& viewer);

}  // namespace aerie::viewer
