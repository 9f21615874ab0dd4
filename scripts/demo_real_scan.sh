#!/usr/bin/env bash
# Real-scan demo (Chapter 2 planes): planes of PCL's table_scene_lms400.pcd at three scales.
#   scripts/demo_real_scan.sh [BUILD_DIR]      (BUILD_DIR defaults to build; run ./build.sh build first)
# Downloads Debian's python3-pcl package once into out/real_scan/ (apt-get download, no install),
# extracts only the scan from it, then runs info, planes, segment at three scales and render.
# Pictures go to docs/images/real_scan_*.png; everything else stays in out/real_scan/.
# Idempotent: the download and extraction are skipped when the scan is already there.
set -euo pipefail
cd "$(dirname "$0")/.."

build=${1:-build}
exe=$build/scalespace
cache=out/real_scan
images=docs/images
scan=$cache/table_scene_lms400.pcd
member=./usr/share/doc/python3-pcl/examples/pcldata/tutorials/table_scene_lms400.pcd

# Scales t of the three segmentations: computed scales of the stack (`segment --scale` takes the
# nearest one; components.json lists them: 50 log-spaced scales from 0.0044, components up to 0.47).
# small: many tile-like pieces; medium: table top and floor merged, legs apart; large: a few planes.
scales=(small:0.0057 medium:0.0183 large:0.1466)
# The scanner looks along -z with +y up: the "top" view (along -z) shows the table from the front.
view=top
size=1024x768

die() {
  echo "demo_real_scan: error: $*" >&2
  exit 1
}

if [[ ! -x $exe ]]; then
  die "$exe not found: build first (./build.sh build, or pass the build directory as argument)"
fi
for tool in apt-get dpkg-deb tar awk; do
  command -v "$tool" >/dev/null || die "'$tool' is missing (this script needs Debian's tools)"
done

mkdir -p "$cache" "$images"

# Prints the wall time of a step: step NAME COMMAND...
step() {
  local name=$1
  shift
  local start=$EPOCHREALTIME
  "$@"
  awk -v n="$name" -v a="$start" -v b="$EPOCHREALTIME" \
    'BEGIN { printf "demo_real_scan: time %-26s %7.1f s\n", n, b - a }' >&2
}

if [[ ! -s $scan ]]; then
  debs=("$cache"/python3-pcl_*.deb)
  if [[ ! -f ${debs[0]} ]]; then
    echo "demo_real_scan: downloading python3-pcl (about 8 MB) into $cache" >&2
    if ! (cd "$cache" && apt-get download python3-pcl); then
      die "'apt-get download python3-pcl' failed (no network, or no Debian package lists: try 'apt-get update')"
    fi
    debs=("$cache"/python3-pcl_*.deb)
    [[ -f ${debs[0]} ]] || die "apt-get download reported success but no python3-pcl_*.deb is in $cache"
  fi
  deb=${debs[0]}
  dpkg-deb --fsys-tarfile "$deb" | tar -xO "$member" >"$scan.tmp" ||
    die "could not extract $member from $deb"
  [[ -s $scan.tmp ]] || die "$member is empty or missing in $deb"
  mv "$scan.tmp" "$scan"
fi

step "info" "$exe" info "$scan"
step "render input" "$exe" render "$scan" --color intensity --view "$view" --size "$size" \
  -o "$images/real_scan_input.png" -q
step "planes" "$exe" planes "$scan" -o "$cache/planes"
if [[ -f $cache/planes/persistence.svg ]]; then
  # Without the per-component tooltips (<title>), which make up a third of the file.
  sed -e 's|<title>[^<]*</title>||' "$cache/planes/persistence.svg" >"$images/real_scan_persistence.svg"
fi
for entry in "${scales[@]}"; do
  name=${entry%%:*}
  t=${entry#*:}
  step "segment --scale $t" "$exe" segment "$cache/planes" --scale "$t" \
    -o "$cache/segment_$name.ply"
  step "render $name" "$exe" render "$cache/segment_$name.ply" --labels plane_id \
    --view "$view" --size "$size" -o "$images/real_scan_planes_$name.png" -q
done
echo "demo_real_scan: pictures in $images/real_scan_*.png, results in $cache/" >&2
