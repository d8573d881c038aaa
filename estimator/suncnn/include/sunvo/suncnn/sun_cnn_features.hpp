#pragma once
// How strong the sun cues are that Sun-CNN's trunk found in an image, measured against the
// training images' features (docs/sun_cnn_calibration.md, "Distance from the training features").
//
// Per member m, the trunk's F features x_m (dropout off) are projected on the P principal axes
// a_mp of the training images' features, about their mean mu_m, and whitened by the axes'
// variances s_mp:
//   d = (1 / M) sum_m (1 / P) sum_p ((x_m - mu_m) . a_mp)^2 / s_mp     (about 1 on training images)
// Images with weak cues (a blank wall, a street wholly in shade) give features near the mean:
// d < 1. On the validation renders the gross errors have the smallest d; images of looks the
// network never saw do not have a larger d (so d is no out-of-distribution detector). The
// estimator adds feature_gain * max(0, -ln d) to its squared raw spread: weak features widen
// sigma, strong or unusual ones never narrow it.
//
// The prior is fitted by estimator/suncnn/training/sun_cnn_calibrate.py on the training renders
// and shipped in the model's JSON ("feature_prior"; for grey images on a colour model,
// "gray_input"."feature_prior").
#include <vector>

#include "sunvo/core/status.hpp"

namespace sunvo::suncnn {

struct SunCnnFeaturePrior {
  int components = 0;             // P, principal axes per member, [1, features]; 0: no prior
  int features = 0;               // F, trunk features per member (the model's mask1 size)
  std::vector<double> mean;       // [M F], member after member
  std::vector<double> axes;       // [M P F], member after member, axis after axis (unit rows)
  std::vector<double> variances;  // [M P], > 0
  bool empty() const { return components == 0; }
  int members() const { return empty() || features == 0 ? 0 : int(mean.size()) / features; }
  // Sizes against the model (members, features), finite numbers, positive variances; `key`
  // names the JSON key in the message ("feature_prior").
  Status validate(int members, int features, const char* key) const;
  // d of the header for one member's trunk output (F values), summed over members by the
  // caller: (1 / P) sum_p ((x - mu_m) . a_mp)^2 / s_mp.
  double memberDistance(int member, const float* x) const;
};

// max(0, -ln d); d <= 1e-12 counts as 1e-12.
double featureWeakness(double distance);

}  // namespace sunvo::suncnn
