#pragma once
// Loads a KITTI odometry sample folder (calib.txt with P0..P3, times.txt, image_0/ and image_1/
// with NNNNNN.png): the rectified stereo camera and every grayscale image pair, for benchmarks
// and tests.

#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "sunvo/core/camera.hpp"
#include "sunvo/core/status.hpp"

namespace sunvo::bench {

struct KittiOdometrySample {
  StereoCamera camera;          // from P0 (fu fv cu cv) and P1 (baseline = -P1[3] / P1[0])
  std::vector<double> times_s;  // times.txt
  std::vector<cv::Mat> left;    // image_0, CV_8UC1
  std::vector<cv::Mat> right;   // image_1, CV_8UC1
};

// Reads P0/P1 of a KITTI odometry calib.txt; width/height are left 0.
Expected<StereoCamera> readKittiOdometryCalib(const std::string& path);

// Reads the whole folder; one image pair per line of times.txt.
Expected<KittiOdometrySample> loadKittiOdometrySample(const std::string& dir);

}  // namespace sunvo::bench
