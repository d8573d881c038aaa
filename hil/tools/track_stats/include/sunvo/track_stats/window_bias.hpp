#pragma once
// Where a two-frame stereo window's rotation error comes from, frame by frame, measured at the
// ground-truth motion (issue 15: the roll of one-sided frames).
//
// For each pair (k-1, k) the window's problem is built as BundleWindow builds it: base b = k-1
// (fixed), unknowns xi = (phi, dt) of T_k_b (left perturbation in camera k:
// C_k_b = exp(phi) C_gt, t_k_b = t_gt + dt) and the landmarks p_b seen in both frames, residuals
// e = y_hat - y of (u, v, d) in both frames whitened by (sigma_u, sigma_v, sigma_d). The poses are
// held at the truth, every landmark is moved to its own optimum (3 Gauss-Newton steps), pairs with
// any residual over max_residual_px are dropped (the RANSAC inlier test) and the rest weighted by
// the Cauchy loss (IRLS weight 1 / (1 + (r / s)^2)). With the landmarks eliminated (Schur
// complement S of the pose block), one Gauss-Newton step from the truth is
//   dxi = -S^-1 sum_l (J_p^T W e - H_pl H_ll^-1 J_l^T W e),
// linear in e: the first-order error the window makes on this frame. It is split by which
// measurement carries e (the u, v or d rows) and evaluated for hypothetical error fields added to
// exact measurements (a constant vL shift in frame k, a vL shift c / z_k in frame k, a disparity
// bias in both frames), which shows how each maps into roll. sqrt(diag(S^-1)) is the window's
// marginal standard deviation per rotation axis for 1 px noise.
//
// Rotation errors are reported as track_stats does: the rotation vector of
// C_km1_k,true^T C_km1_k,est in camera k, i.e. -phi.

#include <vector>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/features.hpp"
#include "sunvo/core/geometry.hpp"
#include "sunvo/core/status.hpp"

namespace sunvo::track_stats {

struct WindowBiasOptions {
  double sigma_u_px = 1.0;        // px, > 0: as window.sigma_u_px
  double sigma_v_px = 1.0;        // px, > 0
  double sigma_d_px = 1.0;        // px, > 0
  double loss_scale = 2.0;        // whitened units, > 0: Cauchy scale (window.loss_scale)
  double min_disparity_px = 1.0;  // px, > 0: triangulation in k-1 needs this disparity
  double max_residual_px = 5.0;   // px, > 0: a pair with a larger residual is an outlier
  double inject_v_px = -0.127;    // px: constant vL shift of frame k (hypothesis 1)
  double inject_v_z_pxm = -3.6;   // px m: vL shift c / z_k of frame k (hypothesis 2)
  double inject_d_px = -0.3;      // px: disparity bias of both frames (hypothesis 3)
  double inject_k1 = 0.0;  // 1, finite: radial distortion left in every image (hypothesis 4),
                           // (u, v) += (fu x, fv y) k1 (x^2 + y^2), x = (u - cu) / fu, y alike;
                           // 0 = the k1 fitted to the motion residuals (WindowBias::fit_k1)

  Status validate() const;
};

struct FrameWindowBias {
  int landmarks = 0;  // pairs used
  // One-step rotation error from the truth [mdeg], camera k (x pitch, y yaw, z roll).
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  Eigen::Vector3d from_u = Eigen::Vector3d::Zero();      // of it, the u rows
  Eigen::Vector3d from_v = Eigen::Vector3d::Zero();      // the v rows
  Eigen::Vector3d from_d = Eigen::Vector3d::Zero();      // the d rows
  Eigen::Vector3d inject_v = Eigen::Vector3d::Zero();    // hypothesis 1 alone
  Eigen::Vector3d inject_v_z = Eigen::Vector3d::Zero();  // hypothesis 2 alone
  Eigen::Vector3d inject_d = Eigen::Vector3d::Zero();    // hypothesis 3 alone
  Eigen::Vector3d inject_k1 = Eigen::Vector3d::Zero();   // hypothesis 4 alone
  Eigen::Vector3d sigma_mdeg = Eigen::Vector3d::Zero();  // marginal std per axis, 1 px noise
  Eigen::Matrix<double, 6, 6> S = Eigen::Matrix<double, 6, 6>::Zero();  // reduced information
};

// Motion residual (observed - predicted: triangulated in k-1 from its stereo pair, moved by the
// true motion, projected into k) of the pairs whose uL in k-1 falls in [u_min, u_max): the
// image-position dependence that a two-frame window reads as roll when all tracks are on one side.
struct ColumnBin {
  double u_min = 0.0, u_max = 0.0;  // px
  std::size_t n = 0;
  double mean_du = 0.0, mean_dv = 0.0;  // px
};

struct WindowBias {
  std::vector<FrameWindowBias> frames;  // one per frame (frame 0 and frames with < 3 pairs: zeros)
  std::vector<ColumnBin> columns;       // 8 columns over the image width
  // Least-squares fit of the motion residuals (those of the columns) as a radial distortion D
  // of every image (left u, v and right u) plus a shift a + c / z per axis:
  //   r = k1 (D(y1) - M D(y0)) + (a_u + c_u / z, a_v + c_v / z),
  // M = d project(C tri(y0) + t) / d y0 (the distorted y0 moves the triangulated point).
  double fit_k1 = 0.0;
  double fit_a_u_px = 0.0, fit_c_u_pxm = 0.0, fit_a_v_px = 0.0, fit_c_v_pxm = 0.0;
  double rms_before_px = 0.0, rms_after_px = 0.0;  // of the residuals, per component
  double k1_used = 0.0;                            // the k1 of hypothesis 4
};

Expected<WindowBias> computeWindowBias(const StereoCamera& camera,
                                       const std::vector<FrameFeatures>& frames,
                                       const std::vector<Isometry3>& gt_T_0_k,
                                       const WindowBiasOptions& options);

}  // namespace sunvo::track_stats
