#!/usr/bin/env bash
# The README's animation and still: a showcase run of rubble-demo in an Xvfb window (llvmpipe) on
# demolition_block.cfg, a frame every 0.2 s of game time, made into docs/images/showcase.gif by ffmpeg (palette,
# 3x time-lapse, under 3 MB) and the last frame (the rubble at rest) into docs/images/showcase-rest.png.
# Usage: scripts/readme-animation.sh BUILD_DIR [SECONDS] [WIDTH]   (needs xvfb and ffmpeg: install-deps.sh all)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
. "$root/scripts/bench-lib.sh"
build="${1:?usage: scripts/readme-animation.sh BUILD_DIR [SECONDS] [WIDTH]}"
seconds="${2:-30}"
width="${3:-480}"
demo="$build/bin/rubble-demo"
need_binary readme-animation "$demo"
for tool in xvfb-run ffmpeg; do
    command -v "$tool" >/dev/null || { echo "readme-animation: $tool missing (scripts/install-deps.sh all)" >&2; exit 1; }
done
out=$(mktemp -d /tmp/rubble-animation.XXXXXX)
trap 'rm -rf "$out"' EXIT
images="$root/docs/images"

xvfb-run -a -s "-screen 0 1280x720x24" "$demo" --window --mute --scene "$root/assets/scenes/demolition_block.cfg" \
    --showcase --demolish 0.5 --autopilot "$seconds" --width 640 --height 360 --screenshot-every 0.2 \
    --out "$out" >"$out/log" 2>&1 || { tail -n 20 "$out/log"; exit 1; }
grep '^report:' "$out/log"
frames=$(ls "$out"/shot_*.png | wc -l)
[ "$frames" -gt 10 ] || { echo "readme-animation: only $frames frames" >&2; exit 1; }

ffmpeg -v error -y -framerate 15 -i "$out/shot_%04d.png" \
    -vf "scale=$width:-1:flags=lanczos,split[a][b];[a]palettegen=max_colors=96:stats_mode=diff[p];[b][p]paletteuse=dither=bayer:bayer_scale=4:diff_mode=rectangle" \
    "$out/showcase.gif"
size=$(stat -c %s "$out/showcase.gif")
[ "$size" -lt 3000000 ] || { echo "readme-animation: the GIF has $size bytes (over 3 MB): lower WIDTH" >&2; exit 1; }
cp "$out/showcase.gif" "$images/showcase.gif"
cp "$(ls "$out"/shot_*.png | tail -n 1)" "$images/showcase-rest.png"
python3 -c "import json,sys; r=json.load(open(sys.argv[1])); print('pieces live %d (awake %d, frozen %d)' % (r['pieces_live'], r['pieces_awake'], r['pieces_frozen']))" "$out/report.json"
echo "wrote $images/showcase.gif ($size bytes, $frames frames) and $images/showcase-rest.png"
