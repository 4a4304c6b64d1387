#!/usr/bin/env bash
# Issue #29's frame target at a million triangles: each of the mega bench's meshes (geodesic sphere, torus and
# arch of about 1M triangles, `rubble-bench decomposition --mega --write-mega`) stands as a static object in a
# scene of its own and is shot 10 times a second for SECONDS through the runtime on Bullet (`rubble-bench
# scene`, paced at 60 Hz like a game). Two runs per mesh: results adopted inside the frame
# (--no-idle-adoption), and adopted in the idle time after it (the default, which a game gets by adopting
# before it renders). One row per run in OUT/mega_scene.csv (LABEL in its build column; APPEND=1 keeps the
# rows already there, so two builds can be measured one after the other into one table), drawn in
# OUT/mega_scene.png (bench/results/mega_scene.gp); the meshes and scenes go to a temporary folder.
# Usage: [APPEND=1] scripts/mega-scene-bench.sh [BUILD_DIR=build-rel] [SECONDS=20] [LABEL=this]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
. "$root/scripts/bench-lib.sh"
build="${1:-$root/build-rel}"
seconds="${2:-20}"
label="${3:-this}"
bench="$build/bin/rubble-bench"
need_binary mega-scene-bench "$bench" "make release"
python=/usr/bin/python3
[ -x "$python" ] || python=python3

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$bench" decomposition --mega --write-mega "$work" --mega-kinds geosphere torus arch --mega-sizes 1000000 >/dev/null
csv="$results/mega_scene.csv"
if [ "${APPEND:-0}" != 1 ] || [ ! -f "$csv" ]; then
    echo "mesh,triangles,scale,adoption,seconds,shots_per_second,impacts,fractures,failed,frame_p50_ms,frame_p99_ms,frame_max_ms,physics_p99_ms,idle_adoption_p99_ms,idle_adoption_max_ms,latency_p50_ms,latency_p99_ms,remainder_triangles,peak_rss_mb,other_cpu_cores,build" >"$csv"
fi
tex="$root/assets/textures"
for obj in "$work"/*.obj; do
    name=$(basename "$obj" .obj)
    case "$name" in # about 20 m across, standing on the ground (whose top is at y = -10)
    geosphere_*) scale=10 y=0 ;;
    torus_*) scale=8 y=-7.6 ;;
    arch_*) scale=2 y=-10 ;;
    esac
    cfg="$work/$name.cfg"
    {
        echo "$tex/skybox/top.png;$tex/skybox/bottom.png;$tex/skybox/left.png;$tex/skybox/right.png;$tex/skybox/front.png;$tex/skybox/back.png"
        echo ";$tex/ground.png;0;-15;0;1000;10;1000;0"
        echo "$root/assets/models/fighter.obj;$tex/metal.png;0;20;90;1;1;1;100"
        echo "$obj;$tex/concrete.png;0;$y;-40;$scale;$scale;$scale;0"
    } >"$cfg"
    for adoption in in_frame idle; do
        extra=()
        [ "$adoption" = in_frame ] && extra=(--no-idle-adoption)
        echo "== $name x$scale, adoption $adoption, $seconds s at 10 shots/s"
        "$bench" scene "$cfg" --seconds "$seconds" --shots-per-second 10 "${extra[@]}" --json >"$work/run.json"
        "$python" - "$work/run.json" "$name" "$scale" "$adoption" "$seconds" "$label" >>"$csv" <<'EOF'
import json, sys
d = json.load(open(sys.argv[1]))
name, scale, adoption, seconds, label = sys.argv[2:7]
tris = name.split('_')[1]
row = [name.split('_')[0], tris, scale, adoption, seconds, 10, d['impacts'], d['fractures'], d['failed'],
       d['frame_ms']['p50'], d['frame_ms']['p99'], d['frame_ms']['max'], d['physics_ms']['p99'],
       d['idle_adoption_ms']['p99'], d['idle_adoption_ms']['max'], d['latency_ms']['p50'], d['latency_ms']['p99'],
       d['world_max_triangles'], d['peak_rss_mb'], d['cpu_cores']['other'], label]
print(','.join(f'{x:.3f}' if isinstance(x, float) else str(x) for x in row))
EOF
        tail -1 "$csv"
    done
done
if command -v gnuplot >/dev/null; then
    (cd "$results" && gnuplot -e "csv='$csv'; png='$results/mega_scene.png'" "$root/bench/results/mega_scene.gp")
    echo "plot: $results/mega_scene.png"
fi
echo "CSV: $csv"
