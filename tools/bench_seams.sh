#!/usr/bin/env bash
# Frame-time ratios to the UV baseline (`bench render`) of two builds, interleaved run by run:
# the Duck at uniform R = 16, and the Duck at R = 4 with a patch raised to R = 64 (resolution
# boundaries all around it; made by each build's own `paint --tool set`).
#   tools/bench_seams.sh BEFORE_BINARY AFTER_BINARY [ROUNDS]
set -euo pipefail
before=$1
after=$2
rounds=${3:-2}
here=$(cd "$(dirname "$0")/.." && pwd)
duck="$here/assets/models/Duck/Duck.glb"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for label in before after; do
  bin=${!label}
  "$bin" paint "$duck" -r 4 --tool set --target-resolution 64 \
    --stroke "500,300 524,300" --radius-px 110 -o "$tmp/$label.mpk" 2>/dev/null
done
for round in $(seq "$rounds"); do
  for label in before after; do
    bin=${!label}
    for scene in uniform16 patch; do
      if [ "$scene" = uniform16 ]; then args=("$duck" -r 16); else args=("$tmp/$label.mpk"); fi
      "$bin" bench render "${args[@]}" --frames 20 2>/dev/null |
        python3 -c "import json,sys; d=json.load(sys.stdin); print(json.dumps({'build':'$label','round':$round,'scene':'$scene','baseline':d['baseline'],'ratios':{m['mode']:round(m['ratio_to_baseline'],3) for m in d['modes']},'gpu_bytes':{m['mode']:m['gpu_bytes'] for m in d['modes']}}))"
    done
  done
done
