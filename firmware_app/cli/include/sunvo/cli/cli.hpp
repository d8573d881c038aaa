#pragma once
// One command-line convention for every sunvo program (CLI11 from Debian):
//   --help and --version answer on stdout and exit 0;
//   a usage error (unknown option, missing or mistyped value, value out of range) prints the
//   reason and a hint to stderr and exits 2;
//   a runtime failure (a file that does not parse, a device that fails) exits 1 (fail()).
//
//   CLI::App app{"what the program does", "sunvo_x"};
//   app.add_option("--frames", frames, "...")->check(CLI::Range(0, 1000000));
//   if (auto code = sunvo::cli::parse(app, argc, argv)) return *code;
//   ...
//   if (!status.isOk()) return sunvo::cli::fail("sunvo_x", status);

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "sunvo/core/fields.hpp"
#include "sunvo/core/status.hpp"

namespace sunvo::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;  // runtime failure
inline constexpr int kExitUsage = 2;    // bad command line

// Adds --version and parses. nullopt: go on; else the exit code (help, version, usage error).
std::optional<int> parse(CLI::App& app, int argc, char** argv);

// Prints "<program>: <status>" to stderr and returns kExitFailure.
int fail(const std::string& program, const Status& status);
int fail(const std::string& program, const std::string& message);

// The project version, e.g. "0.1.0".
const char* version();

// An option whose value is one of a named enum's names (enumNames, as the config files spell
// them), e.g. --detector edge_chains|lsd; any other word is a usage error naming the option.
template <NamedEnum E>
CLI::Option* addEnumOption(CLI::App& app, const std::string& name, E& value,
                           const std::string& help) {
  const std::span<const std::string_view> names = enumNames(value);
  std::vector<std::string> choices(names.begin(), names.end());
  return app
      .add_option_function<std::string>(
          name,
          [&value, names](const std::string& word) {
            for (std::size_t i = 0; i < names.size(); ++i) {
              if (names[i] == word) value = static_cast<E>(i);
            }
          },
          help)
      ->check(CLI::IsMember(choices));
}

// The vehicle the KITTI tools assume (sunvo_track_vo, sunvo_experiment; docs/lateral_prior.md,
// "On for the KITTI car"): the window's sideways non-holonomic row on, with the KITTI car's lever
// arm, the camera 0.88 m ahead of the rear axle to within 0.1 m (fitted on odometry 00's truth, a
// drive no set uses; the 0020 and 06 truths give 0.93 and 0.89 m), and the camera's axis aligned
// with the car's to within 2.5 deg (chosen on the validation sets; it also widens the vertical
// row). A property of the rig, like its calibration: another vehicle gives its own --lever-m, or
// --lateral-prior 0 when its lever arm is not known. The library's and the rover's defaults keep
// the row off (no lever arm known).
template <class WindowOptions>
void setKittiCarVehicle(WindowOptions& win) {
  win.lateral_prior_sigma_m_s = 0.1;
  win.lateral_lever_m = 0.88;
  win.lateral_lever_sigma_m = 0.1;
  win.lateral_mount_sigma_deg = 2.5;
}

// The window's motion priors (backend::WindowOptions, docs/backend.md), the same in every program
// that runs the back end: the constant-velocity prior's --prior-rot-deg and --prior-trans-m (per
// frame; 0 = that part off) or --prior-accel (the translation's std as an acceleration, m/s^2),
// and the rotation-rate prior's --no-rate-prior, --rate-prior-pitch/-yaw/-roll (deg/s),
// --rate-prior-adapt-frames, --yaw-axis-memory-s, --yaw-axis-prior-deg. A template so that this
// library needs nothing of the back end.
template <class WindowOptions>
void addWindowPriorOptions(CLI::App& app, WindowOptions& win) {
  app.add_option("--prior-rot-deg", win.motion_prior_sigma_rot_deg,
                 "constant-velocity prior: std of a frame's rotation about the last motion's, deg "
                 "(window.motion_prior_sigma_rot_deg; 0 with --prior-trans-m 0 = off)")
      ->check(CLI::Range(0.0, 180.0));
  app.add_option("--prior-trans-m", win.motion_prior_sigma_trans_m,
                 "constant-velocity prior: std of a frame's translation about the last motion's, m "
                 "(window.motion_prior_sigma_trans_m; needs --prior-accel 0)")
      ->check(CLI::Range(0.0, 1000.0));
  app.add_option("--prior-accel", win.motion_prior_sigma_accel_m_s2,
                 "constant-velocity prior on the translation as an acceleration std, m/s^2: the "
                 "std is this x dt^2 (window.motion_prior_sigma_accel_m_s2; 0 = off)")
      ->check(CLI::Range(0.0, 1000.0));
  app.add_option("--lateral-prior", win.lateral_prior_sigma_m_s,
                 "non-holonomic prior: std of the camera's sideways velocity about a wheeled "
                 "vehicle's, m/s (window.lateral_prior_sigma_m_s; 0 = off)")
      ->check(CLI::Range(0.0, 100.0));
  app.add_option("--lever-m", win.lateral_lever_m,
                 "non-holonomic prior: the camera's distance ahead of the rear axle, m "
                 "(window.lateral_lever_m)")
      ->check(CLI::Range(-10.0, 10.0));
  app.add_option("--lever-sigma-m", win.lateral_lever_sigma_m,
                 "non-holonomic prior: the std of --lever-m, m (window.lateral_lever_sigma_m)")
      ->check(CLI::Range(0.0, 10.0));
  app.add_option("--mount-sigma-deg", win.lateral_mount_sigma_deg,
                 "non-holonomic prior: how well the camera axis is aligned with the vehicle's, deg "
                 "(window.lateral_mount_sigma_deg)")
      ->check(CLI::Range(0.0, 45.0));
  app.add_option("--beta-frames", win.lateral_beta_frames,
                 "non-holonomic prior: learn the camera's direction of travel as the median over "
                 "this many solved steps (window.lateral_beta_frames; 0 = straight ahead)")
      ->check(CLI::Range(0, 1024));
  app.add_option("--vertical-prior", win.vertical_prior_sigma_m_s,
                 "non-holonomic prior in the vertical plane: std of the camera's vertical velocity "
                 "about the vehicle's body axis, m/s (window.vertical_prior_sigma_m_s; 0 = off)")
      ->check(CLI::Range(0.0, 100.0));
  app.add_option("--lateral-near-m", win.lateral_prior_near_m,
                 "non-holonomic prior: leave the sideways row out of frames with a track nearer "
                 "than this, m (window.lateral_prior_near_m; 0 = every frame)")
      ->check(CLI::Range(0.0, 1000.0));
  app.add_option("--vertical-near-m", win.vertical_prior_near_m,
                 "vertical prior: leave the row out of frames with a track nearer than this, m "
                 "(window.vertical_prior_near_m; 0 = every frame)")
      ->check(CLI::Range(0.0, 1000.0));
  app.add_option("--gamma-frames", win.vertical_gamma_frames,
                 "vertical prior: learn the camera's pitch against the direction of travel as the "
                 "median over this many solved steps (window.vertical_gamma_frames; 0 = level)")
      ->check(CLI::Range(0, 1024));
  app.add_flag(
      "!--no-rate-prior", win.rotation_rate_prior,
      "VO without the window's zero-mean rotation-rate prior (window.rotation_rate_prior)");
  app.add_option("--rate-prior-pitch", win.rate_prior_pitch_deg_s,
                 "rotation-rate prior std about the camera x axis, deg/s (0 = none)")
      ->check(CLI::Range(0.0, 1000.0));
  app.add_option("--rate-prior-yaw", win.rate_prior_yaw_deg_s,
                 "rotation-rate prior std about the camera y axis, deg/s (0 = none)")
      ->check(CLI::Range(0.0, 1000.0));
  app.add_option("--rate-prior-roll", win.rate_prior_roll_deg_s,
                 "rotation-rate prior std about the optical axis, deg/s (0 = none)")
      ->check(CLI::Range(0.0, 1000.0));
  app.add_option("--rate-prior-adapt-frames", win.rate_prior_adapt_frames,
                 "frames of the vehicle's own rates whose spread raises the rate prior's std "
                 "(0 = fixed std)")
      ->check(CLI::Range(0, 256));
  app.add_option("--yaw-axis-memory-s", win.yaw_axis_memory_s,
                 "time constant of the window's yaw-axis estimate, s")
      ->check(CLI::Range(1e-3, 1e6));
  app.add_option("--yaw-axis-prior-deg", win.yaw_axis_prior_deg,
                 "weight of the camera's y axis in the yaw-axis estimate, deg of turning")
      ->check(CLI::Range(1e-3, 180.0));
}

// A start attitude wrong in tilt and its levelling (docs/start_levelling.md), the same in every
// program that emulates it: --start-pitch-error-deg, --start-roll-error-deg (deg, [-30, 30]: VO
// starts from the true first pose turned by them) and --level-start (the vertical cue's first
// answers measure that error, which is then removed where the filter has not taken it).
inline void addStartTiltOptions(CLI::App& app, double& pitch_error_deg, double& roll_error_deg,
                                bool& level_start) {
  app.add_option("--start-pitch-error-deg", pitch_error_deg,
                 "start VO from the first true pose pitched by this much (a rover's wrongly "
                 "configured start tilt; evaluated against the true poses), deg")
      ->check(CLI::Range(-30.0, 30.0));
  app.add_option("--start-roll-error-deg", roll_error_deg, "the same about the optical axis, deg")
      ->check(CLI::Range(-30.0, 30.0));
  app.add_flag("--level-start", level_start,
               "the vertical cue's answers of the first frames (15 unless "
               "--world-up-alignment-frames) measure the start attitude's tilt error; what the "
               "filter has not taken of it by then is removed where significant (the rover's "
               "setting; worlds whose up is known)");
}

// A bias state's std (deg) and correlation length (frames) as --<prefix>bias-state-deg and
// --<prefix>bias-state-frames, in [0, max_sigma_deg] and [1, max_length_frames] (the fusion's
// ranges; the sun's azimuth bias by default); `std_help` describes the std.
inline void addBiasStateOptions(CLI::App& app, double& sigma_deg, double& length_frames,
                                const std::string& prefix, const std::string& std_help,
                                double max_sigma_deg = 45.0, double max_length_frames = 1e6) {
  app.add_option("--" + prefix + "bias-state-deg", sigma_deg, std_help)
      ->check(CLI::Range(0.0, max_sigma_deg));
  app.add_option("--" + prefix + "bias-state-frames", length_frames,
                 "its correlation length, frames")
      ->check(CLI::Range(1.0, max_length_frames));
}

// The fusion's bias states (sunfusion::SunFusionOptions), the same in every program that runs the
// fusion: the sun's azimuth bias (docs/fusion_bias.md) as --bias-state-deg, --bias-state-frames,
// and the vertical cue's (docs/fusion_bias.md) as --up-bias-state-deg, --up-bias-state-frames.
template <class FusionOptions>
void addBiasStateOptions(CLI::App& app, FusionOptions& fusion) {
  addBiasStateOptions(app, fusion.sun_bias_sigma_deg, fusion.sun_bias_length_frames, "",
                      "the fusion's sun azimuth bias state: its std, deg (0 = none; the true "
                      "vector runs without it)");
  addBiasStateOptions(app, fusion.vertical_bias_sigma_deg, fusion.vertical_bias_length_frames,
                      "up-",
                      "the fusion's bias state of the vertical cue (a turn of its up about the "
                      "camera's x and z axes): its std, deg (0 = none)",
                      10.0, 1e7);
}

// The ranges the likelihood rule chooses the tilt's walk from (sunfusion::SunFusionOptions,
// docs/vertical.md), the same in every program that runs the fusion: --vertical-max-drift-deg
// (the fastest walk, deg/frame), --likelihood-noise-min and --likelihood-noise-max (the cue's
// noise scales, true / reported std), --bank-up-bias and --bank-up-bias-max-deg (the cue's bias
// stds, docs/fusion_bias.md).
template <class FusionOptions>
void addTiltWalkRangeOptions(CLI::App& app, FusionOptions& fusion) {
  app.add_option("--vertical-max-drift-deg", fusion.vertical_max_drift_deg_per_frame,
                 "the fastest tilt walk the cue's answers may choose, deg/frame")
      ->check(CLI::Range(0.0, 5.0));
  app.add_option("--likelihood-noise-min", fusion.likelihood_noise_min,
                 "the smallest noise scale of the cue (true / reported std) the likelihood rule "
                 "considers")
      ->check(CLI::Range(1e-3, 100.0));
  app.add_option("--likelihood-noise-max", fusion.likelihood_noise_max,
                 "the largest such noise scale")
      ->check(CLI::Range(1e-3, 100.0));
  app.add_option("--bank-up-bias", fusion.likelihood_up_bias_scales,
                 "bias stds of the cue the likelihood rule considers (0, then halving down to "
                 "--bank-up-bias-max-deg); 1 = none; with more the bank's bias estimate is taken "
                 "out of the cue's answers")
      ->check(CLI::Range(1, 4));
  app.add_option("--bank-up-bias-max-deg", fusion.likelihood_up_bias_max_deg,
                 "the widest such bias std, deg")
      ->check(CLI::Range(1e-3, 10.0));
}

// The stereo self-calibration's options (selfcal::StereoSelfCalibrationOptions, docs/selfcal.md),
// the same in every program that runs it: its drift rate, --self-calib-rate-deg and
// --self-calib-rate-frames, and the rig's constant disparity bias, --disparity-bias-px, measured
// offline (scripts/disparity_bias.py with poses of a known length; docs/disparity_bias.md) and
// taken out of every observation with or without the self-calibration.
template <class SelfCalibrationOptions>
void addSelfCalibrationOptions(CLI::App& app, SelfCalibrationOptions& sc) {
  app.add_option("--self-calib-rate-deg", sc.drift_rate_sigma_deg,
                 "std of the self-calibration's pitch/roll drift rate, deg/frame (0 = random walk "
                 "only)")
      ->check(CLI::Range(0.0, 0.1));
  app.add_option("--self-calib-rate-frames", sc.drift_rate_time_frames,
                 "correlation time of that drift rate, frames")
      ->check(CLI::Range(1.0, 1e7));
  app.add_option("--disparity-bias-px", sc.disparity_bias_px,
                 "the rig's measured disparity bias, px: d - bias is used "
                 "(self_calibration.disparity_bias_px; 0 = none)")
      ->check(CLI::Range(-5.0, 5.0));
}

}  // namespace sunvo::cli
