#pragma once
// A feature-track folder (files/tracks_io.hpp) with the KITTI sources of its image size. The size
// is the first found of:
//   1. TrackReadOptions::image_width x image_height (explicit);
//   2. the size on calib.txt's line ("fu fv cu cv baseline_m width height");
//   3. S_rect_00 of a KITTI raw calib_cam_to_cam.txt in the folder or its parent (the raw layout
//      keeps it in the recording day's folder);
//   4. the KITTI rig of the recording day that starts the folder's name (e.g.
//      "2011_10_03_drive_0027" -> 1241x376), when calib.txt's fu, cu, cv match that rig's
//      within 1 px;
//   5. the observed extent of tracks.csv.
// Observations within the tolerance past the border are dropped and counted (TrackSequence).

#include <string>

#include "sunvo/core/status.hpp"
#include "sunvo/files/tracks_io.hpp"

namespace sunvo::dataset {

Expected<files::TrackSequence> readTrackFolder(const std::string& folder,
                                               files::TrackReadOptions options);

}  // namespace sunvo::dataset
