// The window's non-holonomic rows (WindowOptions::lateral_prior_sigma_m_s and
// vertical_prior_sigma_m_s; MotionPriorResidual; docs/lateral_prior.md, docs/vertical_prior.md):
// their per-frame stds and the directions of travel they are built around, learnt from the solved
// steps. Part of BundleWindow, kept apart from bundle_window.cpp by topic.
#include <algorithm>
#include <cmath>

#include "sunvo/backend/bundle_window.hpp"

namespace sunvo::backend {

// Each row's std: the vehicle's own velocity across its body axis over dt, widened by what the
// model's parameters leave open for this step (t_z and, sideways, psi of the initial guess): a
// mount known to within its std, and a lever arm known to within its std. The slopes (beta, gamma)
// are 0 until learnt; the mount's turn is in the std either way. A row is left out of a frame
// with a track nearer than its *_prior_near_m (depth fu b / d from the track's disparity d).
bool BundleWindow::setTravelRows(double dt_s, const Isometry3& T_k_km1_guess,
                                 std::span<const WindowObservation> obs,
                                 MotionPriorData& prior) const {
  const bool lateral_on = options_.lateral_prior_sigma_m_s > 0.0;
  const bool vertical_on = options_.vertical_prior_sigma_m_s > 0.0;
  if (!(dt_s > 0.0) || !(lateral_on || vertical_on)) return false;
  const double mount_rad = options_.lateral_mount_sigma_deg * M_PI / 180.0;
  const double t_z = T_k_km1_guess.translation().z();
  // The nearest track's disparity, px: looked at only when an active row has a near rule.
  double d_max = 0.0;
  if ((lateral_on && options_.lateral_prior_near_m > 0.0) ||
      (vertical_on && options_.vertical_prior_near_m > 0.0)) {
    for (const WindowObservation& o : obs) d_max = std::max(d_max, o.y.d);
  }
  // Whether no track is nearer than near_m (0 = no condition).
  const auto noneNearer = [&](double near_m) {
    return near_m <= 0.0 || d_max * near_m <= model_.fu * model_.baseline_m;
  };
  // A row whose slope is learnt (a ring with capacity, from *_frames) stays out until the slope
  // is (TravelDirection::ready): held to a slope of 0 meanwhile, a camera pitched or turned
  // against the travel would have its steps pulled towards 0, and those steps are the samples the
  // slope is learnt from. Without a ring the slope is 0 by choice and the row acts at once.
  const auto slopeKnown = [](const TravelDirection& slope) {
    return slope.capacity() == 0 || slope.ready();
  };
  bool any = false;
  if (lateral_on && slopeKnown(travel_x_) && noneNearer(options_.lateral_prior_near_m)) {
    const double s_lat =
        std::hypot(options_.lateral_prior_sigma_m_s * dt_s, mount_rad * t_z,
                   options_.lateral_lever_sigma_m * logSO3(T_k_km1_guess.linear()).y());
    if (s_lat > 0.0 && std::isfinite(s_lat)) {
      prior.lateral_beta = travel_x_.beta();
      prior.lateral_lever_m = options_.lateral_lever_m;
      prior.sqrt_info_lateral = 1.0 / s_lat;
      any = true;
    }
  }
  if (vertical_on && slopeKnown(travel_y_) && noneNearer(options_.vertical_prior_near_m)) {
    const double s_vert = std::hypot(options_.vertical_prior_sigma_m_s * dt_s, mount_rad * t_z);
    if (s_vert > 0.0 && std::isfinite(s_vert)) {
      prior.vertical_gamma = travel_y_.beta();
      prior.sqrt_info_vertical = 1.0 / s_vert;
      any = true;
    }
  }
  return any;
}

// One sample of each direction of travel per solved step T_k_km1 = [C | t], phi = log(C)
// (TravelDirection): the rows solved for their slopes,
//   beta = (t_x - psi (t_z / 2 + L)) / t_z,  gamma = (t_y + theta t_z / 2) / t_z,
// psi = phi_y, theta = phi_x. Only steps with |t_z| >= sigma dt / tan(sigma_mount) count (sigma the
// row's velocity std): on a shorter one the vehicle's own velocity across its axis hides a turn of
// the mount as large as its std, and t_z near 0 makes the ratio noise.
void BundleWindow::updateTravelDirection(double dt_s, const Eigen::Vector3d& t,
                                         const Eigen::Vector3d& phi) {
  const double tan_mount =
      std::tan(std::max(options_.lateral_mount_sigma_deg, 0.01) * M_PI / 180.0);
  if (travel_x_.capacity() > 0 &&
      std::abs(t.z()) >= options_.lateral_prior_sigma_m_s * dt_s / tan_mount) {
    travel_x_.push((t.x() - phi.y() * (0.5 * t.z() + options_.lateral_lever_m)) / t.z());
  }
  if (travel_y_.capacity() > 0 &&
      std::abs(t.z()) >= options_.vertical_prior_sigma_m_s * dt_s / tan_mount) {
    travel_y_.push((t.y() + 0.5 * phi.x() * t.z()) / t.z());
  }
}

}  // namespace sunvo::backend
