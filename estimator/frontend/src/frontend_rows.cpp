// correct_edge_columns: the row-offset field of a rig whose rectification is slightly off, and the
// columns of the matches that lie along edges.
//
// Row offset. A right camera turned by small angles moves a right-image point's row by
//   v_R - v_L = a + b x + c y,   x = (u - cu) / fu, y = (v - cv) / fv,
// to first order: a from the pitch about x (fv * pitch), b from the roll about the optical axis
// (-fv * roll), c from a vertical scale; the yaw's x y term (0.026 px at the corners for 0.01 deg)
// is left out. The front end measures the row of every match whose window is not an edge
// (measureRightRow); this plane is fitted to those rows by least squares with forgetting (each
// frame's rows weigh 1 - 1/row_offset_memory_frames less per later frame), rows further than a
// gate from the previous plane left out.
//
// Edge columns. A match whose window is an edge (all gradients g = (g_u, g_v) one way) has its
// column from the parabola along the left row v_L (refineStereo). The right image's point lies on
// row v_L + dv (dv the plane's row offset there); its edge crosses row v_L where moving along the
// edge (g_u du + g_v dv' = 0) by dv' = -dv takes it: u' = u_R + (g_v / g_u) dv. So a rig whose rows
// are off by dv puts a sideways error s dv on every slanted edge's disparity, s = g_v / g_u, which
// a rig correction of the tracks cannot take out (it depends on the texture). The column is moved
// back, u_R = u' - s dv, with s the window's least-squares slope a12 / a11 = S g_u g_v / S g_u^2:
// the Lucas-Kanade step of measureRightRow with the row held at dv (a11 du + a12 dv = b1) gives the
// same. Edges flatter than kMaxEdgeSlope are left as they are: there the row does not fix the
// column.
//
// Measured, and why it is off by default: docs/edge_columns.md.

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "sunvo/frontend/stereo_frontend.hpp"

namespace sunvo {
namespace {
constexpr double kMaxEdgeSlope = 2.0;    // |g_v / g_u| at most (edges 27 deg or more from level)
constexpr double kRowGateStartPx = 2.5;  // px: gate without a plane (rows are measured <= 2 px)
constexpr double kRowGateSigmas = 3.0;   // gate: this many rms of the plane's residuals ...
constexpr double kRowGateMinPx = 0.3;    // px: ... but never tighter than this
constexpr double kMinRowWeight = 30.0;   // rows (decayed) before the plane is used
}  // namespace

void StereoFrontend::correctEdgeColumns(FrameFeatures& out) {
  const auto n = out.observations.size();
  const auto plane = [this](double x, double y) {
    return row_plane_[0] + row_plane_[1] * x + row_plane_[2] * y;
  };
  // Adds this frame's measured rows within `gate` px of the current plane (or of 0 without one)
  // to the decayed normal equations; returns how many it took and counts the measured ones.
  const auto addRows = [&](double gate, int* measured) {
    int used = 0;
    *measured = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const StereoObservation& o = out.observations[i];
      if (!o.v_right_measured) continue;
      ++*measured;
      const double x = (o.u_left - camera_.cu) / camera_.fu;
      const double y = (o.v_left - camera_.cv) / camera_.fv;
      const double r = o.v_right - o.v_left;
      const double e = r - (row_plane_valid_ ? plane(x, y) : 0.0);
      if (!(std::abs(e) <= gate)) continue;
      row_ata_[0] += 1.0;
      row_ata_[1] += x;
      row_ata_[2] += y;
      row_ata_[3] += x * x;
      row_ata_[4] += x * y;
      row_ata_[5] += y * y;
      row_atb_[0] += r;
      row_atb_[1] += x * r;
      row_atb_[2] += y * r;
      row_weight_ += 1.0;
      row_sse_ += e * e;
      ++used;
    }
    return used;
  };
  const auto forgetAll = [this](double keep) {
    for (double& a : row_ata_) a *= keep;
    for (double& b : row_atb_) b *= keep;
    row_weight_ *= keep;
    row_sse_ *= keep;
  };

  forgetAll(1.0 - 1.0 / options_.row_offset_memory_frames);
  const double rms = row_weight_ > 0.0 ? std::sqrt(row_sse_ / row_weight_) : 0.0;
  const double gate =
      row_plane_valid_ ? std::max(kRowGateMinPx, kRowGateSigmas * rms) : kRowGateStartPx;
  int measured = 0;
  int used = addRows(gate, &measured);
  // Most of this frame's rows far from the plane: the rig moved (a knock) or the plane was
  // wrong. Start again from this frame alone.
  if (row_plane_valid_ && measured >= kMinRowWeight && 2 * used < measured) {
    forgetAll(0.0);
    row_plane_valid_ = false;
    stats_.row_offset_restarted = true;
    used = addRows(kRowGateStartPx, &measured);
  }
  stats_.row_offset_rows_used = used;
  if (row_weight_ >= kMinRowWeight) {
    Eigen::Matrix3d ata;
    ata << row_ata_[0], row_ata_[1], row_ata_[2], row_ata_[1], row_ata_[3], row_ata_[4],
        row_ata_[2], row_ata_[4], row_ata_[5];
    const Eigen::Vector3d atb(row_atb_[0], row_atb_[1], row_atb_[2]);
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(ata);
    const Eigen::Vector3d p = ldlt.solve(atb);
    if (ldlt.info() == Eigen::Success && ldlt.isPositive() && p.allFinite()) {
      row_plane_ = {p[0], p[1], p[2]};
      row_plane_valid_ = true;
    }
  }
  stats_.row_offset_a_px = row_plane_[0];
  stats_.row_offset_b_px = row_plane_[1];
  stats_.row_offset_c_px = row_plane_[2];
  if (!row_plane_valid_) return;

  for (std::size_t i = 0; i < n; ++i) {
    const float s = edge_slope_[i];
    if (!std::isfinite(s) || std::abs(static_cast<double>(s)) > kMaxEdgeSlope) continue;
    StereoObservation& o = out.observations[i];
    const double dv =
        plane((o.u_left - camera_.cu) / camera_.fu, (o.v_left - camera_.cv) / camera_.fv);
    const double u_right = o.u_right - static_cast<double>(s) * dv;
    const double disparity = o.u_left - u_right;
    if (!(disparity >= options_.min_disparity) || !(disparity <= options_.max_disparity)) continue;
    o.u_right = u_right;
    ++stats_.edge_columns_moved;
  }
}

}  // namespace sunvo
