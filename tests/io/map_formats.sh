#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-2-Clause
# ctest io.map_formats (label scenario): output.formats geojson and kml of `pednav run` read back with real parsers —
# Python's json (RFC 7946: a FeatureCollection, [lon, lat, h] positions, no crs member, one Point per solution.csv
# row plus the LineString) and xmllint + Python's xml.etree (well-formed KML 2.2, one Placemark per row plus the track,
# UTC TimeStamps) — and their positions equal solution.csv's.
set -euo pipefail
pednav="${1:?usage: $0 PEDNAV_BINARY WORKDIR}"
work="${2:?usage: $0 PEDNAV_BINARY WORKDIR}"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
rm -rf "$work"
"$pednav" -q simulate "$root/datasets/indoor_loops.yaml" -o "$work/data"
sed -i 's/^  formats: .*/  formats: [csv, geojson, kml]/' "$work/data/config.yaml"
grep -q 'formats: \[csv, geojson, kml\]' "$work/data/config.yaml" || printf 'output:\n  formats: [csv, geojson, kml]\n' >> "$work/data/config.yaml"
"$pednav" -q run "$work/data/config.yaml" -o "$work/run"
xmllint --noout "$work/run/solution.kml" "$work/run/smoothed.kml"
python3 - "$work/run" <<'PY'
import csv, json, sys, xml.etree.ElementTree as ET
d = sys.argv[1]
for stem in ("solution", "smoothed"):
    rows = list(csv.DictReader(open(f"{d}/{stem}.csv")))
    g = json.load(open(f"{d}/{stem}.geojson"))
    assert g["type"] == "FeatureCollection" and "crs" not in g, "RFC 7946 FeatureCollection without crs"
    f = g["features"]
    assert f[0]["geometry"]["type"] == "LineString" and len(f[0]["geometry"]["coordinates"]) == len(rows)
    pts = f[1:]
    assert len(pts) == len(rows), (len(pts), len(rows))
    for p, r in zip(pts, rows):
        lon, lat, h = p["geometry"]["coordinates"]
        assert -180 <= lon <= 180 and -90 <= lat <= 90
        assert abs(lon - float(r["lon_deg"])) < 1e-8 and abs(lat - float(r["lat_deg"])) < 1e-8, (lon, lat, r)
        assert abs(h - float(r["h_m"])) < 1e-3
        pr = p["properties"]
        assert abs(pr["gps_tow_s"] - float(r["gps_tow_s"])) < 1e-3 and pr["utc"].endswith("Z")
        assert abs(pr["sd_n_m"] - float(r["sd_n_m"])) < 1e-3 and pr["sigma_major_m"] >= pr["sigma_minor_m"] >= 0
    ns = {"k": "http://www.opengis.net/kml/2.2"}
    k = ET.parse(f"{d}/{stem}.kml")
    marks = k.findall(".//k:Placemark", ns)
    assert len(marks) == len(rows) + 1, (len(marks), len(rows))
    assert len(k.findall(".//k:TimeStamp/k:when", ns)) == len(rows)
    track = k.find(".//k:LineString/k:coordinates", ns).text.split()
    assert len(track) == len(rows)
    lon, lat, h = map(float, track[-1].split(","))
    assert abs(lon - float(rows[-1]["lon_deg"])) < 1e-8 and abs(lat - float(rows[-1]["lat_deg"])) < 1e-8
    print(f"{stem}: {len(rows)} epochs in geojson and kml")
PY
