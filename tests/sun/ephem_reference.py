#!/usr/bin/python3
"""Independent reference for sunvo's SPA test: the sun's topocentric position from PyEphem.

Usage: ephem_reference.py CASES_CSV OUT_CSV
CASES_CSV has a header and rows "utc_iso,lat_deg,lon_deg,alt_m" with utc_iso as
"YYYY-MM-DD HH:MM:SS.ffffff" (UTC). OUT_CSV gets "delta_t_s,zenith_deg,azimuth_deg" per case:
PyEphem's own Delta T (TT - UT) for that date, so the caller can run its ephemeris with the
same time scale, and the airless (pressure = 0) topocentric zenith and azimuth (from north,
clockwise) of the sun's centre for an observer at that height.
Exit status 3 when PyEphem is missing (Debian: apt-get install python3-ephem), 2 on bad input.
"""
import csv
import math
import sys

try:
    import ephem
except ImportError:
    sys.stderr.write("ephem_reference.py: PyEphem is not installed for %s "
                     "(apt-get install python3-ephem)\n" % sys.executable)
    sys.exit(3)


def main(argv):
    if len(argv) != 3:
        sys.stderr.write(__doc__)
        return 2
    with open(argv[1], newline="") as f_in, open(argv[2], "w", newline="") as f_out:
        reader = csv.reader(f_in)
        header = next(reader)
        if header != ["utc_iso", "lat_deg", "lon_deg", "alt_m"]:
            sys.stderr.write("%s:1: unexpected header %r\n" % (argv[1], header))
            return 2
        f_out.write("delta_t_s,zenith_deg,azimuth_deg\n")
        for line_no, row in enumerate(reader, start=2):
            try:
                when, lat, lon, alt = row[0], float(row[1]), float(row[2]), float(row[3])
            except (IndexError, ValueError) as e:
                sys.stderr.write("%s:%d: %s\n" % (argv[1], line_no, e))
                return 2
            obs = ephem.Observer()
            obs.lat = math.radians(lat)
            obs.lon = math.radians(lon)
            obs.elevation = alt
            obs.pressure = 0.0  # no refraction
            obs.date = ephem.Date(when.replace("-", "/"))
            sun = ephem.Sun(obs)
            f_out.write("%.9f,%.9f,%.9f\n" % (ephem.delta_t(obs.date),
                                            90.0 - math.degrees(float(sun.alt)),
                                            math.degrees(float(sun.az))))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
