# Sourced by the bench scripts that alternate configurations (latency-bench.sh, showcase-bench.sh).
# busy: the machine's busy CPU ticks so far (/proc/stat); hz: ticks per second.
busy() { awk '/^cpu /{print $2 + $3 + $4 + $7 + $8 + $9; exit}' /proc/stat; }
hz=$(getconf CLK_TCK)
# split_config LABEL=OPTIONS: sets label and the array opts (options split at spaces).
split_config() {
    label=${1%%=*}
    read -r -a opts <<<"${1#*=}"
}
