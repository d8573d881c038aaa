#include "sunvo/track_stats/track_stats.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>

namespace sunvo::track_stats {
namespace {
constexpr double kRadToMdeg = 180.0 / M_PI * 1e3;

struct OffsetSample {
  double du, dv, offset;  // uL - cu, vL - cv, vL - vR
};

// Least-squares plane offset = a + b du + c dv over the samples flagged in `keep`.
Eigen::Vector3d fitPlane(const std::vector<OffsetSample>& s, const std::vector<char>& keep) {
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (!keep[i]) continue;
    const Eigen::Vector3d x(1.0, s[i].du, s[i].dv);
    A += x * x.transpose();
    rhs += x * s[i].offset;
  }
  return A.ldlt().solve(rhs);
}

// Robust plane: fit, drop residuals beyond 4 MAD-sigmas, refit (three rounds).
OffsetPlane robustPlane(const std::vector<OffsetSample>& s, std::size_t pre_rejected) {
  OffsetPlane p;
  std::vector<char> keep(s.size(), 1);
  if (s.size() < 3) return p;
  Eigen::Vector3d x = fitPlane(s, keep);
  std::vector<double> r(s.size());
  for (int round = 0; round < 3; ++round) {
    std::vector<double> absr;
    absr.reserve(s.size());
    for (std::size_t i = 0; i < s.size(); ++i) {
      r[i] = s[i].offset - (x[0] + x[1] * s[i].du + x[2] * s[i].dv);
      absr.push_back(std::abs(r[i]));
    }
    const double sigma = 1.4826 * median(absr);
    for (std::size_t i = 0; i < s.size(); ++i) keep[i] = std::abs(r[i]) <= 4.0 * sigma + 1e-9;
    x = fitPlane(s, keep);
  }
  double ss = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (!keep[i]) continue;
    const double e = s[i].offset - (x[0] + x[1] * s[i].du + x[2] * s[i].dv);
    ss += e * e;
    ++p.used;
  }
  p.a_px = x[0];
  p.b = x[1];
  p.c = x[2];
  p.rms_px = p.used > 0 ? std::sqrt(ss / static_cast<double>(p.used)) : 0.0;
  p.rejected = pre_rejected + (s.size() - p.used);
  return p;
}

double mean(const std::vector<double>& v) {
  if (v.empty()) return 0.0;
  double s = 0.0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

struct MonoObs {
  std::size_t frame;
  const StereoObservation* o;
};

// Disparity error against the depth of a monocular triangulation with the true poses.
void disparityVsDepth(const StereoCamera& cam, const std::vector<FrameFeatures>& frames,
                      const std::vector<Isometry3>& T_0_k, const TrackStatsOptions& opt,
                      TrackStats& out) {
  std::unordered_map<std::int64_t, std::vector<MonoObs>> tracks;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    for (const StereoObservation& o : frames[k].observations)
      tracks[o.landmark_id].push_back({k, &o});
  }
  static constexpr double kEdges[] = {0, 5, 10, 15, 20, 30, 40, 60, 1e9};
  constexpr std::size_t kBins = std::size(kEdges) - 1;
  std::vector<std::vector<double>> bins(kBins);
  constexpr int kFractionBins = 10;  // 0.1 px each over [-0.5, 0.5)
  std::vector<std::vector<double>> fraction_bins(kFractionBins);
  const double min_cos = std::cos(opt.min_parallax_deg * M_PI / 180.0);
  for (const auto& [id, obs] : tracks) {
    if (obs.size() < 3) continue;
    // Least-squares midpoint: minimise sum_i |(I - r_i r_i^T)(p - c_i)|^2 over p (world = camera
    // 0).
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    std::vector<Eigen::Vector3d> rays;
    for (const MonoObs& m : obs) {
      const Isometry3& T = T_0_k[m.frame];
      const Eigen::Vector3d r_c((m.o->u_left - cam.cu) / cam.fu, (m.o->v_left - cam.cv) / cam.fv,
                                1.0);
      const Eigen::Vector3d r_0 = (T.linear() * r_c).normalized();
      const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - r_0 * r_0.transpose();
      A += P;
      b += P * T.translation();
      rays.push_back(r_0);
    }
    double min_dot = 1.0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      for (std::size_t j = i + 1; j < rays.size(); ++j)
        min_dot = std::min(min_dot, rays[i].dot(rays[j]));
    }
    if (min_dot > min_cos) continue;
    const Eigen::Vector3d p_0 = A.ldlt().solve(b);
    if (!p_0.allFinite()) continue;
    bool good = true;
    std::vector<std::array<double, 3>> zd;  // (z_k, d error, d)
    for (const MonoObs& m : obs) {
      const Eigen::Vector3d p_k = T_0_k[m.frame].inverse() * p_0;
      if (!(p_k.z() > 0.5)) {
        good = false;
        break;
      }
      const double u = cam.fu * p_k.x() / p_k.z() + cam.cu;
      const double v = cam.fv * p_k.y() / p_k.z() + cam.cv;
      if (std::hypot(u - m.o->u_left, v - m.o->v_left) > opt.max_mono_reproj_px) {
        good = false;
        break;
      }
      const double d = m.o->disparity();
      zd.push_back({p_k.z(), d - cam.fu * cam.baseline_m / p_k.z(), d});
    }
    if (!good) continue;
    ++out.mono_landmarks;
    for (const auto& [z, e, d] : zd) {
      for (std::size_t i = 0; i < kBins; ++i) {
        if (z >= kEdges[i] && z < kEdges[i + 1]) bins[i].push_back(e);
      }
      const int f = static_cast<int>(std::floor((d - std::round(d) + 0.5) * kFractionBins));
      fraction_bins[static_cast<std::size_t>(std::clamp(f, 0, kFractionBins - 1))].push_back(e);
    }
  }
  for (std::size_t i = 0; i < kBins; ++i) {
    DepthBin bin;
    bin.z_min_m = kEdges[i];
    bin.z_max_m = kEdges[i + 1];
    bin.n = bins[i].size();
    bin.mean_px = mean(bins[i]);
    bin.median_px = median(bins[i]);
    out.depth_bins.push_back(bin);
  }
  for (int i = 0; i < kFractionBins; ++i) {
    auto& v = fraction_bins[static_cast<std::size_t>(i)];
    FractionBin bin;
    bin.f_min = -0.5 + static_cast<double>(i) / kFractionBins;
    bin.f_max = bin.f_min + 1.0 / kFractionBins;
    bin.n = v.size();
    bin.mean_px = mean(v);
    bin.median_px = median(v);
    out.fraction_bins.push_back(bin);
  }
}
}  // namespace

double median(std::vector<double>& v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

Status TrackStatsOptions::validate() const {
  auto in = [](double x, double lo, double hi) { return x >= lo && x <= hi; };
  if (!in(min_disparity_px, 0.0, 100.0)) return invalidArgument("min_disparity_px: [0, 100] px");
  if (!(max_residual_px > 0.0 && max_residual_px <= 100.0)) {
    return invalidArgument("max_residual_px: (0, 100] px");
  }
  if (!(max_offset_px > 0.0 && max_offset_px <= 100.0)) {
    return invalidArgument("max_offset_px: (0, 100] px");
  }
  if (block_frames < 10 || block_frames > 100000)
    return invalidArgument("block_frames: [10, 100000]");
  if (!(min_parallax_deg > 0.0 && min_parallax_deg < 90.0)) {
    return invalidArgument("min_parallax_deg: (0, 90) deg");
  }
  if (!(max_mono_reproj_px > 0.0 && max_mono_reproj_px <= 10.0)) {
    return invalidArgument("max_mono_reproj_px: (0, 10] px");
  }
  if (grid_cols < 1 || grid_cols > 64 || grid_rows < 1 || grid_rows > 64) {
    return invalidArgument("grid_cols, grid_rows: [1, 64]");
  }
  if (!(jump_sigmas > 0.0 && jump_sigmas <= 100.0)) return invalidArgument("jump_sigmas: (0, 100]");
  if (!(jump_min_px >= 0.0 && jump_min_px <= 100.0))
    return invalidArgument("jump_min_px: [0, 100]");
  if (!(jump_rotation_mdeg > 0.0 && jump_rotation_mdeg <= 1e6)) {
    return invalidArgument("jump_rotation_mdeg: (0, 1e6] mdeg");
  }
  return Status::ok();
}

Expected<TrackStats> computeTrackStats(const StereoCamera& cam,
                                       const std::vector<FrameFeatures>& frames,
                                       const std::vector<Isometry3>& T_0_k,
                                       const std::vector<Isometry3>& est_T_0_k,
                                       const TrackStatsOptions& opt) {
  SUNVO_RETURN_IF_ERROR(opt.validate());
  SUNVO_RETURN_IF_ERROR(cam.validate());
  if (T_0_k.size() != frames.size()) {
    return invalidArgument("track stats: " + std::to_string(T_0_k.size()) +
                           " ground-truth poses for " + std::to_string(frames.size()) + " frames");
  }
  if (!est_T_0_k.empty() && est_T_0_k.size() != frames.size()) {
    return invalidArgument("track stats: " + std::to_string(est_T_0_k.size()) +
                           " estimated poses for " + std::to_string(frames.size()) + " frames");
  }
  TrackStats out;
  out.frames.resize(frames.size());
  std::vector<OffsetSample> all;
  std::size_t all_rejected = 0;
  std::unordered_map<std::int64_t, const StereoObservation*> prev;
  std::unordered_map<std::int64_t, std::size_t> first_seen;
  static constexpr int kAgeEdges[] = {0, 1, 2, 3, 4, 6, 9, 13, 21, 41, 1000000};
  constexpr std::size_t kAges = std::size(kAgeEdges) - 1;
  std::vector<double> age_du[kAges], age_dv[kAges], age_off[kAges];
  auto ageBin = [&](std::size_t age) {
    std::size_t i = 0;
    while (i + 1 < kAges && static_cast<int>(age) >= kAgeEdges[i + 1]) ++i;
    return i;
  };
  static constexpr double kZEdges[] = {0, 5, 10, 15, 20, 30, 40, 60, 1e9};
  constexpr std::size_t kZ = std::size(kZEdges) - 1;
  std::vector<double> z_du[kZ], z_dv[kZ];
  Eigen::Matrix3d flow_A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d flow_b = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < frames.size(); ++k) {
    FrameStats& fs = out.frames[k];
    const auto& obs = frames[k].observations;
    fs.tracks = static_cast<int>(obs.size());
    std::vector<char> cell(static_cast<std::size_t>(opt.grid_cols * opt.grid_rows), 0);
    std::vector<double> offsets;
    int left = 0;
    for (const StereoObservation& o : obs) {
      first_seen.try_emplace(o.landmark_id, k);
      if (o.u_left < cam.cu) ++left;
      const int cx =
          std::clamp(static_cast<int>(o.u_left / cam.width * opt.grid_cols), 0, opt.grid_cols - 1);
      const int cy =
          std::clamp(static_cast<int>(o.v_left / cam.height * opt.grid_rows), 0, opt.grid_rows - 1);
      cell[static_cast<std::size_t>(cy * opt.grid_cols + cx)] = 1;
      if (!o.v_right_measured) continue;  // vR is a copy of vL (a written image drive's tracks)
      const double offset = o.v_left - o.v_right;
      if (std::abs(offset) > opt.max_offset_px) {
        ++all_rejected;
        continue;
      }
      offsets.push_back(offset);
      age_off[ageBin(k - first_seen[o.landmark_id])].push_back(offset);
      all.push_back({o.u_left - cam.cu, o.v_left - cam.cv, offset});
    }
    fs.left_share = obs.empty() ? 0.0 : static_cast<double>(left) / static_cast<double>(obs.size());
    fs.cells = static_cast<int>(std::count(cell.begin(), cell.end(), 1));
    fs.mean_offset = mean(offsets);
    if (k > 0) {
      // r = observed(k) - project(T_k_km1 triangulate(k-1)), true motion.
      const Isometry3 T_k_km1 = T_0_k[k].inverse() * T_0_k[k - 1];
      std::vector<double> du, dv, dd;
      for (const StereoObservation& o : obs) {
        const auto it = prev.find(o.landmark_id);
        if (it == prev.end() || it->second->disparity() < opt.min_disparity_px) continue;
        const StereoObservation& q = *it->second;
        const Eigen::Vector3d p_k = T_k_km1 * cam.triangulate(q.u_left, q.v_left, q.disparity());
        if (!(p_k.z() > 0.5)) continue;
        const Eigen::Vector3d pred = cam.project(p_k);
        const double eu = o.u_left - pred.x(), ev = o.v_left - pred.y();
        if (std::abs(eu) > opt.max_residual_px || std::abs(ev) > opt.max_residual_px) continue;
        du.push_back(eu);
        dv.push_back(ev);
        const double z_km1 = cam.fu * cam.baseline_m / q.disparity();
        for (std::size_t i = 0; i < kZ; ++i) {
          if (z_km1 >= kZEdges[i] && z_km1 < kZEdges[i + 1]) {
            z_du[i].push_back(eu);
            z_dv[i].push_back(ev);
          }
        }
        const std::size_t bin = ageBin(k - first_seen[o.landmark_id]);
        age_du[bin].push_back(eu);
        age_dv[bin].push_back(ev);
        // Rows (flow_u, 1, 0) -> eu and (flow_v, 0, 1) -> ev of r = g flow + o.
        const Eigen::Vector3d xu(pred.x() - q.u_left, 1.0, 0.0), xv(pred.y() - q.v_left, 0.0, 1.0);
        flow_A += xu * xu.transpose() + xv * xv.transpose();
        flow_b += xu * eu + xv * ev;
        ++out.flow.n;
        dd.push_back(o.disparity() - pred.z());
      }
      fs.pairs = static_cast<int>(du.size());
      fs.mean_du = mean(du);
      fs.mean_dv = mean(dv);
      fs.mean_dd = mean(dd);
      fs.median_du = median(du);
      fs.median_dv = median(dv);
      if (!est_T_0_k.empty()) {
        // E = (true motion)^-1 (estimated motion), both T_km1_k.
        const Isometry3 gt = T_0_k[k - 1].inverse() * T_0_k[k];
        const Isometry3 est = est_T_0_k[k - 1].inverse() * est_T_0_k[k];
        fs.rot_err_c_mdeg = logSO3(gt.linear().transpose() * est.linear()) * kRadToMdeg;
        fs.rot_err_mdeg = fs.rot_err_c_mdeg.norm();
      }
    }
    prev.clear();
    for (const StereoObservation& o : obs) prev[o.landmark_id] = &o;
  }
  for (std::size_t i = 0; i < kAges; ++i) {
    AgeBin a;
    a.age_min = kAgeEdges[i];
    a.age_max = kAgeEdges[i + 1] - 1;
    a.n = age_du[i].size();
    a.mean_du = mean(age_du[i]);
    a.mean_dv = mean(age_dv[i]);
    a.n_offset = age_off[i].size();
    a.mean_offset = mean(age_off[i]);
    out.ages.push_back(a);
  }
  for (std::size_t i = 0; i < kZ; ++i) {
    out.residual_depths.push_back(
        {kZEdges[i], kZEdges[i + 1], z_du[i].size(), mean(z_du[i]), mean(z_dv[i])});
  }
  if (out.flow.n > 0) {
    const Eigen::Vector3d x = flow_A.ldlt().solve(flow_b);
    out.flow.gain = x[0];
    out.flow.offset_u_px = x[1];
    out.flow.offset_v_px = x[2];
  }
  out.plane = robustPlane(all, all_rejected);
  out.plane.first_frame = 0;
  out.plane.last_frame = static_cast<int>(frames.size()) - 1;
  for (std::size_t b0 = 0; b0 < frames.size(); b0 += static_cast<std::size_t>(opt.block_frames)) {
    const std::size_t b1 = std::min(frames.size(), b0 + static_cast<std::size_t>(opt.block_frames));
    std::vector<OffsetSample> s;
    std::size_t rejected = 0;
    for (std::size_t k = b0; k < b1; ++k) {
      for (const StereoObservation& o : frames[k].observations) {
        if (!o.v_right_measured) continue;
        const double offset = o.v_left - o.v_right;
        if (std::abs(offset) > opt.max_offset_px) {
          ++rejected;
        } else {
          s.push_back({o.u_left - cam.cu, o.v_left - cam.cv, offset});
        }
      }
    }
    OffsetPlane p = robustPlane(s, rejected);
    p.first_frame = static_cast<int>(b0);
    p.last_frame = static_cast<int>(b1) - 1;
    out.blocks.push_back(p);
  }
  disparityVsDepth(cam, frames, T_0_k, opt, out);

  // Jumps: robust outliers of the per-frame mean residual, and large rotation errors.
  std::vector<double> mu, mv;
  for (std::size_t k = 1; k < out.frames.size(); ++k) {
    if (out.frames[k].pairs == 0) continue;
    mu.push_back(out.frames[k].mean_du);
    mv.push_back(out.frames[k].mean_dv);
  }
  auto centre_spread = [](std::vector<double> v) {
    const double m = median(v);
    for (double& x : v) x = std::abs(x - m);
    return std::pair<double, double>(m, 1.4826 * median(v));
  };
  const auto [mu_c, mu_s] = centre_spread(mu);
  const auto [mv_c, mv_s] = centre_spread(mv);
  for (std::size_t k = 1; k < out.frames.size(); ++k) {
    const FrameStats& f = out.frames[k];
    const bool res =
        f.pairs > 0 &&
        (std::abs(f.mean_du - mu_c) > std::max(opt.jump_sigmas * mu_s, opt.jump_min_px) ||
         std::abs(f.mean_dv - mv_c) > std::max(opt.jump_sigmas * mv_s, opt.jump_min_px));
    const bool rot = !est_T_0_k.empty() && f.rot_err_mdeg > opt.jump_rotation_mdeg;
    if (res || rot) out.jumps.push_back({static_cast<int>(k), res, rot});
  }
  return out;
}

}  // namespace sunvo::track_stats
