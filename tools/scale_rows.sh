#!/usr/bin/env bash
# Every row of the scale table (docs/BENCHMARKS.md): runs each `meshpaint bench …` command
# once (`bench load` three times), on this machine, and prints the rows as a Markdown table,
# with the raw JSON in DIR.
#   tools/scale_rows.sh [BINARY] [DIR]
# BINARY defaults to target/release/meshpaint, DIR to target/scale-rows. The ≥ 1M-triangle
# inputs are made, not shipped: Bunny144k split twice (`--subdivide 2`, 2 304 736 triangles)
# and the Duck exported tessellated at R = 16 (1 078 272 triangles, into DIR). The idle row
# needs Xvfb (`apt-get install xvfb`); without it that row says so. Takes about 10 minutes.
# With TABLE_ONLY=1 it prints the table from the JSON already in DIR.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
bin=$(realpath "${1:-$here/target/release/meshpaint}")
out=$(realpath -m "${2:-$here/target/scale-rows}")
mkdir -p "$out"
bunny="$here/assets/models/Bunny144k/bunny.glb"
duck="$here/assets/models/Duck/Duck.glb"

if [ -z "${TABLE_ONLY:-}" ]; then
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), load $(cut -d' ' -f1-3 /proc/loadavg), $(date -u +%F)" >&2
echo "binary: $bin" >&2

"$bin" bench paint "$bunny" -r 8 --subdivide 2 --dabs 100 --dab-samples 10000,100000 --json >"$out/paint.json"
"$bin" bench pack "$bunny" -r 8 --subdivide 2 --format rgba8 --runs 1 >"$out/pack_2m.json"
"$bin" bench pack "$bunny" --resolution 16 --runs 5 >"$out/pack_bunny16.json"
[ -f "$out/duck1m.glb" ] || "$bin" export "$duck" -r 16 -o "$out/duck1m.glb" >/dev/null
# Three opens back to back: on a VM that hands freed memory back to its host (virtio-balloon
# free page reporting), the first open after other programs freed gigabytes waits for the
# host to back its pages again (docs/BENCHMARKS.md, "Where the time goes where a goal is missed").
for run in 1 2 3; do "$bin" bench load "$out/duck1m.glb" -r 8 >"$out/load_1m_$run.json"; done
# Over the sample limit: refused before anything is allocated (time and peak memory).
/usr/bin/time -f '%e %M' -o "$out/refuse.txt" "$bin" pack "$bunny" -r 64 -o "$out/never.mpk" 2>"$out/refuse.err" || true

# Idle: the editor on the Duck under Xvfb, its UI passes (MESHPAINT_FRAME_COUNT_FILE) and CPU
# time over 10 s with nothing moving, after 20 s to settle.
if command -v Xvfb >/dev/null; then
  Xvfb :93 -screen 0 1280x800x24 >/dev/null 2>&1 &
  xvfb=$!
  # Up to 10 s for its socket (a fixed 2 s once left the editor without a display).
  for _ in $(seq 100); do [ -S /tmp/.X11-unix/X93 ] && break; sleep 0.1; done
  if ! kill -0 "$xvfb" 2>/dev/null || [ ! -S /tmp/.X11-unix/X93 ]; then
    echo "Xvfb :93 did not start (a stale /tmp/.X93-lock?)" >&2
    echo '{"skipped": "Xvfb :93 did not start"}' >"$out/idle.json"
  else
    DISPLAY=:93 MESHPAINT_FRAME_COUNT_FILE="$out/frames" MESHPAINT_AUTOSAVE_SECONDS=3600 \
      "$bin" "$duck" >"$out/app.log" 2>&1 &
    app=$!
    sleep 20
    ticks() { awk '{print $14 + $15}' "/proc/$app/stat"; }
    f0=$(cat "$out/frames" 2>/dev/null || echo 0); t0=$(ticks)
    sleep 10
    f1=$(cat "$out/frames" 2>/dev/null || echo 0); t1=$(ticks)
    kill "$app" "$xvfb" 2>/dev/null || true
    wait 2>/dev/null || true
    echo "{\"frames\": $((f1 - f0)), \"cpu_seconds\": $(python3 -c "print(($t1 - $t0) / $(getconf CLK_TCK))"), \"seconds\": 10}" >"$out/idle.json"
  fi
else
  echo '{"skipped": "no Xvfb"}' >"$out/idle.json"
fi
fi

python3 - "$out" <<'EOF'
import json, sys, pathlib
out = pathlib.Path(sys.argv[1])
paint = json.loads((out / "paint.json").read_text())
pack2m = json.loads((out / "pack_2m.json").read_text())["results"][0]
bunny16 = json.loads((out / "pack_bunny16.json").read_text())["results"]
loads = [json.loads((out / f"load_1m_{run}.json").read_text()) for run in (1, 2, 3)]
refuse = [line for line in (out / "refuse.txt").read_text().splitlines() if line.strip()][-1].split()
idle = json.loads((out / "idle.json").read_text())
brushes = {b["target_samples"]: b for b in paint["brushes"]}
def rate(row, key="samples_per_second"):
    return " · ".join(f"{brushes[t][row][key + '_best'] / 1e6:.1f} ({brushes[t][row][key + '_median'] / 1e6:.1f})" for t in (10_000, 100_000))
def paced(row):
    return " · ".join(f"{brushes[t][row]['samples_per_second_median'] / 1e6:.1f}" for t in (10_000, 100_000))
inc = pack2m["incremental_after_stroke"]
print(f"{paint['triangles']:,} triangles at R = {paint['resolution']} ({paint['samples']:,} samples) unless a row says otherwise; "
      "dab rows: M samples/s, best (median) of 100 dabs, 10k · 100k-sample dabs; frame-paced: median, one dab per 1/60 s.\n")
print("| row | measured |")
print("|---|---|")
print(f"| brush with the editor's defaults (`occlusion`) | {rate('occlusion')}; frame-paced {paced('occlusion_frame_paced')} |")
print(f"| paint without occlusion (`paint`) | {rate('paint')} |")
print(f"| first dab of a stroke, records undo (`first_dab`) | {rate('first_dab')} |")
print(f"| blur (`blur`) | {rate('blur')}; frame-paced {paced('blur_frame_paced')} |")
up = paint["gpu_upload"]
print(f"| whole dab with its GPU upload (`gpu_upload`), 100k | {up['samples_per_second_best'] / 1e6:.1f} M/s best, {up['upload_spans']} writes |")
print(f"| repack after a 100k-sample stroke (`incremental_after_stroke`), RGBA8 | {inc['repack']['best_seconds'] * 1e3:.1f} ms (full repack {inc['full_repack']['best_seconds']:.2f} s, byte-equal: {inc['equal_to_full_pack']}) |")
rel = pack2m.get("relayout_after_resolution_stroke")
if rel:
    print(f"| repack after a resolution stroke adding 100k samples (`relayout_after_resolution_stroke`), RGBA8 | {rel['relayout']['best_seconds'] * 1e3:.0f} ms ({rel['ratio_to_memcpy']:.1f}× memcpy; the full repack into reused buffers it replaces {rel['rebuild']['best_seconds']:.2f} s; byte-equal: {rel['equal_to_full_pack']}) |")
for row in bunny16:
    r = row.get("relayout_after_resolution_stroke")
    after = f"; after a 100k-sample resolution stroke {r['relayout']['best_seconds']:.3f} s ({r['ratio_to_memcpy']:.1f}×)" if r else ""
    print(f"| full repack, Bunny R = 16, {row['format']} (best of {row['pack']['runs']}) | fresh {row['pack']['best_seconds']:.3f} s ({row['ratio_to_memcpy']:.1f}× memcpy), into reused buffers {row['rebuild']['best_seconds']:.3f} s ({row['rebuild_ratio_to_memcpy']:.1f}×); reading the store alone {row['store_read_ratio_to_memcpy']:.1f}×{after} |")
def phases(load):
    p = load["phases"]
    names = ["import", "weld", "topology", "store", "pack", "upload", "bvh", "first_frame"]
    return ", ".join(f"{name.replace('_', ' ')} {p[name + '_seconds']:.2f}" for name in names)
opens = " · ".join(f"{load['total_seconds']:.2f}" for load in loads)
last = loads[-1]
print(f"| open the 1.08M-tri Duck export at R = 8 to the document on screen (`bench load`, three runs) | {opens} s; "
      f"the last: {phases(last)}; peak {last['peak_resident_on_screen_bytes'] / 1e9:.2f} GB on screen, "
      f"{last['peak_resident_bytes'] / 1e9:.2f} GB in paint mode |")
print(f"| `pack bunny.glb -r 64` (over the sample limit) | refused in {refuse[0]} s, peak {int(refuse[1]) / 1024:.0f} MB |")
if "frames" in idle:
    print(f"| editor idle on the Duck, view mode, Xvfb, 10 s | {idle['frames']} UI passes, {idle['cpu_seconds']:.2f} s CPU |")
else:
    print(f"| editor idle | {idle['skipped']} |")
print(f"| pick latency | {paint['pick_latency']['best_seconds'] * 1e6:.2f} µs best, {paint['pick_latency']['median_seconds'] * 1e6:.2f} µs median |")
EOF
