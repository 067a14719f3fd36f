#!/usr/bin/env bash
# The window as a user feels it: orbit the camera with real right-button
# drags (Xvfb + xdotool) on each scene at 1280x720 and print the frame rate
# and the worst frame while the camera moved (octovox --frame-stats).
#
#   bash benches/window_orbit.sh [path/to/octovox]   (default: target/release/octovox)
#
# Needs Xvfb and xdotool (the window tests' packages) and ../shared/assets.
set -euo pipefail
cd "$(dirname "$0")/.."
bin="${1:-target/release/octovox}"
assets="../shared/assets"
work="$(mktemp -d)"
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$work"' EXIT
export XDG_RUNTIME_DIR="$work/xdg"
mkdir -m 700 "$XDG_RUNTIME_DIR"

"$bin" import "$assets/meshes/nefertiti.obj" -o "$work/nefertiti512.vox" --size 512 --up z >/dev/null

display=":$((200 + $$ % 300))"
Xvfb "$display" -screen 0 1600x1000x24 -nolisten tcp -noreset >/dev/null 2>&1 &
export DISPLAY="$display"
for _ in $(seq 100); do xdotool getdisplaygeometry >/dev/null 2>&1 && break; sleep 0.1; done

orbit() {
    local name="$1"; shift
    local log="$work/$name.log"
    "$bin" "$@" --size 1280x720 --frame-stats >"$log" 2>"$work/$name.err" &
    local app=$!
    for _ in $(seq 1200); do grep -q "octovox: ready" "$log" && break; sleep 0.1; done
    local window
    window="$(xdotool search --sync --name octovox | head -1)"
    xdotool windowfocus --sync "$window"
    # Three seconds of steady dragging, the way a hand orbits a model, from
    # a mouse reporting at 125 Hz (USB's default rate; a move every 8 ms):
    # one xdotool process for the whole drag (a process per move would take
    # the two cores from the window it measures).
    local moves=()
    for _ in $(seq 375); do moves+=(mousemove_relative -- 2 0 sleep 0.008); done
    xdotool mousemove --window "$window" 760 360 mousedown 3 "${moves[@]}" mouseup 3
    xdotool key ctrl+q
    wait "$app"
    printf '| %s | %s |\n' "$name" "$(grep -o 'frame-stats: .*' "$log" | cut -d' ' -f2-)"
}

echo "| scene (1280×720) | while orbiting |"
echo "|---|---|"
orbit demo
orbit teapot256 "$assets/vox/seed/teapot256.vox"
orbit nefertiti512 "$work/nefertiti512.vox"
