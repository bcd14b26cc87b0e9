#!/usr/bin/env bash
# The editor with its painting tools in view (colour wheel, hex field, recent colours, brush
# presets, the heat map with its legend), as a PNG: the real window under Xvfb, one stroke
# painted with each of three colours, the heat map on (or, with FINAL_KEY=F1, the help window
# instead; COLORS="" paints nothing). Settings go to a temporary directory.
#   tools/tools_screenshot.sh [OUT.png] [path/to/meshpaint]
set -euo pipefail
out=${1:-target/test-output/tools.png}
bin=${2:-target/debug/meshpaint}
work=$(mktemp -d)
display=:$((300 + RANDOM % 200))
Xvfb "$display" -screen 0 1280x1250x24 -nolisten tcp >/dev/null 2>&1 &
xvfb=$!
trap 'kill "$app" "$xvfb" 2>/dev/null || true; rm -rf "$work"' EXIT
sleep 1
DISPLAY=$display MESHPAINT_CONFIG_DIR=$work XDG_STATE_HOME=$work "$bin" >"$work/log" 2>&1 &
app=$!
export DISPLAY=$display
window=$(xdotool search --sync --name meshpaint | head -1)
xdotool windowsize --sync "$window" 1280 1250
xdotool windowmove "$window" 0 0
xdotool windowfocus --sync "$window"
sleep 8 # the Duck opens
xdotool key Tab
sleep 2
# "Resolution follows the brush", so the strokes raise R and the heat map shows it.
xdotool mousemove "${FOLLOW_X:-34}" "${FOLLOW_Y:-613}" click 1
sleep 1
# Three strokes, each in another colour typed into the hex field (found by its position
# in the side panel: read it off a screenshot when the layout changes).
hex_x=${HEX_X:-140}
hex_y=${HEX_Y:-360}
y=${STROKE_Y:-520}
for color in ${COLORS-ff8800 2a7fff 33cc44}; do
    xdotool mousemove "$hex_x" "$hex_y" click 1 key ctrl+a type "$color"
    xdotool key Return
    sleep 1
    x=${STROKE_X:-760}
    xdotool mousemove "$x" "$y" mousedown 1 mousemove $((x + 60)) $((y + 10)) mousemove $((x + 120)) $((y + 20)) mousemove $((x + 180)) $((y + 20)) mouseup 1
    y=$((y + ${STROKE_DY:-120}))
    sleep 2
done
xdotool mousemove 1200 1200
xdotool key "${FINAL_KEY:-h}"
sleep 3
mkdir -p "$(dirname "$out")"
import -window root "$out"
echo "$out"
