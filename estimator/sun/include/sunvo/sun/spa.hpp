#pragma once
// The NREL Solar Position Algorithm (SPA): I. Reda and A. Andreas, "Solar Position Algorithm for
// Solar Radiation Applications", NREL/TP-560-34302 (2003, revised 2008). Topocentric zenith and
// azimuth of the sun for an observer on the WGS84 ellipsoid at a UTC time, with a stated
// uncertainty of +/-0.0003 deg over the years -2000..6000, and the unit sun vector in the local
// East-North-Up frame. Pure computation: no I/O, no allocation, no global state.

#include <Eigen/Core>
#include <optional>

#include "sunvo/core/status.hpp"
#include "sunvo/core/time.hpp"

namespace sunvo::sun {

// Which zenith angle the ENU sun vector is built from.
enum class SunVectorZenith {
  kUnrefracted,  // geometric (airless) direction: smooth, weather-independent; the default
  kRefracted,    // apparent direction through the standard-atmosphere refraction model
};

// Observer and model settings of one SPA evaluation.
struct SpaOptions {
  // Geodetic (WGS84) latitude, deg, north positive. Valid [-90, 90].
  double latitude_deg = 0.0;
  // Longitude, deg, east positive. Valid [-180, 180].
  double longitude_deg = 0.0;
  // Observer height, m (the SPA report's "elevation"; ellipsoidal and orthometric heights differ
  // by < 110 m, which moves the sun by < 1e-7 deg through parallax). Valid [-1000, 100000].
  double elevation_m = 0.0;
  // Annual mean local pressure for refraction, mbar (= hPa). Valid [0, 5000]; 0 = no refraction.
  double pressure_mbar = 1013.25;
  // Annual mean local temperature for refraction, deg C. Valid [-100, 100].
  double temperature_c = 15.0;
  // Delta T = TT - UT1, s. Valid [-8000, 8000]. Unset: defaultDeltaTSeconds(t), a table of
  // measured yearly values 1990..2025 (held constant after). A 10 s error in Delta T moves the
  // sun by ~1e-4 deg (it only shifts the time of the geocentric ephemeris).
  std::optional<double> delta_t_s;
  // Delta UT1 = UT1 - UTC, s (IERS Bulletin A). Valid (-1, 1). Leaving it 0 costs at most
  // 0.9 s of Earth rotation = 0.0038 deg of hour angle.
  double delta_ut1_s = 0.0;
  // Refraction of the sun's centre at sunrise/sunset, deg; together with the sun's semi-diameter
  // (0.26667 deg) it sets the horizon limit below which no refraction is applied, as in the SPA
  // report's reference implementation. Valid [-5, 5].
  double atmospheric_refraction_deg = 0.5667;
  // Zenith used for SolarPosition::sun_enu.
  SunVectorZenith vector_zenith = SunVectorZenith::kUnrefracted;

  // Checks every field; the error names the bad key and its valid range.
  Status validate() const;
};

// Intermediate quantities of the SPA, named as in the report (angles in deg), for checking an
// evaluation against the report's worked example.
struct SpaIntermediate {
  double julian_day = 0.0;            // JD (UT1)
  double julian_ephemeris_day = 0.0;  // JDE (TT)
  double delta_t_s = 0.0;             // Delta T used, s
  double L_deg = 0.0;                 // Earth heliocentric longitude, [0, 360)
  double B_deg = 0.0;                 // Earth heliocentric latitude
  double R_au = 0.0;                  // Earth-sun distance, AU
  double delta_psi_deg = 0.0;         // nutation in longitude
  double delta_epsilon_deg = 0.0;     // nutation in obliquity
  double epsilon_deg = 0.0;           // true obliquity of the ecliptic
  double lambda_deg = 0.0;            // apparent sun longitude, [0, 360)
  double nu_deg = 0.0;                // apparent sidereal time at Greenwich, [0, 360)
  double alpha_deg = 0.0;             // geocentric right ascension, [0, 360)
  double delta_deg = 0.0;             // geocentric declination
  double H_deg = 0.0;                 // observer local hour angle, [0, 360)
  double alpha_topo_deg = 0.0;        // topocentric right ascension
  double delta_topo_deg = 0.0;        // topocentric declination
  double H_topo_deg = 0.0;            // topocentric local hour angle
};

struct SolarPosition {
  double zenith_deg = 0.0;            // topocentric zenith without refraction, [0, 180]
  double zenith_refracted_deg = 0.0;  // with refraction (= zenith_deg below the horizon limit)
  double azimuth_deg = 0.0;           // from north, clockwise (east = 90), [0, 360)
  // Unit vector from the observer toward the sun in local ENU: east = sin z sin a,
  // north = sin z cos a, up = cos z, with z per SpaOptions::vector_zenith.
  Eigen::Vector3d sun_enu = Eigen::Vector3d::UnitZ();
  SpaIntermediate intermediate;
};

// Default Delta T (TT - UT1, s) for a UTC time: linear interpolation in a table of yearly
// values (IERS/USNO, 1 January of each year) from 1990 to 2025, held constant outside.
double defaultDeltaTSeconds(TimeNs t_utc);

// Runs the SPA for the UTC time t_utc. Fails (kInvalidArgument) only when options.validate()
// fails.
Expected<SolarPosition> computeSolarPosition(TimeNs t_utc, const SpaOptions& options);

// ENU unit vector from a zenith and an azimuth (from north, clockwise), both in deg.
Eigen::Vector3d enuFromZenithAzimuth(double zenith_deg, double azimuth_deg);

}  // namespace sunvo::sun
