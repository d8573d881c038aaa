#include "sunvo/simtracks/simulated_tracks.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

namespace sunvo::simtracks {
namespace {

Status rangeError(const char* key, const char* range) {
  return invalidArgument(std::string("simtracks.") + key + " out of range " + range);
}

struct Landmark {
  Eigen::Vector3d p_w;
  std::size_t created_at = 0;  // index of the pose it was placed around
  std::int64_t track_id = -1;  // current id while tracked, -1 when not tracked
  std::size_t last_seen = 0;   // last frame that observed it (valid when track_id >= 0)
};

}  // namespace

Status SimTrackOptions::validate() const {
  if (!(landmarks_per_metre > 0.0 && landmarks_per_metre <= 200.0)) {
    return rangeError("landmarks_per_metre", "(0, 200]");
  }
  if (!(facade_min_lateral_m >= 1.0 && facade_min_lateral_m <= 50.0)) {
    return rangeError("facade_min_lateral_m", "[1, 50]");
  }
  if (!(facade_max_lateral_m > facade_min_lateral_m && facade_max_lateral_m <= 100.0)) {
    return rangeError("facade_max_lateral_m", "(facade_min_lateral_m, 100]");
  }
  if (!(max_height_above_camera_m >= 0.0 && max_height_above_camera_m <= 50.0)) {
    return rangeError("max_height_above_camera_m", "[0, 50]");
  }
  if (!(camera_height_m >= 0.2 && camera_height_m <= 5.0)) {
    return rangeError("camera_height_m", "[0.2, 5]");
  }
  if (!(ground_share >= 0.0 && ground_share <= 1.0)) return rangeError("ground_share", "[0, 1]");
  if (!(max_depth_m > 1.0 && max_depth_m <= 200.0)) return rangeError("max_depth_m", "(1, 200]");
  if (!(min_depth_m > 0.0 && min_depth_m < max_depth_m)) {
    return rangeError("min_depth_m", "(0, max_depth_m)");
  }
  if (!(pixel_noise_px >= 0.0 && pixel_noise_px <= 10.0)) {
    return rangeError("pixel_noise_px", "[0, 10]");
  }
  if (!(outlier_share >= 0.0 && outlier_share <= 0.9))
    return rangeError("outlier_share", "[0, 0.9]");
  if (!(mean_track_length >= 2.0 && mean_track_length <= 1000.0)) {
    return rangeError("mean_track_length", "[2, 1000]");
  }
  if (max_features_per_frame < 10 || max_features_per_frame > 5000) {
    return rangeError("max_features_per_frame", "[10, 5000]");
  }
  return Status::ok();
}

Expected<std::vector<FrameFeatures>> simulateTracks(const std::vector<Isometry3>& T_w_c,
                                                    const std::vector<TimeNs>& times_ns,
                                                    const StereoCamera& camera,
                                                    const SimTrackOptions& options) {
  SUNVO_RETURN_IF_ERROR(options.validate());
  SUNVO_RETURN_IF_ERROR(camera.validate());
  if (T_w_c.size() < 2) return invalidArgument("simulateTracks: need at least 2 poses");
  if (!times_ns.empty() && times_ns.size() != T_w_c.size()) {
    return invalidArgument("simulateTracks: times_ns and T_w_c differ in length");
  }
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, options.pixel_noise_px);

  // 1. Landmarks around the path: placed relative to the pose nearest to each metre of travel,
  //    in that camera's frame (x right, y down, z forward), then mapped to the world.
  std::vector<Landmark> landmarks;
  double carry = 0.0;
  for (std::size_t k = 1; k < T_w_c.size(); ++k) {
    const double step = (T_w_c[k].translation() - T_w_c[k - 1].translation()).norm();
    carry += step * options.landmarks_per_metre;
    while (carry >= 1.0) {
      carry -= 1.0;
      Eigen::Vector3d p_c;
      const double side = unit(rng) < 0.5 ? -1.0 : 1.0;
      const double along = (unit(rng) - 0.5) * 2.0 / std::max(options.landmarks_per_metre, 1.0);
      if (unit(rng) < options.ground_share) {
        p_c = {side * (0.5 + unit(rng) * (options.facade_min_lateral_m - 0.5)),
               options.camera_height_m, along};
      } else {
        const double lateral =
            options.facade_min_lateral_m +
            unit(rng) * (options.facade_max_lateral_m - options.facade_min_lateral_m);
        const double height =
            unit(rng) * (options.max_height_above_camera_m + options.camera_height_m);
        p_c = {side * lateral, options.camera_height_m - height, along};
      }
      landmarks.push_back({T_w_c[k] * p_c, k, -1, 0});
    }
  }

  // 2. Observations per frame. Landmarks are stored in creation order, so the candidates of frame
  //    j are those created around poses [j - back, j + ahead]; a window in path length bounds it.
  std::vector<FrameFeatures> frames(T_w_c.size());
  std::int64_t next_id = 0;
  const double stop_prob = 1.0 / options.mean_track_length;
  std::vector<std::pair<double, std::size_t>> visible;  // (depth, landmark index)
  std::size_t first = 0;
  for (std::size_t j = 0; j < T_w_c.size(); ++j) {
    const Isometry3 T_c_w = T_w_c[j].inverse();
    const Eigen::Vector3d c_w = T_w_c[j].translation();
    // Skip landmarks created far behind (more than max depth of path behind this pose).
    while (first < landmarks.size() &&
           (T_w_c[landmarks[first].created_at].translation() - c_w).norm() >
               2.0 * options.max_depth_m &&
           landmarks[first].created_at < j) {
      ++first;
    }
    visible.clear();
    for (std::size_t i = first; i < landmarks.size(); ++i) {
      const Landmark& lm = landmarks[i];
      if (lm.created_at > j &&
          (T_w_c[lm.created_at].translation() - c_w).norm() > 1.5 * options.max_depth_m) {
        break;
      }
      const Eigen::Vector3d p_c = T_c_w * lm.p_w;
      if (p_c.z() < options.min_depth_m || p_c.z() > options.max_depth_m) continue;
      const Eigen::Vector3d y = camera.project(p_c);
      const double u_right = y.x() - y.z();
      if (y.x() < 0.0 || y.x() >= camera.width || y.y() < 0.0 || y.y() >= camera.height ||
          u_right < 0.0) {
        continue;
      }
      visible.emplace_back(p_c.z(), i);
    }
    // Keep the nearest features (best conditioned, like a detector keeping strong corners).
    if (visible.size() > static_cast<std::size_t>(options.max_features_per_frame)) {
      std::nth_element(visible.begin(), visible.begin() + options.max_features_per_frame,
                       visible.end());
      visible.resize(static_cast<std::size_t>(options.max_features_per_frame));
    }
    std::sort(visible.begin(), visible.end(),
              [](const auto& a, const auto& b) { return a.second < b.second; });
    FrameFeatures& out = frames[j];
    out.sequence = j;
    out.time_ns = times_ns.empty() ? static_cast<TimeNs>(j) * (kNsPerSecond / 10) : times_ns[j];
    out.observations.reserve(visible.size());
    for (const auto& [depth, i] : visible) {
      Landmark& lm = landmarks[i];
      // A track continues only from the previous frame and only while it survives.
      const bool continues = lm.track_id >= 0 && lm.last_seen + 1 == j && unit(rng) >= stop_prob;
      if (!continues) lm.track_id = next_id++;
      lm.last_seen = j;
      const Eigen::Vector3d y = camera.project(T_c_w * lm.p_w);
      StereoObservation obs;
      obs.landmark_id = lm.track_id;
      if (unit(rng) < options.outlier_share) {
        // A gross mismatch: anywhere in the image, disparity of a 5-40 m point.
        obs.u_left = unit(rng) * (camera.width - 1);
        obs.v_left = unit(rng) * (camera.height - 1);
        const double d = camera.fu * camera.baseline_m / (5.0 + 35.0 * unit(rng));
        obs.u_right = obs.u_left - d;
        obs.v_right = obs.v_left;
      } else {
        obs.u_left = y.x() + noise(rng);
        obs.v_left = y.y() + noise(rng);
        obs.u_right = y.x() - y.z() + noise(rng);
        obs.v_right = obs.v_left;
      }
      out.observations.push_back(obs);
    }
  }
  return frames;
}

}  // namespace sunvo::simtracks
