#pragma once
// The tilt's random walk chosen by the likelihood of the vertical cue's innovations over a small
// bank of walks (multiple-model adaptive estimation; fusion.vertical_drift_adaptation likelihood).
//
// VO's tilt error e (world-frame rotation vector, normal to the world's up; the truth is Exp(e)
// times the estimate) is modelled as a random walk, e_{k+1} = e_k + w_k,
// w_k ~ N(0, q^2 (I - u u^T)) per frame. Which q is right differs
// tenfold between routes and cue sources (docs/vertical.md), and a walk stepped on a test trails
// a steady drift. The cue's reported sigma is not exact either (on rendered drives 100 % of its
// errors lie within 2 sigma, on real frames 36-60 %), and a filter's gain depends on the ratio of
// the walk to the noise, so both are chosen together. Each member (j, i) of the bank is a Kalman
// filter of e with its own walk q_j and noise scale s_i (both log-spaced over their ranges; the
// answer's true std is s_i times the reported one) fed the same answers: an answer whose
// whitened innovation at the current estimate is r = H e + n (H = d r / d e, m rows) has under
// the member
//   the prediction H x, the innovation covariance S = H P H^T + s_i^2 I,
//   log-likelihood l <- lambda l - (nu^T S^-1 nu + log det S) / 2, nu = r - H x,
//   and the update x += K nu, P -= K H P, K = P H^T S^-1.
// The members track the error of the estimate the fusion keeps, so when the fusion corrects the
// estimate by c_w every x becomes x - c_w (a known input: the members stay exact filters).
// lambda < 1 forgets old answers, so the bank follows a drive whose drift changes. Weights
// w proportional to exp(l) times a prior 1/q_j (not forgotten): the fusion starts near the slow
// end (0.0043 deg/frame over the default ranges; 0.0045 with the cap at 0.05) and a faster walk
// must be earned, as the persistence rule's walk sinks under noise alone. q and s are scales,
// averaged in their logarithms. The fusion weighs each answer with its reported sigma, so the walk
// it is given keeps the chosen member's ratio of walk to noise: walk() = exp(E[log q - log s]) (the
// same gain as the filter with the chosen walk and the true noise). A walk too slow leaves
// innovations that persist, one too fast pays for its wide S, and a noise scale is told from the
// walk by how the innovations correlate from answer to answer.
//
// The cue's own error may stay alike for a whole drive (a pitch bias of 0.02-0.10 deg on renders,
// docs/fusion_bias.md), which a filter of e alone reads as VO's drift and follows. With
// up_bias_scales > 1 the bank has a third axis: each member also carries the cue's bias, a turn
// c = (c_x, c_z) of its "up" about the camera's x and z axes (sun_residual.hpp,
// turnAboutCameraXZ), Gauss-Markov with std sigma_l and correlation length up_bias_length_frames,
// sigma_l in {0, then halving down from up_bias_max_rad} (0.2 deg, 4 scales: 0, 0.05, 0.1, 0.2).
// A member's state is x = (e, c) and an answer's whitened innovation at c = 0
//   r = H e + H_c c + n,  H_c = W [s_k]x, columns x and z
// (W the answer's square-root information, s_k the predicted up in the camera: the turn moves
// the measured up by c x s_k). VO's tilt error stays in the world and c in the camera, so the two
// come apart as the route turns; on a straight road they look alike and the prior keeps c at 0
// (sigma 0 as likely as all the others together). The bank's c is the mixture of its members'
// (mean weighted by the posterior), which the fusion may take out of the answers before they
// are fused (two-stage bias estimation: the members see the answers as they came).
//
// The same bank chooses the heading's walk from the sun's answers (heading = true,
// SunFusionOptions::heading_drift_adaptation): the walk is then about up, w_k ~ N(0, q^2 u u^T),
// and the tilt, which the sun's answers see too, walks by the fusion's own tilt walk in every
// member (propagate's other_q), so that no member reads the tilt's moves as heading; once the cue
// measures, the members take its answers in too (absorb), so that the tilt left in the sun's rows
// they judge is the tilt the fusion has left. Fixed-size, no allocation.

#include <Eigen/Core>
#include <array>
#include <optional>

#include "sunvo/core/status.hpp"

namespace sunvo::sunfusion {

struct WalkBankOptions {
  double q_min_rad = 0.0;          // rad/frame, > 0: the slowest walk
  double q_max_rad = 0.0;          // rad/frame, >= q_min_rad: the fastest
  int walks = 6;                   // [2, kMaxWalks]
  double noise_min = 1.0;          // > 0: the smallest noise scale (true / reported std)
  double noise_max = 1.0;          // >= noise_min
  int noise_scales = 1;            // [1, kMaxScales]; 1 = noise_min (the reported sigma if 1)
  double initial_sigma_rad = 0.0;  // rad, > 0: every member's start std per axis
  double forgetting = 0.99;        // (0, 1]: of the log-likelihoods, per answer
  int up_bias_scales = 1;          // [1, kMaxBiasScales]; 1 = no bias axis (c is no state)
  double up_bias_max_rad = 0.0;    // rad, > 0 with up_bias_scales > 1: the widest bias std
  double up_bias_length_frames = 2500.0;  // frames, [1, 1e7]: the bias's correlation length
  // The walk's axis: false = the tilt (the plane normal to up, the cue's bank), true = the
  // heading (about up, the sun's bank; SunFusionOptions::heading_drift_adaptation).
  bool heading = false;
};

class WalkBank {
 public:
  static constexpr int kMaxWalks = 8;
  static constexpr int kMaxScales = 8;
  static constexpr int kMaxBiasScales = 4;
  using BiasJacobian = Eigen::Matrix<double, 3, 2>;

  Status init(const WalkBankOptions& options);
  // frames have passed: each P grows by q_j^2 frames on its walk's subspace (the plane normal to
  // up, or up itself for a heading bank) and by other_q^2 frames (rad per frame: the fusion's walk
  // there) on the other one, so that a member is not sure of what it does not choose.
  void propagate(double frames, const Eigen::Vector3d& up, double other_q = 0.0);
  // One answer: m (1..3) whitened rows r (at the current estimate, c = 0), H = d r / d e (world)
  // and H_c its dependence on the cue's bias c (ignored without a bias axis).
  void update(const Eigen::Matrix3d& H, const BiasJacobian& H_c, const Eigen::Vector3d& r, int m);
  void update(const Eigen::Matrix3d& H, const Eigen::Vector3d& r, int m) {
    update(H, BiasJacobian::Zero(), r, m);
  }
  // An answer of the other channel (the cue's, for a heading bank): every member's e takes in its
  // m whitened rows with noise std s, as the fusion does; the likelihoods are left as they are,
  // so the walk is chosen by this bank's own channel's answers while its members know the tilt the
  // fusion knows. A bias axis is not informed (the rows are taken at c = 0).
  void absorb(const Eigen::Matrix3d& H, const Eigen::Vector3d& r, int m, double s);
  // The estimate was corrected by the world rotation vector c_w.
  void shift(const Eigen::Vector3d& c_w);
  // The error the members have been explaining was removed from outside (a levelled start): every
  // member starts again from e = 0 with covariance P_e (the fusion's, after the removal), its bias
  // at its prior and its likelihood at the prior's. Answers that saw the removed error would
  // otherwise keep the fast walks that followed it chosen long after (docs/vertical_height.md).
  void restart(const Eigen::Matrix3d& P_e);
  // The walk for a fusion that weighs the answers by their reported sigma, exp(E[log q - log s]),
  // rad per frame.
  double walk() const;
  double tiltWalk() const;    // exp(E[log q]), rad per frame
  double noiseScale() const;  // exp(E[log s])
  // The cue's bias c (rad) and its std per axis, the mixture over the members; zero without a
  // bias axis.
  Eigen::Vector2d upBias() const;
  Eigen::Vector2d upBiasSigma() const;
  bool hasUpBias() const { return biases_ > 1; }
  int members() const { return walks_ * scales_ * biases_; }
  double weight(int member) const;  // sums to 1 over the members

 private:
  static constexpr int kMax = kMaxWalks * kMaxScales * kMaxBiasScales;
  using State = Eigen::Matrix<double, 5, 1>;  // (e, c)
  using Covariance = Eigen::Matrix<double, 5, 5>;
  // Member k = (j * scales_ + i) * biases_ + l: walk j, noise scale i, bias std l.
  std::size_t walkOf(int k) const { return static_cast<std::size_t>(k / (scales_ * biases_)); }
  std::size_t scaleOf(int k) const { return static_cast<std::size_t>((k / biases_) % scales_); }
  std::size_t biasOf(int k) const { return static_cast<std::size_t>(k % biases_); }
  // Every member's Kalman update by one answer: with its own noise scale and its likelihood
  // counted (update), or with the other channel's noise std other_s and the likelihood left
  // (absorb).
  void updateMembers(const Eigen::Matrix3d& H, const BiasJacobian& H_c, const Eigen::Vector3d& r,
                     int m, std::optional<double> other_s);
  double mean(bool walk_part, bool noise_part) const;
  double logPosterior(int member) const;
  double maxLogPosterior() const;  // over the members, for weights without overflow
  // Each member's posterior weight, unnormalised (the largest is 1, no overflow); returns their
  // sum. The one loop behind weight(), the means and the bias's mixture.
  double posteriorWeights(std::array<double, kMax>* w) const;
  int walks_ = 0;
  int scales_ = 0;
  int biases_ = 1;
  double forgetting_ = 1.0;
  double bias_length_ = 2500.0;
  bool heading_ = false;
  std::array<double, kMaxWalks> log_q_{};
  std::array<double, kMaxScales> log_s_{};
  std::array<double, kMaxBiasScales> bias_sigma_{};  // rad
  std::array<double, kMax> loglik_{};
  std::array<State, kMax> x_{};
  std::array<Covariance, kMax> P_{};
};

}  // namespace sunvo::sunfusion
