#pragma once
// What any attitude source could take off a run: VO's own steps re-chained with the true world
// attitude (all of it, only its tilt, or only its heading). The fusion moves a run's position only
// through its attitude (docs/fusion_ceiling.md: a fused run re-chained this way ends within
// 0.05 m of itself), so these oracle runs bound what a sun or a vertical cue can gain on a route.
//
// Re-chaining: VO's step k-1 -> k in its previous camera, t_k = C_vo,k-1^T (p_vo,k - p_vo,k-1), is
// laid into the world by the corrected attitude of frame k-1:
//   p_k = p_k-1 + C_k-1 t_k,   p_0 = p_vo,0,
//   C_k = Exp(c_k) C_vo,k with e_k = Log(C_gt,k C_vo,k^T) the world attitude error and
//   c_k = e_k (true attitude), (e_k . u) u (true heading: the error about the world's up u),
//   e_k - (e_k . u) u (true tilt: the error across it).
// The split of e_k into an about-up and an across-up part is that of scripts/fusion_ceiling.py,
// which computes the same oracles from pose files.
#include <vector>

#include "sunvo/core/geometry.hpp"
#include "sunvo/core/status.hpp"

namespace sunvo::experiment {

enum class AttitudeOracle { kTrueAttitude, kTrueTilt, kTrueHeading };

// The oracle name as a table row: "Pure VO, true attitude (oracle)" and so on.
const char* attitudeOracleName(AttitudeOracle which);

// VO's poses T_w_c_vo re-chained with the part `which` of the true attitude of T_w_c_gt (same
// frames, same world; up_w the world's up, any length > 0). Error when the sizes differ, a list
// is empty or up_w is zero.
Expected<std::vector<Isometry3>> withTrueAttitude(const std::vector<Isometry3>& T_w_c_vo,
                                                  const std::vector<Isometry3>& T_w_c_gt,
                                                  const Eigen::Vector3d& up_w,
                                                  AttitudeOracle which);

}  // namespace sunvo::experiment
