#!/usr/bin/env bash
# Before/after picture of the seam rule: a red stroke that ends on an R boundary (Duck at
# R = 4 with a patch raised to R = 64 by the resolution tool), linear filter, unlit,
# zoomed onto the stroke's end and cropped (ImageMagick `convert`).
#   tools/seam_screenshots.sh BINARY OUTPUT.png
# e.g. tools/seam_screenshots.sh target/release/meshpaint screenshots/seam_after.png
set -euo pipefail
bin=$1
out=$2
here=$(cd "$(dirname "$0")/.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$bin" paint "$here/assets/models/Duck/Duck.glb" -r 4 --tool set --target-resolution 64 \
  --stroke "500,300 524,300" --radius-px 110 -o "$tmp/resized.mpk"
"$bin" paint "$tmp/resized.mpk" --stroke "520,300 560,300 600,300 640,300" --radius-px 10 \
  --color '#ff2020' -o "$tmp/painted.mpk"
"$bin" render "$tmp/painted.mpk" -o "$tmp/full.png" --filter linear --shading unlit \
  --width 2048 --height 1536 --distance 1.6
convert "$tmp/full.png" -crop 400x300+1450+180 +repage -filter point -resize 200% "$out"
