#pragma once
// Batch geodetic -> local ENU conversion of a CSV table (the sunvo_geodesy tool).
//
// Input: a header line "origin_lat,origin_lon,origin_alt,lat,lon,alt", then one row per point:
// the origin of the local ENU frame and the point, degrees and metres above the WGS84 ellipsoid.
// Output: the header and every row with ",east,north,up" appended (metres, 6 decimals), the input
// fields written back as read. Blank lines are skipped. Errors name the file, line and field.

#include <ostream>

#include "sunvo/core/status.hpp"
#include "sunvo/files/text_file.hpp"

namespace sunvo::geodesy_cli {

Status convertGeodesyCsv(files::TextFile& in, std::ostream& out);

}  // namespace sunvo::geodesy_cli
