#!/usr/bin/env python3
"""Extract a compact star catalogue CSV from the d3-celestial npm package.

Input: the untarred npm package folder (``package/`` from
``npm pack d3-celestial``), in which case ``data/stars.8.json`` is read, or the
path of one of its star GeoJSON files directly (``stars.6.json``,
``stars.8.json`` or ``stars.14.json``).

Output: CSV with header ``hip,ra_deg,dec_deg,vmag,bv``.

* ``hip``     Hipparcos catalogue number (GeoJSON feature ``id``).
* ``ra_deg``  right ascension in degrees, [0, 360), 4 decimals.  The package
              stores RA as GeoJSON longitude in [-180, 180] (12..24 h mapped to
              -180..0 deg), so negative longitudes get +360 here.
* ``dec_deg`` declination in degrees, [-90, 90], 4 decimals (GeoJSON latitude).
* ``vmag``    apparent V magnitude, 2 decimals.
* ``bv``      B-V colour index, 2 decimals; empty field where the source has
              no value.

All rounding is done on the exact decimal values found in the JSON (Decimal,
round-half-up), rows are sorted by (vmag, hip), so the output is byte-for-byte
deterministic.  Python 3 standard library only.
"""

import argparse
import json
import os
import sys
from decimal import Decimal, ROUND_HALF_UP

DEFAULT_STAR_FILE = os.path.join("data", "stars.8.json")
Q4 = Decimal("0.0001")
Q2 = Decimal("0.01")

# (hip, name) of stars printed as spot checks.
CHECK_STARS = [
    (32349, "Sirius"),
    (30438, "Canopus"),
    (69673, "Arcturus"),
    (91262, "Vega"),
    (24608, "Capella"),
    (24436, "Rigel"),
    (27989, "Betelgeuse"),
    (11767, "Polaris"),
]


def fmt(value, quantum):
    """Round an exact Decimal half-up to `quantum` and format it; no '-0'."""
    q = value.quantize(quantum, rounding=ROUND_HALF_UP)
    if q == 0:
        q = abs(q)
    return format(q, "f")


def to_decimal(value, what, hip):
    if isinstance(value, bool):
        raise ValueError("HIP %s: %s is a boolean" % (hip, what))
    if isinstance(value, (int, Decimal)):
        return Decimal(value)
    if isinstance(value, str):
        return Decimal(value.strip())
    raise ValueError("HIP %s: unexpected %s %r" % (hip, what, value))


def load_features(path):
    with open(path, "r", encoding="utf-8") as fh:
        # parse_float=Decimal keeps the exact decimal text of every number.
        doc = json.load(fh, parse_float=Decimal)
    if doc.get("type") != "FeatureCollection":
        raise ValueError("%s is not a GeoJSON FeatureCollection" % path)
    return doc["features"]


def convert(features, max_mag):
    rows = []
    seen = set()
    n_missing_bv = 0
    n_skipped_faint = 0
    for feat in features:
        hip = feat["id"]
        if isinstance(hip, str):
            hip = int(hip)
        if not isinstance(hip, int) or isinstance(hip, bool) or hip <= 0:
            raise ValueError("bad Hipparcos id %r" % (feat["id"],))
        if hip in seen:
            raise ValueError("duplicate Hipparcos id %d" % hip)
        seen.add(hip)

        props = feat["properties"]
        mag = to_decimal(props["mag"], "mag", hip)
        if mag > max_mag:
            n_skipped_faint += 1
            continue

        geom = feat["geometry"]
        if geom["type"] != "Point" or len(geom["coordinates"]) != 2:
            raise ValueError("HIP %d: geometry is not a 2-D Point" % hip)
        lon = to_decimal(geom["coordinates"][0], "longitude", hip)
        lat = to_decimal(geom["coordinates"][1], "latitude", hip)
        if not (Decimal(-180) <= lon <= Decimal(180)):
            raise ValueError("HIP %d: longitude %s out of range" % (hip, lon))
        if not (Decimal(-90) <= lat <= Decimal(90)):
            raise ValueError("HIP %d: latitude %s out of range" % (hip, lat))
        ra = lon + 360 if lon < 0 else lon

        bv_raw = props.get("bv")
        if bv_raw is None or (isinstance(bv_raw, str) and bv_raw.strip() == ""):
            bv = None
            n_missing_bv += 1
        else:
            bv = to_decimal(bv_raw, "bv", hip)

        ra_s = fmt(ra, Q4)
        if ra_s == "360.0000":
            ra_s = "0.0000"
        rows.append((mag, hip, ra_s, fmt(lat, Q4), fmt(mag, Q2),
                     "" if bv is None else fmt(bv, Q2)))
    rows.sort(key=lambda r: (r[0], r[1]))
    return rows, n_missing_bv, n_skipped_faint


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("source",
                    help="untarred d3-celestial package folder, or a "
                         "stars.*.json file from its data/ folder")
    ap.add_argument("output", help="CSV file to write")
    ap.add_argument("--max-mag", type=Decimal, default=Decimal("8.0"),
                    help="keep stars with V magnitude <= this (default 8.0)")
    args = ap.parse_args(argv)

    src = args.source
    if os.path.isdir(src):
        src = os.path.join(src, DEFAULT_STAR_FILE)
    features = load_features(src)
    rows, n_missing_bv, n_faint = convert(features, args.max_mag)

    with open(args.output, "w", encoding="ascii", newline="\n") as out:
        out.write("hip,ra_deg,dec_deg,vmag,bv\n")
        for _, hip, ra, dec, mag, bv in rows:
            out.write("%d,%s,%s,%s,%s\n" % (hip, ra, dec, mag, bv))

    # ---- summary and spot checks -----------------------------------------
    by_hip = {r[1]: r for r in rows}
    print("input:           %s (%d features)" % (src, len(features)))
    print("output:          %s (%d bytes)" % (args.output,
                                              os.path.getsize(args.output)))
    print("stars written:   %d (V <= %s; %d fainter skipped)"
          % (len(rows), args.max_mag, n_faint))
    if rows:
        print("vmag range:      %s .. %s" % (rows[0][4], rows[-1][4]))
        ras = [Decimal(r[2]) for r in rows]
        decs = [Decimal(r[3]) for r in rows]
        print("ra_deg range:    %s .. %s" % (min(ras), max(ras)))
        print("dec_deg range:   %s .. %s" % (min(decs), max(decs)))
        bvs = [Decimal(r[5]) for r in rows if r[5] != ""]
        print("bv range:        %s .. %s" % (min(bvs), max(bvs)))
    print("missing B-V:     %d" % n_missing_bv)
    print("brightest 10:")
    for _, hip, ra, dec, mag, bv in rows[:10]:
        print("  HIP %6d  ra %9s  dec %8s  V %5s  B-V %s" % (hip, ra, dec, mag, bv))
    print("spot checks:")
    for hip, name in CHECK_STARS:
        r = by_hip.get(hip)
        if r is None:
            print("  %-10s HIP %6d  not in output" % (name, hip))
        else:
            print("  %-10s HIP %6d  ra %9s  dec %8s  V %5s  B-V %s"
                  % (name, hip, r[2], r[3], r[4], r[5]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
