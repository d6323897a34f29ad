#include "tools/eval/trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace aerie::eval {
namespace {

// The numbers of each data row ('#' comments and blank lines skipped, commas as spaces);
// `lines` (optional) receives each row's line number in the file.
std::vector<std::vector<double>> read_numbers(const std::string& path, std::vector<int>* lines = nullptr) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::vector<std::vector<double>> rows;
  std::string line;
  int lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    for (char& c : line)
      if (c == ',') c = ' ';
    std::istringstream ss(line);
    std::vector<double> row;
    std::string tok;
    while (ss >> tok) {
      try {
        size_t used = 0;
        row.push_back(std::stod(tok, &used));
        if (used != tok.size()) throw std::invalid_argument(tok);
      } catch (const std::exception&) {
        throw std::runtime_error(path + ":" + std::to_string(lineno) + ": '" + tok + "' is not a number");
      }
    }
    for (double v : row)
      if (!std::isfinite(v)) throw std::runtime_error(path + ":" + std::to_string(lineno) + ": value is not finite");
    rows.push_back(std::move(row));
    if (lines) lines->push_back(lineno);
  }
  return rows;
}

void expect_columns(const std::string& path, const std::vector<std::vector<double>>& rows, size_t n,
                    const char* format) {
  for (size_t i = 0; i < rows.size(); ++i)
    if (rows[i].size() != n)
      throw std::runtime_error(path + ": data row " + std::to_string(i + 1) + " has " + std::to_string(rows[i].size()) +
                               " numbers, a " + format + " row has " + std::to_string(n));
}

}  // namespace

double Trajectory::path_length() const { return empty() ? 0.0 : distances().back(); }

std::vector<double> Trajectory::distances() const {
  std::vector<double> d(poses.size(), 0.0);
  for (size_t i = 1; i < poses.size(); ++i)
    d[i] = d[i - 1] + (poses[i].translation() - poses[i - 1].translation()).norm();
  return d;
}

Trajectory read_tum(const std::string& path) {
  const auto rows = read_numbers(path);
  expect_columns(path, rows, 8, "TUM");
  Trajectory traj;
  for (const auto& r : rows) {
    const double wxyz[4] = {r[7], r[4], r[5], r[6]};
    const double t[3] = {r[1], r[2], r[3]};
    traj.push_back(r[0], geometry::SE3::from_wxyz(wxyz, t));
  }
  return traj;
}

void write_tum(const Trajectory& traj, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write");
  out << "# timestamp tx ty tz qx qy qz qw\n" << std::setprecision(9) << std::fixed;
  for (size_t i = 0; i < traj.size(); ++i) {
    const auto& T = traj.poses[i];
    const auto& q = T.rotation();
    const auto& t = T.translation();
    out << traj.stamps[i] << ' ' << t.x() << ' ' << t.y() << ' ' << t.z() << ' ' << q.x() << ' ' << q.y() << ' '
        << q.z() << ' ' << q.w() << '\n';
  }
  if (!out) throw std::runtime_error(path + ": write failed");
}

Trajectory read_kitti_poses(const std::string& path, const std::string& times_path) {
  const auto rows = read_numbers(path);
  expect_columns(path, rows, 12, "KITTI pose");
  std::vector<double> times;
  if (!times_path.empty()) {
    const auto trows = read_numbers(times_path);
    expect_columns(times_path, trows, 1, "times");
    if (trows.size() != rows.size())
      throw std::runtime_error(times_path + ": " + std::to_string(trows.size()) + " times for " +
                               std::to_string(rows.size()) + " poses in " + path);
    for (const auto& r : trows) times.push_back(r[0]);
  }
  Trajectory traj;
  for (size_t i = 0; i < rows.size(); ++i) {
    Eigen::Matrix3d R;
    Eigen::Vector3d t;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) R(r, c) = rows[i][4 * r + c];
      t[r] = rows[i][4 * r + 3];
    }
    // Re-orthonormalise: printed matrices carry ~1e-9 rounding.
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
    R = svd.matrixU() * svd.matrixV().transpose();
    if (R.determinant() < 0) throw std::runtime_error(path + ": pose " + std::to_string(i) + " is not a rotation");
    traj.push_back(times.empty() ? static_cast<double>(i) : times[i], geometry::SE3(R, t));
  }
  return traj;
}

void write_kitti_poses(const Trajectory& traj, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write");
  out << std::setprecision(9) << std::scientific;
  for (const auto& T : traj.poses) {
    const Eigen::Matrix4d M = T.matrix();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) out << M(r, c) << (r == 2 && c == 3 ? '\n' : ' ');
  }
  if (!out) throw std::runtime_error(path + ": write failed");
}

const char* format_name(TrajectoryFormat f) {
  switch (f) {
    case TrajectoryFormat::Tum: return "TUM";
    case TrajectoryFormat::EurocCsv: return "EuRoC CSV";
    case TrajectoryFormat::KittiPoses: return "KITTI poses";
  }
  return "?";
}

namespace {

// A timestamp in nanoseconds (EuRoC) rather than seconds (TUM): an integer beyond 1e12
// (1e12 s would be 31 700 years; 1e12 ns is 17 minutes after the epoch).
bool is_nanoseconds(double t) { return t >= 1e12 && t == std::floor(t); }

TrajectoryFormat detect(const std::string& path, const std::vector<std::vector<double>>& rows,
                        const std::vector<int>& lines) {
  if (rows.empty()) throw std::runtime_error(path + ": no poses");
  const auto& r = rows.front();
  if (r.size() == 12) return TrajectoryFormat::KittiPoses;
  if (r.size() >= 8 && is_nanoseconds(r[0])) return TrajectoryFormat::EurocCsv;
  if (r.size() == 8) return TrajectoryFormat::Tum;
  throw std::runtime_error(path + ":" + std::to_string(lines.front()) + ": " + std::to_string(r.size()) +
                           " numbers in the first pose; expected " + kTrajectoryFormats);
}

}  // namespace

TrajectoryFormat detect_trajectory_format(const std::string& path) {
  std::vector<int> lines;
  const auto rows = read_numbers(path, &lines);
  return detect(path, rows, lines);
}

Trajectory read_euroc_csv(const std::string& path) {
  std::vector<int> lines;
  const auto rows = read_numbers(path, &lines);
  Trajectory traj;
  for (size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    const std::string where = path + ":" + std::to_string(lines[i]);
    if (r.size() != rows.front().size() || r.size() < 8)
      throw std::runtime_error(where + ": " + std::to_string(r.size()) + " numbers; a EuRoC CSV row has " +
                               std::to_string(std::max<size_t>(8, rows.front().size())) +
                               " (t[ns], p xyz, q wxyz, ...)");
    if (!is_nanoseconds(r[0])) throw std::runtime_error(where + ": timestamp is not in nanoseconds (EuRoC CSV)");
    const double wxyz[4] = {r[4], r[5], r[6], r[7]};
    const double t[3] = {r[1], r[2], r[3]};
    traj.push_back(r[0] * 1e-9, geometry::SE3::from_wxyz(wxyz, t));
  }
  return traj;
}

Trajectory read_trajectory(const std::string& path, const std::string& kitti_times, TrajectoryFormat* found) {
  std::vector<int> lines;
  const TrajectoryFormat f = detect(path, read_numbers(path, &lines), lines);
  if (found) *found = f;
  switch (f) {
    case TrajectoryFormat::KittiPoses: return read_kitti_poses(path, kitti_times);
    case TrajectoryFormat::EurocCsv: return read_euroc_csv(path);
    case TrajectoryFormat::Tum: break;
  }
  return read_tum(path);
}

Associated associate(const Trajectory& ref, const Trajectory& est, double max_dt) {
  Associated out;
  size_t j = 0;  // both in time order: walk ref alongside est
  for (size_t i = 0; i < est.size(); ++i) {
    const double t = est.stamps[i];
    while (j + 1 < ref.size() && std::abs(ref.stamps[j + 1] - t) <= std::abs(ref.stamps[j] - t)) ++j;
    if (j < ref.size() && std::abs(ref.stamps[j] - t) <= max_dt) {
      if (!out.ref.empty() && out.ref.stamps.back() == ref.stamps[j]) continue;  // each ref pose once
      out.ref.push_back(ref.stamps[j], ref.poses[j]);
      out.est.push_back(est.stamps[i], est.poses[i]);
    }
  }
  if (out.ref.empty())
    throw std::runtime_error("no poses match in time within " + std::to_string(max_dt) +
                             " s (check the timestamps' units and offsets)");
  return out;
}

}  // namespace aerie::eval
