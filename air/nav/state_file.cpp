#include "air/nav/state_file.hpp"

#include <cmath>
#include <sstream>

#include "common/util/files.hpp"

namespace aerie::nav {

namespace {

constexpr const char* kHeader = "aerie-nav state 1";

void put(std::ostream& out, const char* key, const Vec3& v) {
  out << key << ' ' << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
}

bool get(std::istream& in, const char* key, Vec3& v) {
  std::string k;
  return static_cast<bool>(in >> k >> v.x() >> v.y() >> v.z()) && k == key && v.allFinite();
}

bool get_quaternion(std::istream& in, Eigen::Quaterniond& q) {
  return static_cast<bool>(in >> q.w() >> q.x() >> q.y() >> q.z()) && q.coeffs().allFinite() &&
         std::abs(q.norm() - 1.0) < 1e-6;
}

}  // namespace

void write_snapshot(const std::string& path, const Snapshot& s) {
  std::ostringstream out;
  out.precision(17);
  const NominalState& x = s.x;
  out << kHeader << "\nutime " << x.utime << "\nlast_update_utime " << s.last_update_utime << '\n';
  put(out, "p", x.p);
  put(out, "v", x.v);
  out << "q " << x.q.w() << ' ' << x.q.x() << ' ' << x.q.y() << ' ' << x.q.z() << '\n';
  put(out, "bg", x.bg);
  put(out, "ba", x.ba);
  out << 'P';
  for (int i = 0; i < kErrorDim; ++i)
    for (int j = 0; j < kErrorDim; ++j) out << ' ' << s.P(i, j);
  out << "\nT_world_vo";
  if (s.T_world_vo) {
    const Eigen::Quaterniond q = s.T_world_vo->rotation();
    const Vec3 t = s.T_world_vo->translation();
    out << ' ' << q.w() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z() << ' ' << t.x() << ' ' << t.y() << ' ' << t.z();
  } else {
    out << " none";
  }
  out << '\n';
  util::write_file_atomically(path, out.str());
}

std::optional<Snapshot> read_snapshot(const std::string& path, std::string& why) {
  std::string text;
  try {
    text = util::read_regular_file(path, "state file");
  } catch (const std::exception& e) {
    why = e.what();
    return std::nullopt;
  }
  std::istringstream in(text);
  std::string header, k_utime, k_last, k_q, k_P, k_anchor, anchor, rest;
  Snapshot s;
  NominalState& x = s.x;
  std::getline(in, header);
  bool ok = header == kHeader && (in >> k_utime >> x.utime >> k_last >> s.last_update_utime) && k_utime == "utime" &&
            k_last == "last_update_utime" && get(in, "p", x.p) && get(in, "v", x.v) && (in >> k_q) && k_q == "q" &&
            get_quaternion(in, x.q) && get(in, "bg", x.bg) && get(in, "ba", x.ba) && (in >> k_P) && k_P == "P";
  for (int i = 0; ok && i < kErrorDim * kErrorDim; ++i) ok = static_cast<bool>(in >> s.P(i / kErrorDim, i % kErrorDim));
  const double scale = 1.0 + s.P.cwiseAbs().maxCoeff();
  ok = ok && s.P.allFinite() && (s.P.diagonal().array() >= 0.0).all() &&
       (s.P - s.P.transpose()).cwiseAbs().maxCoeff() <= 1e-9 * scale;  // symmetric, as written
  // The rest of the T_world_vo line: "none", or qw qx qy qz x y z.
  ok = ok && (in >> k_anchor) && k_anchor == "T_world_vo" && std::getline(in >> std::ws, anchor);
  if (ok && anchor != "none") {
    std::istringstream a(anchor);
    Eigen::Quaterniond q;
    Vec3 t;
    ok = get_quaternion(a, q) && (a >> t.x() >> t.y() >> t.z()) && t.allFinite() && !(a >> rest);
    if (ok) s.T_world_vo = geometry::SE3(q, t);
  }
  if (!ok || (in >> rest)) {
    why = path + ": not a state file of aerie-nav (" + kHeader + ")";
    return std::nullopt;
  }
  return s;
}

}  // namespace aerie::nav
