#include "tools/log/log_export.hpp"

#include <aerie/gt_box_t.hpp>
#include <aerie/gt_pose_t.hpp>
#include <aerie/image_t.hpp>
#include <aerie/pose_t.hpp>
#include <aerie/stereo_image_t.hpp>
#include <aerie/track_t.hpp>

#include <cstdio>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <stdexcept>

#include "common/bus/wire.hpp"
#include "common/image/image_message.hpp"
#include "tools/log/type_registry.hpp"

namespace aerie::logtools {
namespace fs = std::filesystem;

std::string utime_to_seconds(int64_t utime) {
  char buf[48];
  const char* sign = utime < 0 ? "-" : "";
  const uint64_t u = static_cast<uint64_t>(utime < 0 ? -utime : utime);
  std::snprintf(buf, sizeof buf, "%s%llu.%06llu", sign, static_cast<unsigned long long>(u / 1'000'000),
                static_cast<unsigned long long>(u % 1'000'000));
  return buf;
}

namespace {

std::ofstream open_out(const fs::path& p) {
  std::ofstream f(p);
  if (!f) throw std::runtime_error(p.string() + ": cannot create file");
  return f;
}

void write_png(const fs::path& p, const cv::Mat& img) {
  if (!cv::imwrite(p.string(), img)) throw std::runtime_error(p.string() + ": cannot write PNG");
}

std::string frame_name(int64_t i) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%06lld.png", static_cast<long long>(i));
  return buf;
}

// One exporter per message type; consume() returns false for an undecodable payload; finish()
// runs after the last message (a second look at the log if the exporter needs one).
class Exporter {
 public:
  virtual ~Exporter() = default;
  virtual bool consume(const logio::Event& ev) = 0;
  virtual void finish(const std::string& /*log_path*/, bool /*resync*/, ExportResult& /*r*/) {}
};

template <typename Msg>
bool decode(const logio::Event& ev, Msg& m) {
  return bus::decode_bounded(ev.data.data(), ev.data.size(), m);
}

class ImageExporter final : public Exporter {
 public:
  ImageExporter(const fs::path& dir, ExportResult& r) : dir_(dir), times_(open_out(dir / "times.txt")) {
    r.outputs = {dir.string() + "/NNNNNN.png", (dir / "times.txt").string()};
  }
  bool consume(const logio::Event& ev) override {
    aerie::image_t m;
    if (!decode(ev, m)) return false;
    cv::Mat img;
    try {
      img = image::from_message(m);
    } catch (const std::invalid_argument&) {
      return false;
    }
    write_png(dir_ / frame_name(n_++), img);
    times_ << utime_to_seconds(m.utime) << "\n";
    return true;
  }

 private:
  fs::path dir_;
  std::ofstream times_;
  int64_t n_ = 0;
};

class StereoExporter final : public Exporter {
 public:
  StereoExporter(const fs::path& dir, ExportResult& r) : dir_(dir), times_(open_out(dir / "times.txt")) {
    fs::create_directories(dir / "image_l");
    fs::create_directories(dir / "image_r");
    r.outputs = {(dir / "image_l").string(), (dir / "image_r").string(), (dir / "times.txt").string(),
                 (dir / "calib.txt").string()};
  }
  bool consume(const logio::Event& ev) override {
    aerie::stereo_image_t m;
    if (!decode(ev, m)) return false;
    cv::Mat l, r;
    try {
      l = image::from_message(m.left);
      r = image::from_message(m.right);
    } catch (const std::invalid_argument&) {
      return false;
    }
    if (n_ == 0) write_calib(m);
    write_png(dir_ / "image_l" / frame_name(n_), l);
    write_png(dir_ / "image_r" / frame_name(n_), r);
    ++n_;
    times_ << utime_to_seconds(m.utime) << "\n";
    return true;
  }

 private:
  // KITTI calib.txt: rectified 3x4 projection matrices, P1[0,3] = -fx * baseline.
  void write_calib(const aerie::stereo_image_t& m) {
    auto f = open_out(dir_ / "calib.txt");
    char line[512];
    for (int cam = 0; cam < 2; ++cam) {
      std::snprintf(line, sizeof line, "P%d: %.12e 0 %.12e %.12e 0 %.12e %.12e 0 0 0 1 0\n", cam, m.fx, m.cx,
                    cam ? -m.fx * m.baseline_m : 0.0, m.fy, m.cy);
      f << line;
    }
  }
  fs::path dir_;
  std::ofstream times_;
  int64_t n_ = 0;
};

// TUM trajectory: timestamp tx ty tz qx qy qz qw (our messages store w, x, y, z).
template <typename Msg>
class TumExporter final : public Exporter {
 public:
  TumExporter(const fs::path& file, ExportResult& r) : out_(open_out(file)) { r.outputs = {file.string()}; }
  bool consume(const logio::Event& ev) override {
    Msg m{};
    if (!decode(ev, m)) return false;
    char line[256];
    std::snprintf(line, sizeof line, "%s %.9f %.9f %.9f %.12f %.12f %.12f %.12f\n", utime_to_seconds(m.utime).c_str(),
                  m.position[0], m.position[1], m.position[2], m.orientation[1], m.orientation[2],
                  m.orientation[3], m.orientation[0]);
    out_ << line;
    return true;
  }

 private:
  std::ofstream out_;
};

class BoxExporter final : public Exporter {
 public:
  BoxExporter(const fs::path& file, ExportResult& r) : out_(open_out(file)) {
    r.outputs = {file.string()};
    out_ << "t,visible,x,y,width,height\n";
  }
  bool consume(const logio::Event& ev) override {
    aerie::gt_box_t m;
    if (!decode(ev, m)) return false;
    char line[256];
    std::snprintf(line, sizeof line, "%s,%d,%.3f,%.3f,%.3f,%.3f\n", utime_to_seconds(m.utime).c_str(),
                  m.visible ? 1 : 0, m.x, m.y, m.width, m.height);
    out_ << line;
    return true;
  }

 private:
  std::ofstream out_;
};

// Tracker output, one row per source frame: the frames of the camera channel the tracker read
// (the messages' `camera` field, or --camera), paired with the TRACK messages by utime (a result
// copies its frame's utime). A frame the tracker skipped is a NaN row with status SKIPPED, so
// row i of both files is frame i of the source, as the OTB toolkits score them. Without frames
// of that channel in the log, one row per TRACK message. The box is the tracker's
// axis-aligned box of the unrotated target (TrackState::box()): top-left corner x, y and width,
// height in pixels, in the image coordinates the trackers use (0-based, as OpenCV; no +1 of the
// MATLAB-made OTB files), as aerie-bench-track reads and writes OTB boxes. theta stays in the
// message. An IDLE frame (no target) has no box: NaN, which the OTB readers take as "no target".
class TrackExporter final : public Exporter {
 public:
  TrackExporter(const fs::path& csv, const fs::path& otb, const std::string& camera, ExportResult& r)
      : csv_(open_out(csv)), otb_(open_out(otb)), camera_(camera) {
    r.outputs = {csv.string(), otb.string()};
    csv_ << "t,seq,x,y,w,h,status,confidence\n";
  }
  bool consume(const logio::Event& ev) override {
    aerie::track_t m;
    if (!decode(ev, m)) return false;
    char box[160], confidence[32];
    if (m.status == aerie::track_t::IDLE) {
      std::snprintf(box, sizeof box, "NaN,NaN,NaN,NaN");
    } else {
      std::snprintf(box, sizeof box, "%.3f,%.3f,%.3f,%.3f", m.x - m.width / 2, m.y - m.height / 2, m.width, m.height);
    }
    std::snprintf(confidence, sizeof confidence, "%.3f", m.confidence);
    if (camera_.empty()) camera_ = m.camera;
    rows_.push_back({m.utime, m.seq, box, status_name(m.status), confidence});
    return true;
  }
  void finish(const std::string& log_path, bool resync, ExportResult& r) override {
    r.camera = camera_;
    const auto frames = camera_.empty() ? std::vector<Frame>{} : read_frames(log_path, resync);
    r.frames = static_cast<int64_t>(frames.size());
    if (frames.empty()) {
      for (const auto& row : rows_) write(row);
      r.notes.push_back("no frames of " + (camera_.empty() ? std::string("the camera (empty camera field)") : camera_) +
                        " in the log: one row per track message (a frame the tracker skipped is not marked; "
                        "--camera names the source channel)");
      return;
    }
    std::map<int64_t, std::deque<size_t>> by_utime;
    for (size_t i = 0; i < rows_.size(); ++i) by_utime[rows_[i].utime].push_back(i);
    for (const auto& f : frames) {
      const auto it = by_utime.find(f.utime);
      if (it == by_utime.end() || it->second.empty()) {
        write({f.utime, f.seq, "NaN,NaN,NaN,NaN", "SKIPPED", "NaN"});
        ++r.skipped_frames;
        continue;
      }
      write(rows_[it->second.front()]);
      it->second.pop_front();
    }
    int64_t unmatched = 0;
    for (const auto& [utime, left] : by_utime) unmatched += static_cast<int64_t>(left.size());
    if (unmatched)
      r.notes.push_back(std::to_string(unmatched) + " track messages have no frame of " + camera_ +
                        " with their utime: left out");
  }

 private:
  struct Row {
    int64_t utime, seq;
    std::string box, status, confidence;
  };
  struct Frame {
    int64_t utime, seq;
  };
  // The source frames: utime and frame number of every decodable message on the camera channel.
  std::vector<Frame> read_frames(const std::string& log_path, bool resync) const {
    logio::Reader reader(log_path, {.resync = resync});
    std::vector<Frame> frames;
    logio::Event ev;
    while (reader.next(ev)) {
      if (ev.channel != camera_) continue;
      const TypeInfo* t = find_type(fingerprint_of(ev.data.data(), ev.data.size()));
      if (!t) continue;
      const Stamp s = t->decode(ev.data.data(), ev.data.size());
      if (s.decoded && s.utime) frames.push_back({*s.utime, s.seq.value_or(-1)});
    }
    return frames;
  }
  void write(const Row& row) {
    csv_ << utime_to_seconds(row.utime) << ',' << row.seq << ',' << row.box << ',' << row.status << ','
         << row.confidence << '\n';
    otb_ << row.box << '\n';
  }
  static std::string status_name(int8_t s) {
    switch (s) {
      case aerie::track_t::IDLE: return "IDLE";
      case aerie::track_t::TRACKING: return "TRACKING";
      case aerie::track_t::LOST: return "LOST";
      case aerie::track_t::REDETECTED: return "REDETECTED";
      default: return std::to_string(s);
    }
  }
  std::ofstream csv_, otb_;
  std::string camera_;
  std::vector<Row> rows_;
};

std::unique_ptr<Exporter> make_exporter(const std::string& type, const std::string& channel, const fs::path& dir,
                                        const std::string& camera, ExportResult& r) {
  if (type == "aerie.image_t") return std::make_unique<ImageExporter>(dir, r);
  if (type == "aerie.stereo_image_t") return std::make_unique<StereoExporter>(dir, r);
  if (type == "aerie.gt_pose_t") return std::make_unique<TumExporter<aerie::gt_pose_t>>(dir / (channel + ".tum"), r);
  if (type == "aerie.pose_t") return std::make_unique<TumExporter<aerie::pose_t>>(dir / (channel + ".tum"), r);
  if (type == "aerie.gt_box_t") return std::make_unique<BoxExporter>(dir / (channel + ".csv"), r);
  if (type == "aerie.track_t")
    return std::make_unique<TrackExporter>(dir / (channel + ".csv"), dir / (channel + ".txt"), camera, r);
  return nullptr;
}

}  // namespace

ExportResult export_channel(const std::string& log_path, const std::string& channel, const std::string& out_dir,
                            bool resync, bool force, const std::string& camera) {
  std::error_code ec;
  if (!force && fs::exists(fs::symlink_status(out_dir, ec)) &&
      !(fs::is_directory(out_dir, ec) && fs::is_empty(out_dir, ec)))
    throw std::runtime_error("export: the output " + out_dir + " exists and is not an empty folder; pass --force to "
                             "write over the files in it");
  logio::Reader reader(log_path, {.resync = resync});
  ExportResult r;
  std::unique_ptr<Exporter> exporter;
  int64_t fingerprint = 0;
  std::set<std::string> channels;
  logio::Event ev;
  while (reader.next(ev)) {
    if (ev.channel != channel) {
      channels.insert(ev.channel);
      continue;
    }
    const int64_t fp = fingerprint_of(ev.data.data(), ev.data.size());
    if (!exporter) {
      const TypeInfo* t = find_type(fp);
      if (!t) {  // an unknown or corrupt first payload: look at the next message
        ++r.undecodable;
        continue;
      }
      r.type = t->name;
      fs::create_directories(out_dir);
      exporter = make_exporter(r.type, channel, out_dir, camera, r);
      if (!exporter)
        throw std::runtime_error(log_path + ": channel " + channel + " carries " + r.type +
                                 ", which cannot be exported (images, stereo pairs, poses, boxes and tracks can)");
      fingerprint = fp;
    }
    if (fp != fingerprint) {
      ++r.other_type;
    } else if (exporter->consume(ev)) {
      ++r.exported;
    } else {
      ++r.undecodable;
    }
  }
  r.damage = reader.damage();
  if (exporter) exporter->finish(log_path, resync, r);
  if (!exporter && r.undecodable == 0) {
    std::string list;
    for (const auto& c : channels) list += (list.empty() ? "" : ", ") + c;
    throw std::runtime_error(log_path + ": no messages on channel " + channel + " (channels: " +
                             (list.empty() ? "none" : list) + ")");
  }
  return r;
}

}  // namespace aerie::logtools
