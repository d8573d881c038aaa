#include "sunvo/experiment/attitude_oracle.hpp"

namespace sunvo::experiment {

const char* attitudeOracleName(AttitudeOracle which) {
  switch (which) {
    case AttitudeOracle::kTrueAttitude:
      return "Pure VO, true attitude (oracle)";
    case AttitudeOracle::kTrueTilt:
      return "Pure VO, true tilt (oracle)";
    case AttitudeOracle::kTrueHeading:
      return "Pure VO, true heading (oracle)";
  }
  return "Pure VO, oracle";
}

Expected<std::vector<Isometry3>> withTrueAttitude(const std::vector<Isometry3>& T_w_c_vo,
                                                  const std::vector<Isometry3>& T_w_c_gt,
                                                  const Eigen::Vector3d& up_w,
                                                  AttitudeOracle which) {
  if (T_w_c_vo.empty() || T_w_c_vo.size() != T_w_c_gt.size()) {
    return invalidArgument("attitude oracle: " + std::to_string(T_w_c_vo.size()) +
                           " VO poses against " + std::to_string(T_w_c_gt.size()) +
                           " true poses (equal and > 0 needed)");
  }
  if (!(up_w.norm() > 0.0)) return invalidArgument("attitude oracle: the world's up is zero");
  const Eigen::Vector3d u = up_w.normalized();
  std::vector<Isometry3> out(T_w_c_vo.size(), Isometry3::Identity());
  Eigen::Vector3d p_w = T_w_c_vo.front().translation();
  for (std::size_t k = 0; k < T_w_c_vo.size(); ++k) {
    const Eigen::Matrix3d& C_vo = T_w_c_vo[k].linear();
    const Eigen::Vector3d e_w = logSO3(T_w_c_gt[k].linear() * C_vo.transpose());
    const Eigen::Vector3d heading_w = e_w.dot(u) * u;
    Eigen::Vector3d c_w = e_w;
    if (which == AttitudeOracle::kTrueHeading) c_w = heading_w;
    if (which == AttitudeOracle::kTrueTilt) c_w = e_w - heading_w;
    if (k > 0) {
      const Isometry3& prev_vo = T_w_c_vo[k - 1];
      const Eigen::Vector3d t_prev =
          prev_vo.linear().transpose() * (T_w_c_vo[k].translation() - prev_vo.translation());
      p_w += out[k - 1].linear() * t_prev;
    }
    out[k].linear() = expSO3(c_w) * C_vo;
    out[k].translation() = p_w;
  }
  return out;
}

}  // namespace sunvo::experiment
