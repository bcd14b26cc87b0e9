#!/usr/bin/env bash
# The editor on a Wayland compositor: weston's headless backend (apt-get install weston),
# the editor started with WAYLAND_DISPLAY and no DISPLAY (winit takes Wayland; window
# decorations from sctk-adwaita), a screenshot through weston-screenshooter.
#   tools/wayland_screenshot.sh BINARY OUTPUT.png
# e.g. tools/wayland_screenshot.sh target/release/meshpaint screenshots/wayland_weston.png
set -euo pipefail
bin=$(realpath "$1")
out=$(realpath -m "$2")
export XDG_RUNTIME_DIR=$(mktemp -d)
chmod 700 "$XDG_RUNTIME_DIR"
weston --backend=headless-backend.so --socket=meshpaint-wayland --width=1280 --height=800 \
  --debug --use-pixman > "$XDG_RUNTIME_DIR/weston.log" 2>&1 &
weston_pid=$!
trap 'kill "$weston_pid" 2>/dev/null || true; rm -rf "$XDG_RUNTIME_DIR"' EXIT
sleep 3
env -u DISPLAY WAYLAND_DISPLAY=meshpaint-wayland RUST_LOG=info timeout 30 "$bin" \
  > "$XDG_RUNTIME_DIR/meshpaint.log" 2>&1 &
sleep 15
(cd "$XDG_RUNTIME_DIR" && WAYLAND_DISPLAY=meshpaint-wayland weston-screenshooter)
cp "$XDG_RUNTIME_DIR"/wayland-screenshot-*.png "$out"
grep -E "GPU:|Opened" "$XDG_RUNTIME_DIR/meshpaint.log"
