#include "tools/eval/trajectory.hpp"

#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace aerie::eval {
namespace {

std::vector<std::vector<double>> read_numbers(const std::string& path) {
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

Trajectory read_trajectory(const std::string& path) {
  const auto rows = read_numbers(path);
  if (rows.empty()) throw std::runtime_error(path + ": no poses");
  if (rows.front().size() == 12) return read_kitti_poses(path);
  if (rows.front().size() == 8) return read_tum(path);
  throw std::runtime_error(path + ": rows have " + std::to_string(rows.front().size()) +
                           " numbers; expected 8 (TUM) or 12 (KITTI)");
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
