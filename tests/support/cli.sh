# Sourced by tests/cli/*.t.sh: a temporary folder $tmp removed on exit, fail(), run() and json_ok().

tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
# fail MESSAGE: prints MESSAGE after the script's name and exits 1.
fail() { echo "$(basename "$0"): $*"; exit 1; }

# run OUT CMD...: runs CMD with stdout in OUT and stderr in OUT.err; its exit code in $c.
run() { local out=$1; shift; set +e; "$@" >"$out" 2>"$out.err"; c=$?; set -e; }
# Parses JSON file $1 and evaluates the Python expression $2 on it as d.
json_ok() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert $2, d" "$1"; }
