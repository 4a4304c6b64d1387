# Sourced by tests/cli/*.t.sh: run() and json_ok(), shared helpers of the scripts that check exit codes and JSON.

# run OUT CMD...: runs CMD with stdout in OUT and stderr in OUT.err; its exit code in $c.
run() { local out=$1; shift; set +e; "$@" >"$out" 2>"$out.err"; c=$?; set -e; }
# Parses JSON file $1 and evaluates the Python expression $2 on it as d.
json_ok() { python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert $2, d" "$1"; }
