#pragma once
// Sun-CNN: the sun's azimuth in the camera x-z plane from one image, with a per-image
// uncertainty from a deep ensemble and Monte-Carlo dropout (after Ma, Kelly et al.'s Sun-CNN and
// Peretroukhin's Sun-BCNN). The networks are trained by estimator/suncnn/training/ on
// domain-randomised renders and shipped as config/sun_cnn.onnx (colour) and
// config/sun_cnn_gray.onnx (grey cameras), each with a JSON whose numbers the defaults repeat.
//
// The ONNX graph has three inputs and one output:
//   image [1, C, H, W]  BGR (C = 3) or grey (C = 1), (pixel / 255 - pixel_mean) / pixel_std,
//                       resized with INTER_AREA (grey from colour: BT.601 luma after the resize)
//   mask1 [K, F], mask2 [K, D]  inverted-dropout masks of the two fully connected layers
//                              (entries 0 or 1 / (1 - p); a row of ones = dropout off)
//   azimuth_cs [M K, 2]         row m K + k: member m's answer under mask row k,
//                               (c, s) ~ (cos az, sin az), az = atan2(sun_x, sun_z)
// Each member's trunk runs once, its head K times (one row per mask pair), so N MC samples per
// member cost one forward pass. This class draws the masks itself (seeded, reproducible): row 0
// is all ones (the deterministic answer), rows 1..N are dropout samples, the rest are unused.
//
// Answer and uncertainty. v = the mean of the M members' deterministic outputs; az = atan2(v).
// Two mean resultant lengths in [0, 1], turned into circular standard deviations sqrt(-2 ln R)
// and added in quadrature:
//   R_mc = |mean of the M N unit sample directions|  (model uncertainty: members that disagree
//          and dropout spread; the out-of-distribution signal)
//   R_al = |v|  (data ambiguity: each net is trained with the squared chord loss, whose
//          minimiser is E[(cos az, sin az) | image], so an image with no sun cue is answered
//          with a short vector; members that disagree shorten the mean as well)
// and a third term from the sun's elevation e, known from the ephemeris (the prior: sin e =
// sun_c . up_c): the higher the sun, the shorter the shadows and the less the image says about
// its azimuth, which the spread alone misses (docs/sun_cnn_calibration.md):
//   sigma = clamp(sigma_scale * sqrt(-2 ln R_mc - 2 ln R_al + elevation_gain tan^2 e'),
//                 sigma_min_rad, sigma_max_rad),   e' = min(e, 85 deg), tan e' = 0 for e <= 0
// (no prior: no elevation term), and a fourth from how weak the trunk's features are against the
// training images' (sun_cnn_features.hpp): + feature_gain max(0, -ln d) under the root, where the
// model's JSON has a feature prior (none: no term). elevation_gain, feature_gain, sigma_scale and
// max_valid_sigma_rad are chosen on the validation renders (held-out styles).
//
// The library opens no file but the model, and only when init() is given a path.

#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <opencv2/dnn/dnn.hpp>
#include <random>
#include <string>
#include <vector>

#include "sunvo/core/status.hpp"
#include "sunvo/suncnn/sun_cnn_features.hpp"
#include "sunvo/sunfusion/image_sun_estimator.hpp"

namespace sunvo::suncnn {

struct SunCnnOptions {
  int input_width = 208;        // network input width, px, must match the model, [16, 2048]
  int input_height = 64;        // network input height, px, must match the model, [16, 2048]
  double pixel_mean = 0.5;      // input normalisation (pixel / 255 - mean) / std, [0, 1]
  double pixel_std = 0.25;      // (0, 10]
  int input_channels = 3;       // 3: BGR model, 1: grey model, must match the model, {1, 3}
  int ensemble_members = 3;     // M, members in the model's output, must match, [1, 16]
  int mask_rows = 32;           // K, rows of the exported head, must match the model, [2, 1024]
  int mask1_size = 768;         // F, features into the first FC layer, must match, [1, 1e6]
  int mask2_size = 128;         // D, hidden units into the second FC layer, must match, [1, 1e6]
  double dropout_p = 0.3;       // dropout probability used in training, [0, 0.9]
  int mc_samples = 16;          // N, MC dropout samples per image, [0, mask_rows - 1]; 0: R_mc = 1
  double sigma_scale = 0.4896;  // calibration factor on the spread sigma, (0, 100]; fitted
                                // on the validation renders (config/sun_cnn.json)
  double sigma_min_rad = 0.03;  // floor of the reported sigma, rad, [0, 1]
  double sigma_max_rad = 3.0;   // cap of the reported sigma, rad, [sigma_min_rad, 10]
  double max_valid_sigma_rad = 0.4802;  // above this the estimate is returned with
                                        // valid = false, rad, (0, 10]; chosen on the validation
                                        // renders (config/sun_cnn.json)
  // The same two numbers for a grey image fed to a colour model as (Y, Y, Y) (grey V4L2 or
  // KITTI cameras 0/1): its answers are a little less sure than on colour images, so they get
  // their own calibration, chosen on the validation renders' grey luma (config/sun_cnn.json,
  // "gray_input"). A JSON without that section gives them the colour values. Unused by a grey
  // model (input_channels 1).
  double gray_sigma_scale = 0.7983;          // (0, 100]
  double gray_max_valid_sigma_rad = 0.6352;  // rad, (0, 10]
  // Weight of tan^2 of the sun's elevation in the squared raw spread (header comment), rad^2,
  // [0, 100]; 0: off. The JSON's "elevation_gain" (and gray_input's for grey images); a JSON
  // without the key was calibrated without the term, so it means 0.
  double elevation_gain = 0.01;
  double gray_elevation_gain = 0.0;
  // Weight of the features' weakness max(0, -ln d) in the squared raw spread, rad^2, [0, 100];
  // 0: off. It applies only with a prior (the JSON's "feature_prior", gray_input's for grey
  // images; the defaults have none, so without the JSON the term is 0). A JSON without
  // "feature_gain" means 0.
  double feature_gain = 0.3;
  double gray_feature_gain = 0.0;
  SunCnnFeaturePrior feature_prior;       // fitted on the training renders; empty: no term
  SunCnnFeaturePrior gray_feature_prior;  // the same for grey images on a colour model
  double max_up_tilt_deg = 30.0;  // valid = false when the prior's "up" is further than this
                                  // from the camera's -y (the azimuth is in the x-z plane), deg,
                                  // [0, 90]; ignored without a prior
  std::uint64_t seed = 1;         // RNG of the dropout masks
  Status validate() const;        // names the bad key ("suncnn.mc_samples ...")
};

// The JSON the training script writes beside a model (<model>.json): the input size and
// channels, ensemble members, mask sizes, dropout, sigma_scale, max_valid_sigma_rad and
// elevation_gain, feature_gain and feature_prior (and for a colour model gray_input's), over
// `base` (keys it lacks keep base's values). Errors name the file and the key.
Expected<SunCnnOptions> loadSunCnnOptions(const std::string& json_path,
                                          const SunCnnOptions& base = {});
// "dir/name.onnx" -> "dir/name.json".
std::string modelJsonPath(const std::string& model_path);
// The options of the model at model_path: its JSON's when there is one beside it, else the
// defaults (the shipped colour model's).
Expected<SunCnnOptions> optionsForModel(const std::string& model_path);

// The raw network answer for one image, before the uncertainty is turned into a measurement.
struct SunCnnRaw {
  double c = 0.0, s = 0.0;         // deterministic output (dropout off)
  double r_mc = 1.0;               // mean resultant length of the MC sample directions, [0, 1]
  double r_al = 0.0;               // length of the deterministic output, clamped to [0, 1]
  double feature_distance = -1.0;  // d (sun_cnn_features.hpp); -1 without a feature prior
  double feature_weakness = 0.0;   // max(0, -ln d); 0 without a feature prior
  double elevation_tan2 = 0.0;     // tan^2 of the prior's sun elevation (capped at 85 deg), 0
                                   // below the horizon or without a prior
  double sigma_rad = 0.0;          // after scale and clamp
  bool gray_calibration = false;   // a grey image on a colour model: the gray_* numbers applied
};

class SunCnnEstimator : public sunfusion::ImageSunEstimator {
 public:
  SunCnnEstimator() = default;
  SunCnnEstimator(const SunCnnEstimator&) = delete;
  SunCnnEstimator& operator=(const SunCnnEstimator&) = delete;

  // Loads the model from an ONNX file or from its bytes, allocates the buffers and checks the
  // model's shapes against the options with one forward pass. Errors name the option or file.
  Status init(const SunCnnOptions& options, const std::string& model_path);
  Status init(const SunCnnOptions& options, const std::vector<unsigned char>& model_bytes);

  const char* name() const override { return "sun_cnn"; }
  bool acceptsGray() const override { return true; }

  // Azimuth-only estimate: sun_c = (sin az, 0, cos az), sigma from the spread (see above).
  // zenith_deg is 90 (the vector lies in the x-z plane), confidence = R_mc * R_al.
  // The image may be BGR (CV_8UC3) or grey (CV_8UC1), whatever the model's channels: a grey
  // image feeds a colour model as (Y, Y, Y), a colour image a grey model as its BT.601 luma.
  // Errors: not initialised; empty image or another type; image size != camera size (when the
  // camera's size is set); image smaller than the network input.
  Expected<sunfusion::ImageSunEstimate> estimate(const sunfusion::ImageSunInput& input) override;

  // The network alone on a prepared input blob [1, C, H, W] (CV_32F) and masks [K, F], [K, D]:
  // the [M K, 2] output. For the parity test against PyTorch.
  Expected<cv::Mat> forwardRaw(const cv::Mat& blob, const cv::Mat& mask1, const cv::Mat& mask2);

  // The last call's raw numbers (for evaluation tools).
  const SunCnnRaw& lastRaw() const { return raw_; }
  bool initialised() const { return ready_; }

 private:
  Status finishInit();
  void fillMasks();

  SunCnnOptions options_;
  cv::dnn::Net net_;
  bool ready_ = false;
  std::mt19937_64 rng_;
  cv::Mat small3_;  // input_height x input_width, CV_8UC3 (colour images)
  cv::Mat small1_;  // input_height x input_width, CV_8UC1 (grey images)
  cv::Mat blob_;    // [1, C, H, W] CV_32F
  cv::Mat mask1_, mask2_, out_;
  std::vector<cv::Mat> outs_;
  std::vector<cv::String> out_names_;  // "azimuth_cs", then each member's trunk if a prior needs it
  SunCnnRaw raw_;
};

}  // namespace sunvo::suncnn
