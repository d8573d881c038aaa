#pragma once
// The per-kind loaders behind Dataset::open (a friend of Dataset, so each fills its fields).

#include <filesystem>
#include <string>

#include "sunvo/dataset/dataset.hpp"

namespace sunvo::dataset {

class DatasetLoader {
 public:
  // KITTI raw drive or sunvo render (drive_dir holds image_00 and oxts/).
  static Expected<Dataset> raw(const DatasetOptions& options, const std::filesystem::path& drive);
  // KITTI odometry sequence folder (image_0, calib.txt, times.txt).
  static Expected<Dataset> odometry(const DatasetOptions& options,
                                    const std::filesystem::path& dir);
  // Feature-track folder (tracks.csv).
  static Expected<Dataset> tracks(const DatasetOptions& options, const std::filesystem::path& dir);
  // Trajectory route: a folder or a KITTI odometry prefix DIR/NN.
  static Expected<Dataset> trajectory(const DatasetOptions& options,
                                      const std::filesystem::path& path);

  // Applies [first, last] of the options to n frames; the error names the key.
  static Status range(const DatasetOptions& options, std::size_t n, const std::string& what,
                      std::int64_t* first, std::int64_t* last);
  // Ground truth (camera 0 in a first-camera world) and the true sun from a csv of camera
  // vectors, cut to the range [first, last] of the recording; sets world, T_w_c0 and sun.
  static Status firstCameraWorld(Dataset& ds, std::vector<Isometry3> T_gt_all,
                                 const std::string& gt_path, const std::string& sun_csv,
                                 std::int64_t first, std::int64_t last);
};

// An existing file among candidates ("" if none).
std::string firstExisting(std::initializer_list<std::filesystem::path> candidates);

}  // namespace sunvo::dataset
