# Sourced by the bench scripts after they set `root` (the repository): what each of them needs first.
# need_binary SCRIPT PATH [HOW]: stops SCRIPT when PATH, a binary of the build tree, is missing.
need_binary() { [ -x "$2" ] || { echo "$1: $2 not found (build the tree first${3:+: $3})" >&2; exit 1; }; }
# results: bench/results (RUBBLE_BENCH_RESULTS overrides), created.
results="${RUBBLE_BENCH_RESULTS:-$root/bench/results}"
mkdir -p "$results"
# media: the thesis's scenes and models (RUBBLE_SEED_MEDIA overrides); not part of the repository.
media="${RUBBLE_SEED_MEDIA:-$root/../shared/seed/media}"
# need_media SCRIPT FILE: stops SCRIPT cleanly (exit 0) when the thesis's FILE is absent.
need_media() {
    [ -f "$2" ] || { echo "$1: $2 not found: skipped (the thesis's scenes are not part of the repository)"; exit 0; }
}
# busy: the machine's busy CPU ticks so far (/proc/stat); hz: ticks per second.
busy() { awk '/^cpu /{print $2 + $3 + $4 + $7 + $8 + $9; exit}' /proc/stat; }
hz=$(getconf CLK_TCK)
# split_config LABEL=OPTIONS: sets label and the array opts (options split at spaces).
split_config() {
    label=${1%%=*}
    read -r -a opts <<<"${1#*=}"
}
