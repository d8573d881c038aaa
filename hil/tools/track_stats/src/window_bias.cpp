#include "sunvo/track_stats/window_bias.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace sunvo::track_stats {
namespace {
constexpr double kRadToMdeg = 180.0 / M_PI * 1e3;
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Mat36 = Eigen::Matrix<double, 3, 6>;
using Vec6 = Eigen::Matrix<double, 6, 1>;

Mat3 skew(const Vec3& v) {
  Mat3 m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// d(u, v, d)/d p_c of Eq. 1.
Mat3 projectionJacobian(const StereoCamera& cam, const Vec3& p) {
  const double iz = 1.0 / p.z();
  Mat3 J;
  J << cam.fu * iz, 0.0, -cam.fu * p.x() * iz * iz, 0.0, cam.fv * iz, -cam.fv * p.y() * iz * iz,
      0.0, 0.0, -cam.fu * cam.baseline_m * iz * iz;
  return J;
}

// One landmark's share of the reduced system: J rows of frame b (landmark only) and of frame k
// (pose and landmark), the weights W = diag(w / sigma^2) per row, and H_ll^-1.
struct PairSystem {
  Mat3 Jl0, Jl1;
  Mat36 Jp1;
  Vec3 W0, W1;
  Mat3 Hll_inv;
  Eigen::Matrix<double, 6, 3> Hpl;
  double z_k = 0.0;
  Vec3 y0, y1;  // the exact observations a distortion would move: predicted from p_b
};

// Pixel displacement of (u, v) and of the right image's u by a radial distortion with k1 = 1.
Vec3 distortion(const StereoCamera& cam, const Vec3& y) {
  const double x = (y.x() - cam.cu) / cam.fu, v = (y.y() - cam.cv) / cam.fv;
  const double xr = (y.x() - y.z() - cam.cu) / cam.fu;
  const double r2 = x * x + v * v, r2r = xr * xr + v * v;
  const double du = cam.fu * r2 * x, dur = cam.fu * r2r * xr;
  return {du, cam.fv * r2 * v, du - dur};  // (u, v, d)
}

// b = J_p^T W e - H_pl H_ll^-1 J_l^T W e for errors e0 (frame b), e1 (frame k).
Vec6 reducedGradient(const PairSystem& s, const Vec3& e0, const Vec3& e1) {
  const Vec3 we0 = s.W0.cwiseProduct(e0), we1 = s.W1.cwiseProduct(e1);
  const Vec3 gl = s.Jl0.transpose() * we0 + s.Jl1.transpose() * we1;
  return s.Jp1.transpose() * we1 - s.Hpl * (s.Hll_inv * gl);
}
}  // namespace

Status WindowBiasOptions::validate() const {
  if (!(sigma_u_px > 0.0) || !(sigma_v_px > 0.0) || !(sigma_d_px > 0.0)) {
    return invalidArgument("window bias: sigma_u_px, sigma_v_px, sigma_d_px must be > 0");
  }
  if (!(loss_scale > 0.0)) return invalidArgument("window bias: loss_scale must be > 0");
  if (!(min_disparity_px > 0.0)) return invalidArgument("window bias: min_disparity_px > 0");
  if (!(max_residual_px > 0.0)) return invalidArgument("window bias: max_residual_px > 0");
  if (!std::isfinite(inject_v_px) || !std::isfinite(inject_v_z_pxm) ||
      !std::isfinite(inject_d_px) || !std::isfinite(inject_k1)) {
    return invalidArgument("window bias: injected errors must be finite");
  }
  return Status::ok();
}

Expected<WindowBias> computeWindowBias(const StereoCamera& cam,
                                       const std::vector<FrameFeatures>& frames,
                                       const std::vector<Isometry3>& gt_T_0_k,
                                       const WindowBiasOptions& opt) {
  SUNVO_RETURN_IF_ERROR(opt.validate());
  SUNVO_RETURN_IF_ERROR(cam.validate());
  if (gt_T_0_k.size() < frames.size()) {
    return invalidArgument("window bias: fewer ground-truth poses than frames");
  }
  const Vec3 sigma(opt.sigma_u_px, opt.sigma_v_px, opt.sigma_d_px);
  const Vec3 info = sigma.cwiseInverse().cwiseAbs2();
  WindowBias result;
  std::vector<FrameWindowBias>& out = result.frames;
  out.resize(frames.size());
  constexpr int kColumns = 8;
  result.columns.resize(kColumns);
  for (int c = 0; c < kColumns; ++c) {
    result.columns[static_cast<std::size_t>(c)].u_min = cam.width * c / double(kColumns);
    result.columns[static_cast<std::size_t>(c)].u_max = cam.width * (c + 1) / double(kColumns);
  }
  Eigen::Matrix<double, 5, 5> fit_A = Eigen::Matrix<double, 5, 5>::Zero();
  Eigen::Matrix<double, 5, 1> fit_b = Eigen::Matrix<double, 5, 1>::Zero();
  double fit_ee = 0.0;
  std::size_t fit_n = 0;
  std::unordered_map<std::int64_t, const StereoObservation*> prev;
  std::vector<PairSystem> pairs;
  std::vector<std::array<Vec3, 2>> errors;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    if (k > 0) {
      const Isometry3 T_k_b = gt_T_0_k[k].inverse() * gt_T_0_k[k - 1];
      const Mat3 C = T_k_b.linear();
      const Vec3 t = T_k_b.translation();
      pairs.clear();
      errors.clear();
      for (const StereoObservation& o1 : frames[k].observations) {
        const auto it = prev.find(o1.landmark_id);
        if (it == prev.end()) continue;
        const StereoObservation& o0 = *it->second;
        const Vec3 y0(o0.u_left, o0.v_left, o0.disparity());
        const Vec3 y1(o1.u_left, o1.v_left, o1.disparity());
        Vec3 p_b;
        if (y0.z() >= opt.min_disparity_px) {
          p_b = cam.triangulate(y0.x(), y0.y(), y0.z());
        } else if (y1.z() >= opt.min_disparity_px) {
          p_b = T_k_b.inverse() * cam.triangulate(y1.x(), y1.y(), y1.z());
        } else {
          continue;
        }
        if (y0.z() >= opt.min_disparity_px) {
          const Vec3 p_k = C * p_b + t;
          const Vec3 r = y1 - cam.project(p_k);
          if (p_k.z() > 1e-3 && std::abs(r.x()) <= opt.max_residual_px &&
              std::abs(r.y()) <= opt.max_residual_px) {
            const int c =
                std::clamp(static_cast<int>(y0.x() / cam.width * kColumns), 0, kColumns - 1);
            ColumnBin& bin = result.columns[static_cast<std::size_t>(c)];
            ++bin.n;
            bin.mean_du += r.x();
            bin.mean_dv += r.y();
            // The residual's change with k1: D moves y1 directly and y0 through the
            // triangulation and the motion, y0 -> project(C tri(y0) + t):
            // d tri / d(u, v, d) = [(z / fu, 0, 0), (0, z / fv, 0), -p / d] (columns).
            Mat3 tri_jac = Mat3::Zero();
            tri_jac(0, 0) = p_b.z() / cam.fu;
            tri_jac(1, 1) = p_b.z() / cam.fv;
            tri_jac.col(2) = -p_b / y0.z();
            const Vec3 g = distortion(cam, cam.project(p_k)) -
                           projectionJacobian(cam, p_k) * C * tri_jac * distortion(cam, y0);
            Eigen::Matrix<double, 5, 1> xu, xv;
            xu << g.x(), 1.0, 1.0 / p_k.z(), 0.0, 0.0;
            xv << g.y(), 0.0, 0.0, 1.0, 1.0 / p_k.z();
            fit_A += xu * xu.transpose() + xv * xv.transpose();
            fit_b += xu * r.x() + xv * r.y();
            fit_ee += r.x() * r.x() + r.y() * r.y();
            ++fit_n;
          }
        }
        // The landmark's own optimum with the poses at the truth.
        bool ok = true;
        for (int it_gn = 0; it_gn < 3 && ok; ++it_gn) {
          const Vec3 p_k = C * p_b + t;
          if (!(p_b.z() > 1e-3) || !(p_k.z() > 1e-3)) {
            ok = false;
            break;
          }
          const Mat3 J0 = projectionJacobian(cam, p_b);
          const Mat3 J1 = projectionJacobian(cam, p_k) * C;
          const Vec3 e0 = cam.project(p_b) - y0, e1 = cam.project(p_k) - y1;
          const Mat3 H =
              J0.transpose() * info.asDiagonal() * J0 + J1.transpose() * info.asDiagonal() * J1;
          const Vec3 g =
              J0.transpose() * info.cwiseProduct(e0) + J1.transpose() * info.cwiseProduct(e1);
          p_b -= H.ldlt().solve(g);
          ok = p_b.allFinite();
        }
        const Vec3 p_k = C * p_b + t;
        if (!ok || !(p_b.z() > 1e-3) || !(p_k.z() > 1e-3)) continue;
        const Vec3 e0 = cam.project(p_b) - y0, e1 = cam.project(p_k) - y1;
        if (e0.cwiseAbs().maxCoeff() > opt.max_residual_px ||
            e1.cwiseAbs().maxCoeff() > opt.max_residual_px) {
          continue;
        }
        PairSystem s;
        s.Jl0 = projectionJacobian(cam, p_b);
        const Mat3 P1 = projectionJacobian(cam, p_k);
        s.Jl1 = P1 * C;
        s.Jp1.leftCols<3>() = -P1 * skew(C * p_b);
        s.Jp1.rightCols<3>() = P1;
        for (int i = 0; i < 3; ++i) {
          const double r0 = e0[i] / sigma[i], r1 = e1[i] / sigma[i];
          s.W0[i] = info[i] / (1.0 + r0 * r0 / (opt.loss_scale * opt.loss_scale));
          s.W1[i] = info[i] / (1.0 + r1 * r1 / (opt.loss_scale * opt.loss_scale));
        }
        const Mat3 Hll = s.Jl0.transpose() * s.W0.asDiagonal() * s.Jl0 +
                         s.Jl1.transpose() * s.W1.asDiagonal() * s.Jl1;
        s.Hll_inv = Hll.inverse();
        s.Hpl = s.Jp1.transpose() * s.W1.asDiagonal() * s.Jl1;
        s.z_k = p_k.z();
        s.y0 = cam.project(p_b);
        s.y1 = cam.project(p_k);
        if (!s.Hll_inv.allFinite()) continue;
        pairs.push_back(s);
        errors.push_back({e0, e1});
      }
      FrameWindowBias& f = out[k];
      if (pairs.size() >= 3) {
        Eigen::Matrix<double, 6, 6> S = Eigen::Matrix<double, 6, 6>::Zero();
        Vec6 b_total = Vec6::Zero(), b_u = Vec6::Zero(), b_v = Vec6::Zero(), b_d = Vec6::Zero();
        Vec6 b_iv = Vec6::Zero(), b_ivz = Vec6::Zero(), b_id = Vec6::Zero(), b_ik = Vec6::Zero();
        for (std::size_t i = 0; i < pairs.size(); ++i) {
          const PairSystem& s = pairs[i];
          S +=
              s.Jp1.transpose() * s.W1.asDiagonal() * s.Jp1 - s.Hpl * s.Hll_inv * s.Hpl.transpose();
          const Vec3& e0 = errors[i][0];
          const Vec3& e1 = errors[i][1];
          b_total += reducedGradient(s, e0, e1);
          for (int c = 0; c < 3; ++c) {
            Vec3 m = Vec3::Zero();
            m[c] = 1.0;
            (c == 0   ? b_u
             : c == 1 ? b_v
                      : b_d) += reducedGradient(s, e0.cwiseProduct(m), e1.cwiseProduct(m));
          }
          // Injected: observation y += x gives e = -x.
          b_iv += reducedGradient(s, Vec3::Zero(), Vec3(0.0, -opt.inject_v_px, 0.0));
          b_ivz += reducedGradient(s, Vec3::Zero(), Vec3(0.0, -opt.inject_v_z_pxm / s.z_k, 0.0));
          b_id += reducedGradient(s, Vec3(0.0, 0.0, -opt.inject_d_px),
                                  Vec3(0.0, 0.0, -opt.inject_d_px));
          // Radial distortion with k1 = 1 in both images (scaled by the k1 used at the end).
          b_ik += reducedGradient(s, -distortion(cam, s.y0), -distortion(cam, s.y1));
        }
        const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(S);
        const Eigen::Matrix<double, 6, 6> S_inv =
            ldlt.solve(Eigen::Matrix<double, 6, 6>::Identity());
        if (ldlt.info() == Eigen::Success && S_inv.allFinite()) {
          // dxi = -S^-1 b; reported rotation error = -phi = S^-1 b (rotation rows).
          auto rot = [&](const Vec6& b) -> Vec3 { return (S_inv * b).head<3>() * kRadToMdeg; };
          f.landmarks = static_cast<int>(pairs.size());
          f.total = rot(b_total);
          f.from_u = rot(b_u);
          f.from_v = rot(b_v);
          f.from_d = rot(b_d);
          f.inject_v = rot(b_iv);
          f.inject_v_z = rot(b_ivz);
          f.inject_d = rot(b_id);
          f.inject_k1 = rot(b_ik);
          for (int a = 0; a < 3; ++a) f.sigma_mdeg[a] = std::sqrt(S_inv(a, a)) * kRadToMdeg;
          f.S = S;
        }
      }
    }
    prev.clear();
    for (const StereoObservation& o : frames[k].observations) prev[o.landmark_id] = &o;
  }
  if (fit_n > 5) {
    const Eigen::Matrix<double, 5, 1> x = fit_A.ldlt().solve(fit_b);
    if (x.allFinite()) {
      result.fit_k1 = x[0];
      result.fit_a_u_px = x[1];
      result.fit_c_u_pxm = x[2];
      result.fit_a_v_px = x[3];
      result.fit_c_v_pxm = x[4];
      // sum (r - X x)^2 = r.r - 2 x.b + x.A x
      const double ss = fit_ee - 2.0 * x.dot(fit_b) + x.dot(fit_A * x);
      result.rms_before_px = std::sqrt(fit_ee / (2.0 * static_cast<double>(fit_n)));
      result.rms_after_px = std::sqrt(std::max(0.0, ss) / (2.0 * static_cast<double>(fit_n)));
    }
  }
  result.k1_used = opt.inject_k1 != 0.0 ? opt.inject_k1 : result.fit_k1;
  for (FrameWindowBias& f : out) f.inject_k1 *= result.k1_used;
  for (ColumnBin& bin : result.columns) {
    if (bin.n == 0) continue;
    bin.mean_du /= static_cast<double>(bin.n);
    bin.mean_dv /= static_cast<double>(bin.n);
  }
  return result;
}

}  // namespace sunvo::track_stats
