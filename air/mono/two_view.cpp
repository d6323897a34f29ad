#include "air/mono/two_view.hpp"

#include <Eigen/SVD>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace aerie::mono {
namespace {

constexpr double kChi2TwoDof = 5.99;  // T_H, and Gamma of both scores
constexpr double kChi2OneDof = 3.84;  // T_F

double score_homography(const cv::Matx33d& H, const std::vector<cv::Point2f>& ref, const std::vector<cv::Point2f>& cur,
                        double inv_sigma2) {
  const cv::Matx33d Hi = H.inv();
  double s = 0;
  auto transfer = [](const cv::Matx33d& M, const cv::Point2f& p) {
    const cv::Vec3d q = M * cv::Vec3d(p.x, p.y, 1.0);
    return cv::Point2d(q[0] / q[2], q[1] / q[2]);
  };
  for (size_t i = 0; i < ref.size(); ++i) {
    const cv::Point2d dc = transfer(H, ref[i]) - cv::Point2d(cur[i]);
    const cv::Point2d dr = transfer(Hi, cur[i]) - cv::Point2d(ref[i]);
    const double c = dc.dot(dc) * inv_sigma2, r = dr.dot(dr) * inv_sigma2;
    if (c < kChi2TwoDof) s += kChi2TwoDof - c;
    if (r < kChi2TwoDof) s += kChi2TwoDof - r;
  }
  return s;
}

double score_fundamental(const cv::Matx33d& F, const std::vector<cv::Point2f>& ref, const std::vector<cv::Point2f>& cur,
                         double inv_sigma2) {
  double s = 0;
  auto line_d2 = [](const cv::Vec3d& l, const cv::Point2f& p) {
    const double n = l[0] * l[0] + l[1] * l[1];
    if (!(n > 0)) return 1e30;
    const double e = l[0] * p.x + l[1] * p.y + l[2];
    return e * e / n;
  };
  for (size_t i = 0; i < ref.size(); ++i) {
    const cv::Vec3d xr(ref[i].x, ref[i].y, 1.0), xc(cur[i].x, cur[i].y, 1.0);
    const double c = line_d2(F * xr, cur[i]) * inv_sigma2;          // x_c to the epipolar line of x_r
    const double r = line_d2(F.t() * xc, ref[i]) * inv_sigma2;      // x_r to that of x_c
    if (c < kChi2OneDof) s += kChi2TwoDof - c;
    if (r < kChi2OneDof) s += kChi2TwoDof - r;
  }
  return s;
}

struct Candidate {
  geometry::SE3 T_cur_ref;
  std::vector<Eigen::Vector3d> points;
  std::vector<bool> good;
  int n_good = 0;
  double median_parallax = 0;
};

Candidate evaluate(const cv::Matx33d& R, const cv::Vec3d& t, const std::vector<cv::Point2f>& ref,
                   const std::vector<cv::Point2f>& cur, const std::vector<uchar>& inlier, const PinholeCamera& cam,
                   const TwoViewParams& p) {
  Candidate c;
  Eigen::Matrix3d Re;
  cv::cv2eigen(cv::Mat(R), Re);
  Eigen::Vector3d te(t[0], t[1], t[2]);
  if (te.norm() > 0) te.normalize();
  c.T_cur_ref = geometry::SE3(Re, te);
  const geometry::SE3 I;
  c.points.assign(ref.size(), Eigen::Vector3d::Zero());
  c.good.assign(ref.size(), false);
  const double max_e2 = p.reprojection_px * p.reprojection_px;
  std::vector<double> parallaxes;
  for (size_t i = 0; i < ref.size(); ++i) {
    if (!inlier[i]) continue;
    Eigen::Vector3d X;
    if (!triangulate(I, c.T_cur_ref, cam.ray(ref[i]), cam.ray(cur[i]), X)) continue;
    const Eigen::Vector3d Xc = c.T_cur_ref * X;
    if (!(X.z() > 0) || !(Xc.z() > 0) || !X.allFinite()) continue;
    const Eigen::Vector2d er = cam.project(X) - Eigen::Vector2d(ref[i].x, ref[i].y);
    const Eigen::Vector2d ec = cam.project(Xc) - Eigen::Vector2d(cur[i].x, cur[i].y);
    if (er.squaredNorm() > max_e2 || ec.squaredNorm() > max_e2) continue;
    const double par = parallax_deg(I, c.T_cur_ref, X);
    parallaxes.push_back(par);
    if (par < p.min_parallax_deg) continue;
    c.points[i] = X;
    c.good[i] = true;
    ++c.n_good;
  }
  if (!parallaxes.empty()) {
    std::nth_element(parallaxes.begin(), parallaxes.begin() + parallaxes.size() / 2, parallaxes.end());
    c.median_parallax = parallaxes[parallaxes.size() / 2];
  }
  return c;
}

}  // namespace

void PinholeCamera::validate(const std::string& what) const {
  if (!(fx > 0) || !(fy > 0) || width <= 0 || height <= 0 || !std::isfinite(cx) || !std::isfinite(cy))
    throw std::invalid_argument(what + ": fx, fy, width and height must be positive, cx and cy finite");
}

void TwoViewParams::validate(const std::string& what) const {
  auto fail = [&](const std::string& key, const std::string& expected) {
    throw std::invalid_argument(what + "." + key + ": expected " + expected);
  };
  if (!(ransac_px > 0)) fail("ransac_px", "> 0");
  if (!(sigma_px > 0)) fail("sigma_px", "> 0");
  if (!(homography_ratio > 0 && homography_ratio < 1)) fail("homography_ratio", "in (0, 1)");
  if (!(min_parallax_deg > 0 && min_parallax_deg < 45)) fail("min_parallax_deg", "in (0, 45)");
  if (!(reprojection_px > 0)) fail("reprojection_px", "> 0");
  if (min_points < 8) fail("min_points", ">= 8");
  if (!(ambiguity > 0 && ambiguity <= 1)) fail("ambiguity", "in (0, 1]");
}

const char* to_string(Model m) {
  switch (m) {
    case Model::None: return "none";
    case Model::Homography: return "homography";
    case Model::Essential: return "essential";
  }
  return "?";
}

bool triangulate(const geometry::SE3& T1, const geometry::SE3& T2, const Eigen::Vector3d& r1, const Eigen::Vector3d& r2,
                 Eigen::Vector3d& X) {
  Eigen::Matrix<double, 3, 4> P1, P2;
  P1 << T1.rotation_matrix(), T1.translation();
  P2 << T2.rotation_matrix(), T2.translation();
  Eigen::Matrix4d A;
  A.row(0) = r1.x() * P1.row(2) - P1.row(0);
  A.row(1) = r1.y() * P1.row(2) - P1.row(1);
  A.row(2) = r2.x() * P2.row(2) - P2.row(0);
  A.row(3) = r2.y() * P2.row(2) - P2.row(1);
  const Eigen::JacobiSVD<Eigen::Matrix4d> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d h = svd.matrixV().col(3);
  if (std::abs(h[3]) < 1e-12) return false;
  X = h.head<3>() / h[3];
  return X.allFinite();
}

double parallax_deg(const geometry::SE3& T1, const geometry::SE3& T2, const Eigen::Vector3d& X) {
  const Eigen::Vector3d c1 = T1.inverse().translation(), c2 = T2.inverse().translation();
  const Eigen::Vector3d a = (X - c1).normalized(), b = (X - c2).normalized();
  return std::acos(std::clamp(a.dot(b), -1.0, 1.0)) * 180.0 / M_PI;
}

TwoViewResult initialise_two_view(const std::vector<cv::Point2f>& ref, const std::vector<cv::Point2f>& cur,
                                  const PinholeCamera& cam, const TwoViewParams& p) {
  TwoViewResult res;
  if (ref.size() != cur.size()) throw std::invalid_argument("initialise_two_view: ref and cur differ in size");
  if (static_cast<int>(ref.size()) < p.min_points) {
    res.reason = std::to_string(ref.size()) + " matches, " + std::to_string(p.min_points) + " needed";
    return res;
  }
  const cv::Matx33d K = cam.K();
  std::vector<uchar> mask_h, mask_e;
  const cv::Mat H = cv::findHomography(ref, cur, cv::RANSAC, p.ransac_px, mask_h, 2000, 0.999);
  const cv::Mat E = cv::findEssentialMat(ref, cur, cv::Mat(K), cv::RANSAC, 0.999, p.ransac_px, mask_e);
  const double inv_sigma2 = 1.0 / (p.sigma_px * p.sigma_px);
  if (!H.empty()) res.score_h = score_homography(cv::Matx33d(H), ref, cur, inv_sigma2);
  cv::Matx33d E3;
  if (E.rows == 3 && E.cols == 3) {  // findEssentialMat stacks several solutions; the first is its best
    E3 = cv::Matx33d(E);
    const cv::Matx33d Ki = K.inv();
    res.score_f = score_fundamental(Ki.t() * E3 * Ki, ref, cur, inv_sigma2);
  }
  if (res.score_h + res.score_f <= 0) {
    res.reason = "neither a homography nor an essential matrix fits";
    return res;
  }
  res.ratio_h = res.score_h / (res.score_h + res.score_f);
  res.model = res.ratio_h > p.homography_ratio ? Model::Homography : Model::Essential;

  std::vector<Candidate> cands;
  if (res.model == Model::Homography) {
    std::vector<cv::Mat> Rs, ts, ns;
    cv::decomposeHomographyMat(H, cv::Mat(K), Rs, ts, ns);
    for (size_t k = 0; k < Rs.size(); ++k)
      cands.push_back(evaluate(cv::Matx33d(Rs[k]), cv::Vec3d(ts[k]), ref, cur, mask_h, cam, p));
  } else {
    cv::Mat R1, R2, t;
    cv::decomposeEssentialMat(cv::Mat(E3), R1, R2, t);
    for (const cv::Mat& R : {R1, R2})
      for (double sign : {1.0, -1.0}) cands.push_back(evaluate(cv::Matx33d(R), sign * cv::Vec3d(t), ref, cur, mask_e, cam, p));
  }
  std::sort(cands.begin(), cands.end(), [](const Candidate& a, const Candidate& b) { return a.n_good > b.n_good; });
  if (cands.empty()) {
    res.reason = std::string(to_string(res.model)) + " has no decomposition";
    return res;
  }
  const Candidate& best = cands.front();
  res.median_parallax_deg = best.median_parallax;
  res.n_good = best.n_good;
  if (best.n_good < p.min_points) {
    res.reason = std::string(to_string(res.model)) + ": " + std::to_string(best.n_good) +
                 " points with parallax >= " + std::to_string(p.min_parallax_deg) + " deg (median " +
                 std::to_string(best.median_parallax) + " deg), " + std::to_string(p.min_points) + " needed";
    return res;
  }
  if (cands.size() > 1 && cands[1].n_good >= p.ambiguity * best.n_good) {
    res.reason = std::string(to_string(res.model)) + ": ambiguous decomposition (" + std::to_string(best.n_good) +
                 " vs " + std::to_string(cands[1].n_good) + " points)";
    return res;
  }
  res.ok = true;
  res.T_cur_ref = best.T_cur_ref;
  res.points = best.points;
  res.good = best.good;
  return res;
}

}  // namespace aerie::mono
