#!/usr/bin/env bash
# What the denoiser costs the window while it accumulates: the showroom at
# 1280x720 at rest, from the first noise report (2 samples) to the 16th
# sample, with the Denoise box on (the default) and off (--no-denoise),
# alternated, under Xvfb.
#
#   bash benches/window_denoise.sh [path/to/octovox] [runs]   (default: target/release/octovox, 2)
#
# Needs Xvfb (the window tests' package).
set -euo pipefail
cd "$(dirname "$0")/.."
bin="${1:-target/release/octovox}"
runs="${2:-2}"
work="$(mktemp -d)"
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$work"' EXIT
export XDG_RUNTIME_DIR="$work/xdg"
mkdir -m 700 "$XDG_RUNTIME_DIR"

display=":$((200 + $$ % 300))"
Xvfb "$display" -screen 0 1600x1000x24 -nolisten tcp -noreset >/dev/null 2>&1 &
export DISPLAY="$display"
for _ in $(seq 100); do xdotool getdisplaygeometry >/dev/null 2>&1 && break; sleep 0.1; done

# Seconds from the line starting with $2 to the line starting with $3 of
# the window's output, as it runs.
accumulate() {
    local log="$work/run.log"
    "$bin" --demo showroom --size 1280x720 --spp 16 "$@" >"$log" 2>"$work/run.err" &
    local app=$!
    local start="" now
    for _ in $(seq 6000); do
        now="$(date +%s.%N)"
        if [ -z "$start" ] && grep -q "^noise: .* at 2 samples" "$log"; then start="$now"; fi
        if grep -q "^path: 16 samples" "$log"; then break; fi
        sleep 0.05
    done
    kill "$app" 2>/dev/null || true
    wait "$app" 2>/dev/null || true
    awk "BEGIN { printf \"%.1f\", $now - $start }"
}

echo "| run | denoise on: s from sample 2 to 16 | off |"
echo "|---|---|---|"
for run in $(seq "$runs"); do
    on="$(accumulate)"
    off="$(accumulate --no-denoise)"
    echo "| $run | $on | $off |"
done
