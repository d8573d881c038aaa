#pragma once
// A sun source for ablations: the true sun direction in the camera frame (from ground truth) with
// a configurable error model, emulating the error statistics of image-based sun estimators.
//
// Angles are taken in the camera frame: azimuth psi = atan2(x, z) in the x-z plane (0 = straight
// ahead, positive to the right) and zenith zeta = acos(-y), measured from the camera's up (-y).
// Errors are drawn per measurement, in order:
//   dropout (no measurement) -> gross outlier (uniform azimuth, zenith uniform over the upper
//   hemisphere) -> shadow ambiguity flip (psi + 180 deg, the bimodal shadow cue) -> Gaussian
//   azimuth and zenith errors, the zenith with a bias (Lalonde's zenith prior skews it), and a
//   constant azimuth offset (an estimator that is wrong the same way on a whole drive: the
//   Sun-CNN on a foreign generator's drive ran at -66 deg for 260 frames, issue 14).
// Optionally the azimuth also carries an error that is correlated from measurement to measurement
// (an image estimator that is wrong the same way along a whole street): a first-order
// Gauss-Markov process b_{i+1} = phi b_i + sqrt(1 - phi^2) sigma_b n_i, phi = exp(-1 / tau), with
// stationary std sigma_b = azimuth_bias_deg and correlation length tau = azimuth_bias_length in
// measurements (dropped frames included). It is drawn from its own generator, so the other draws,
// and every run without it, stay as they were.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <random>

#include "sunvo/core/status.hpp"
#include "sunvo/sunfusion/sun_measurement.hpp"

namespace sunvo::sunfusion {

struct SunErrorModel {
  double azimuth_sigma_deg = 10.0;  // Gaussian azimuth error, [0, 180] deg
  double zenith_sigma_deg = 5.0;    // Gaussian zenith error, [0, 90] deg
  double zenith_bias_deg = 0.0;     // mean zenith error, [-45, 45] deg
  double outlier_share = 0.0;       // share of uniformly random directions, [0, 1]
  double flip_share = 0.0;          // share with azimuth mirrored by 180 deg, [0, 1]
  double dropout_share = 0.0;       // share of frames without a measurement, [0, 1]
  bool azimuth_only = false;        // emit kAzimuthOnly measurements (Sun-CNN)
  double reported_sigma = 0.15;     // sigma written into each measurement (sets R_s), (0, 2]
  double azimuth_bias_deg = 0.0;    // std of the correlated azimuth error, [0, 90] deg; 0 = none
  double azimuth_bias_length = 50;  // its correlation length, [1, 1e6] measurements
  double azimuth_offset_deg = 0.0;  // constant azimuth error of every non-outlier, [-180, 180] deg
  std::uint32_t seed = 1;           // RNG seed

  Status validate() const;
};

class SimulatedSunSource {
 public:
  explicit SimulatedSunSource(const SunErrorModel& model)
      : model_(model), rng_(model.seed), bias_rng_(model.seed ^ 0x5bd1e995u) {}
  // The correlated azimuth error of the last call, rad (0 without one).
  double azimuthBias() const { return bias_; }

  // A measurement for one frame from the true unit sun vector in that camera frame, or nothing
  // (dropout). Consumes random numbers in a fixed pattern, so runs are reproducible.
  std::optional<SunMeasurement> measure(std::uint64_t sequence, TimeNs time_ns,
                                        const Eigen::Vector3d& true_sun_c);

 private:
  SunErrorModel model_;
  std::mt19937_64 rng_;
  std::mt19937_64 bias_rng_;
  double bias_ = 0.0;
  bool bias_started_ = false;
};

// An "up" source for ablations: the true up in the camera (C_c_w up_w) turned by a small random
// rotation, each camera axis N(bias, sigma) (x: pitch, z: roll, y: about up itself, no effect), or
// for an outlier by outlier_deg about a random axis across it, or nothing (dropout). It emulates
// the vertical vanishing point (estimator/vertical), whose measured statistics are in
// docs/vertical.md.
struct VerticalErrorModel {
  double sigma_deg = 1.0;           // per-axis Gaussian error, [0, 30] deg
  double pitch_bias_deg = 0.0;      // mean error about camera x, [-10, 10] deg
  double roll_bias_deg = 0.0;       // mean error about camera z, [-10, 10] deg
  double outlier_share = 0.0;       // share turned by outlier_deg instead, [0, 1]
  double outlier_deg = 8.0;         // [0, 90] deg
  double dropout_share = 0.0;       // share of frames without a measurement, [0, 1]
  double reported_sigma_deg = 1.0;  // sigma written into each measurement, (0, 30] deg
  std::uint32_t seed = 1;           // RNG seed

  Status validate() const;
};

class SimulatedVerticalSource {
 public:
  explicit SimulatedVerticalSource(const VerticalErrorModel& model)
      : model_(model), rng_(model.seed) {}
  // A measurement (kFull3d, sun_c = the measured up) or nothing; fixed draws per call.
  std::optional<SunMeasurement> measure(std::uint64_t sequence, TimeNs time_ns,
                                        const Eigen::Vector3d& true_up_c);

 private:
  VerticalErrorModel model_;
  std::mt19937_64 rng_;
};

// Camera-frame azimuth/zenith (radians) <-> unit vector, as defined above.
Eigen::Vector3d sunFromAzimuthZenith(double azimuth_rad, double zenith_rad);
void azimuthZenithFromSun(const Eigen::Vector3d& sun_c, double& azimuth_rad, double& zenith_rad);

}  // namespace sunvo::sunfusion
