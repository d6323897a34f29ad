#pragma once
// Reads OctoMap's example scan (bz2 text "x y z" per line), decompressing at run time.
#include <Eigen/Core>

#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace aerie::map::bench {

inline std::vector<Eigen::Vector3f> read_bz2_xyz(const std::string& path) {
  const std::string cmd = "bzip2 -dc '" + path + "'";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(cmd.c_str(), "r"), pclose);
  if (!pipe) throw std::runtime_error("cannot run: " + cmd);
  std::vector<Eigen::Vector3f> points;
  float x, y, z;
  while (std::fscanf(pipe.get(), "%f %f %f", &x, &y, &z) == 3) points.emplace_back(x, y, z);
  if (points.empty()) throw std::runtime_error("no points read from " + path);
  return points;
}

}  // namespace aerie::map::bench
