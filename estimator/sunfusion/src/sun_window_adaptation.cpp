// How SunWindowTerm's attitude random walk follows the measurements (the rules of the header
// comment of sun_window_term.hpp): adaptDrift and the persistence and evidence sums it keeps.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "sunvo/sunfusion/persistence_statistic.hpp"
#include "sunvo/sunfusion/sun_window_term.hpp"

namespace sunvo::sunfusion {
namespace {
constexpr double kDeg = M_PI / 180.0;
}  // namespace

void SunWindowTerm::adaptDrift(const Innovation& inn, const Eigen::Matrix3d& C_w_b, int channel) {
  const int m = inn.dof;
  double step = 0.0;
  switch (options_.drift_adaptation) {
    case DriftAdaptation::kFixed:
      return;
    case DriftAdaptation::kInnovationMedian: {
      // With a consistent filter the NIS is chi-square with m dof and exceeds its median half of
      // the time: a stochastic approximation of the median, one step per measurement.
      const double median = m <= 1 ? 0.455 : (m == 2 ? 1.386 : 2.366);
      step = inn.nis > median ? options_.drift_adaptation_rate : -options_.drift_adaptation_rate;
      break;
    }
    case DriftAdaptation::kEvidence:
      accumulate(inn, C_w_b, &persistence_I_, &persistence_g_, options_.evidence_forgetting);
      persistence_T_ = inflateToEvidence(persistence_I_, persistence_g_);
      return;
    case DriftAdaptation::kPersistence: {
      // H = errorJacobian: r ~ H dtheta_w, dtheta_w the world-frame attitude error. If dtheta_w
      // stayed constant while the filter ignores it, the whitened innovations r_i ~ N(H_i dtheta_w,
      // I) and the least-squares estimate from all of them, I^+ g with g = sum H_i^T r_i and I =
      // sum H_i^T H_i, has the chi-square statistic T = g^T I^+ g with rank(I) dof when dtheta_w =
      // 0 (noise only). The sums forget by persistence_forgetting per measurement, so T weighs the
      // recent drift; a Huber weight caps an outlier's pull at persistence_huber sigmas per row.
      // Once the vertical channel steps the tilt's walk (split below), the sums forget on its
      // answers only: a sun answer between two of them would halve the memory of the cue's evidence
      // the tilt's test reads.
      const bool forget = !(splitByGravity() && channel == 0 && vertical_in_sums_);
      accumulate(inn, C_w_b, &persistence_I_, &persistence_g_,
                 forget ? options_.persistence_forgetting : 1.0);
      std::size_t rank = 0;
      persistence_T_ = sunfusion::persistenceStatistic(persistence_I_, persistence_g_, &rank);
      step = rank > 0 && persistence_T_ > persistence_bound_[rank]
                 ? options_.persistence_step_up
                 : -options_.persistence_step_down;
      if (splitByGravity()) {
        // Each walk steps with the channel that measures it. The heading's on the sun's
        // measurements, from sums of the sun's alone: an "up" never sees the heading. The tilt's,
        // once a vertical measurement is in the sums, on the vertical channel's, up to that
        // channel's cap, on the tilt's part of the test of all channels' sums
        // (tiltPersistenceStatistic): a sun beside it that informs the tilt little (an
        // azimuth-only 15 deg beside a 0.1 deg "up") neither dilutes the test, nor holds the walk
        // to the sun's cap, nor steps it a second time per frame on the cue's evidence. Without
        // vertical measurements the sun steps both walks on the same test, as one.
        if (channel == 1 && tiltByEvidence()) {
          // P's tilt part is made to cover the error the cue's answers evidence, and q_tilt
          // stays at the floor: no walk to trail a steady drift.
          vertical_in_sums_ = true;
          accumulate(inn, C_w_b, &vertical_I_, &vertical_g_, options_.evidence_forgetting);
          inflateToEvidence(vertical_I_, vertical_g_);
          drift_deg_per_frame_ = options_.min_drift_deg_per_frame;
        } else if (channel == 1 && tiltByLikelihood()) {
          // The walk the cue's innovations make most likely (walk_bank.hpp), an outlier's pull
          // capped as in the sums. With a bias axis the bank sees the answer as it came: the
          // innovation at c = 0 is r + J_up c_removed (J_up = d r / d c).
          vertical_in_sums_ = true;
          Eigen::Matrix3d H;
          Eigen::Vector3d r_as_came;
          Eigen::Matrix<double, 3, 2> H_c;
          const int rows = bankAnswer(inn, C_w_b, &H, &r_as_came, &H_c);
          tilt_bank_.update(H, H_c, r_as_came, rows);
          drift_deg_per_frame_ = bankTiltDrift();
        } else if (channel == 1) {
          vertical_in_sums_ = true;
          std::size_t tilt_rank = 0;
          const double T_tilt =
              tiltPersistenceStatistic(persistence_I_, persistence_g_, worldUp(), &tilt_rank);
          const double step_t = tilt_rank > 0 && T_tilt > persistence_bound_[tilt_rank]
                                    ? options_.persistence_step_up
                                    : -options_.persistence_step_down;
          drift_deg_per_frame_ =
              stepDrift(drift_deg_per_frame_, step_t, options_.vertical_max_drift_deg_per_frame);
        } else if (!vertical_in_sums_) {
          drift_deg_per_frame_ = clampDrift(drift_deg_per_frame_ * std::exp(step));
        }
        if (headingByLikelihood()) {
          // Both channels feed the heading's bank, each answer as the fusion took it (a bias taken
          // out of the cue's stays out; the sun's has none). The sun's answers choose its walk,
          // as the tilt's above; it is fed from the first one but chooses only once the cue takes
          // the tilt: before that the tilt's error in the sun's innovations fires the persistence
          // test, which then holds both walks up (docs/vertical.md, "the heading's walk"), and
          // the bank would read it as heading. The cue's answers tell its members the tilt, at
          // the noise scale the tilt's bank reads (the reported sigma under the other tilt rules).
          Innovation fused = inn;
          fused.up_bias_removed.setZero();
          Eigen::Matrix3d H;
          Eigen::Vector3d r;
          Eigen::Matrix<double, 3, 2> H_c;
          const int rows = bankAnswer(fused, C_w_b, &H, &r, &H_c);
          if (channel == 0) {
            heading_bank_.update(H, r, rows);
          } else {
            heading_bank_.absorb(H, r, rows, tiltByLikelihood() ? tilt_bank_.noiseScale() : 1.0);
          }
        }
        if (channel == 0 && headingByLikelihood() && vertical_in_sums_) {
          heading_drift_deg_per_frame_ =
              std::clamp(heading_bank_.walk() / kDeg, options_.min_drift_deg_per_frame,
                         options_.max_drift_deg_per_frame);
        } else if (channel == 0) {
          accumulate(inn, C_w_b, &sun_I_, &sun_g_, options_.persistence_forgetting);
          std::size_t sun_rank = 0;
          const double T = sunfusion::persistenceStatistic(sun_I_, sun_g_, &sun_rank);
          const double step_h = sun_rank > 0 && T > persistence_bound_[sun_rank]
                                    ? options_.persistence_step_up
                                    : -options_.persistence_step_down;
          heading_drift_deg_per_frame_ =
              clampDrift(heading_drift_deg_per_frame_ * std::exp(step_h));
        }
        return;
      }
      break;
    }
  }
  drift_deg_per_frame_ = clampDrift(drift_deg_per_frame_ * std::exp(step));
}

double SunWindowTerm::clampDrift(double q) const {
  return std::clamp(q, options_.min_drift_deg_per_frame, options_.max_drift_deg_per_frame);
}

double SunWindowTerm::stepDrift(double q, double step, double cap) const {
  const double next = q * std::exp(step);
  const double upper = step > 0.0 ? std::max(cap, q) : next;
  return std::max(std::min(next, upper), options_.min_drift_deg_per_frame);
}

double SunWindowTerm::bankTiltDrift() const {
  return std::clamp(tilt_bank_.walk() / kDeg, options_.min_drift_deg_per_frame,
                    options_.vertical_max_drift_deg_per_frame);
}

bool SunWindowTerm::tiltByEvidence() const {
  return splitByGravity() &&
         options_.vertical_drift_adaptation == VerticalDriftAdaptation::kEvidence;
}

bool SunWindowTerm::tiltByLikelihood() const {
  return splitByGravity() &&
         options_.vertical_drift_adaptation == VerticalDriftAdaptation::kLikelihood;
}

bool SunWindowTerm::headingByLikelihood() const {
  return splitByGravity() &&
         options_.heading_drift_adaptation == HeadingDriftAdaptation::kLikelihood;
}

int SunWindowTerm::bankAnswer(const Innovation& inn, const Eigen::Matrix3d& C_w_b,
                              Eigen::Matrix3d* H, Eigen::Vector3d* r,
                              Eigen::Matrix<double, 3, 2>* H_c) const {
  // With the cue's bias axis the bank sees the answer as it came: the innovation at c = 0 is
  // r + J_up c_removed (J_up = d r / d c; zero for the sun's answers).
  *H = errorJacobian(inn.J, C_w_b);
  *r = huberWeight(inn) * (inn.r + inn.J_up * inn.up_bias_removed);
  *H_c = inn.J_up;
  if (inn.radial.squaredNorm() == 0.0) return inn.dof;
  // The rows across the measured direction (the whitened residual's radial direction is the
  // measured one, W s = s / sigma).
  const Eigen::Vector3d t1 = inn.radial.unitOrthogonal();
  Eigen::Matrix3d Q;
  Q << t1, inn.radial.cross(t1), inn.radial;
  *H = Q.transpose() * *H;
  *r = Q.transpose() * *r;
  *H_c = Q.transpose() * *H_c;
  return 2;
}

double SunWindowTerm::huberWeight(const Innovation& inn) const {
  const double cap = options_.persistence_huber * std::sqrt(static_cast<double>(inn.dof));
  const double norm = inn.r.head(inn.dof).norm();
  return norm > cap ? cap / norm : 1.0;
}

void SunWindowTerm::accumulate(const Innovation& inn, const Eigen::Matrix3d& C_w_b,
                               Eigen::Matrix3d* I, Eigen::Vector3d* g, double lambda) const {
  // Fixed-size, with the rows past m zero (no heap allocation).
  const int m = inn.dof;
  Eigen::Matrix3d J = inn.J;
  Eigen::Vector3d r = inn.r;
  J.bottomRows(3 - m).setZero();
  r.tail(3 - m).setZero();
  const Eigen::Matrix3d H = errorJacobian(J, C_w_b);
  *g = lambda * *g + H.transpose() * (huberWeight(inn) * r);
  *I = lambda * *I + H.transpose() * H;
}

double SunWindowTerm::inflateToEvidence(const Eigen::Matrix3d& I, const Eigen::Vector3d& g) {
  // Along each well-informed direction v of I: e = v^T g / l estimates the error left, with
  // variance 1/l under noise alone. A significant e that P does not cover (v^T P v < e^2) widens P
  // along v to e^2, so that the following measurements may remove it; P never shrinks here.
  // Directions with less than a tenth of the strongest information are left alone: an
  // azimuth-only source barely informs some, and a few outliers would make e large there.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(I);
  const double floor = 0.1 * std::max(eig.eigenvalues().maxCoeff(), 1e-300);
  double T = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double l = eig.eigenvalues()(i);
    if (!(l > floor)) continue;
    const Eigen::Vector3d v = eig.eigenvectors().col(i);
    const double e = v.dot(g) / l;
    T += e * e * l;
    const double deficit = e * e - v.dot(P() * v);
    const double bound = options_.evidence_sigmas * options_.evidence_sigmas;
    if (e * e * l > bound * options_.evidence_correlation && deficit > 0.0 &&
        std::isfinite(deficit)) {
      P() += deficit * v * v.transpose();
      ++num_inflations_;
    }
  }
  return T;
}

}  // namespace sunvo::sunfusion
