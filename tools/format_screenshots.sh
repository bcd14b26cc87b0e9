#!/usr/bin/env bash
# The two pictures of the formats issue, from the release binary:
#  - a scan imported from PLY and painted: the Stanford bunny (assets/models/Bunny144k, a
#    .glb) written as binary PLY by tools/glb_to_ply.py, opened at R = 1 with resolution
#    following the brush, two strokes painted, rendered lit (smooth) beside its heat map;
#  - a baked texture opened as a plain glTF: the Fox painted at R = 16 (left, mesh colors),
#    baked into its own UVs (`export --texture 1024`) and drawn through the UV baseline
#    (`render --baseline-uv`, right). (The Duck's two sides share texels, so paint on one
#    side is lost in its bake; `export` reports it.)
#   tools/format_screenshots.sh BINARY OUTPUT_DIR
# e.g. tools/format_screenshots.sh target/release/meshpaint screenshots
set -euo pipefail
bin=$1
out=$2
here=$(cd "$(dirname "$0")/.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

python3 "$here/tools/glb_to_ply.py" "$here/assets/models/Bunny144k/bunny.glb" "$tmp/bunny.ply"
"$bin" paint "$tmp/bunny.ply" -r 1 --follow-resolution 64 --color '#d02828' --radius-px 18 \
  --stroke "430,250 470,300 520,330 580,340 640,330" -o "$tmp/bunny1.mpk"
"$bin" paint "$tmp/bunny1.mpk" --follow-resolution 64 --color '#2860d0' --radius-px 10 \
  --stroke "420,420 480,440 540,450 600,440" -o "$tmp/bunny2.mpk"
"$bin" render "$tmp/bunny2.mpk" -o "$tmp/lit.png" --width 640 --height 480
"$bin" render "$tmp/bunny2.mpk" -o "$tmp/heat.png" --width 640 --height 480 --heatmap --shading flat
convert "$tmp/lit.png" "$tmp/heat.png" +append "$out/ply_scan_painted.png"
"$bin" info "$tmp/bunny2.mpk"

"$bin" paint "$here/assets/models/Fox/Fox.glb" -r 16 --color '#2040e0' --radius-px 22 \
  --stroke "300,420 400,430 500,425 600,410" -o "$tmp/fox1.mpk"
"$bin" paint "$tmp/fox1.mpk" --color '#f0f0f0' --radius-px 12 \
  --stroke "420,300 480,290 540,295 600,310" -o "$tmp/fox.mpk"
"$bin" export "$tmp/fox.mpk" --uvs "$here/assets/models/Fox/Fox.glb" --texture 1024 -o "$tmp/fox_baked.glb"
"$bin" render "$tmp/fox.mpk" -o "$tmp/meshcolors.png" --width 640 --height 480
"$bin" render "$tmp/fox_baked.glb" --baseline-uv -o "$tmp/baked.png" --width 640 --height 480
convert "$tmp/meshcolors.png" "$tmp/baked.png" +append "$out/baked_texture_baseline.png"
