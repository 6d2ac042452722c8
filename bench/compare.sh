#!/usr/bin/env bash
# Every `shoal bench` figure of BENCHMARKS.md's performance table for this tree beside the same
# figure of an earlier revision, in one run: builds REF in a temporary worktree, then runs each
# workload with the two binaries alternately, ROUNDS times (3 unless set), and prints the median
# ticks/s of each and their ratio (this tree / REF; above 1 is faster).
#   bench/compare.sh                 # against the newest tag, or HEAD~1 without one
#   bench/compare.sh 9e7bd01         # against any revision
#   ROUNDS=5 bench/compare.sh v0.1.0 reef boids   # only these workloads
# Costs: one release build of REF (about 4 minutes on 2 cores) and about 5 minutes per round.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
ref="${1:-$(git describe --tags --abbrev=0 2>/dev/null || echo HEAD~1)}"
shift || true
rounds="${ROUNDS:-3}"
# name | arguments (each row is one figure of the table)
all=(
    "boids|boids --agents 10000 --ticks 300"
    "reference|reference --agents 10000 --ticks 300"
    "flock|flock --agents 10000 --ticks 100"
    "reef|reef --agents 10000 --ticks 100"
    "reef-1500|reef --agents 10000 --ticks 1500"
    "reef-100k|reef --agents 100000 --ticks 20"
    "plan|plan --ticks 5"
    "plan-weighted|plan-weighted --ticks 5"
)
rows=()
if [ $# -gt 0 ]; then
    for want in "$@"; do
        found=0
        for r in "${all[@]}"; do
            if [ "${r%%|*}" = "$want" ]; then rows+=("$r"); found=1; fi
        done
        [ $found = 1 ] || { echo "compare.sh: no figure named $want (have: ${all[*]%%|*})" >&2; exit 2; }
    done
else
    rows=("${all[@]}")
fi

work="$(mktemp -d)"
trap 'git worktree remove --force "$work/tree" >/dev/null 2>&1 || true; rm -rf "$work"' EXIT
git worktree add -q --detach "$work/tree" "$ref"
echo "building $ref ($(git rev-parse --short "$ref")) and this tree ($(git rev-parse --short HEAD)$(git diff --quiet || echo ', with changes'))" >&2
(cd "$work/tree" && CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$root/target}/compare-ref" cargo build --release -q -p shoal)
cargo build --release -q -p shoal
old="${CARGO_TARGET_DIR:-$root/target}/compare-ref/release/shoal"
new="${CARGO_TARGET_DIR:-$root/target}/release/shoal"

# The ticks/s of the row a `shoal bench` run prints for its workload. Each revision runs with
# its own `behaviors/` (the shipped species are part of what it is: a species file may use a
# key the older engine lacks).
speed() {
    local bin="$1" species="$2"; shift 2
    "$bin" bench "$@" --behaviors "$species" | awk -v w="$1" '$1 == w { print $4; exit }'
}
median() { sort -g | awk '{ a[NR] = $1 } END { print a[int((NR + 1) / 2)] }'; }

echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'), nproc $(nproc), $rounds rounds, load $(cut -d' ' -f1 /proc/loadavg)"
printf '%-14s %12s %12s %8s\n' figure "$ref" HEAD ratio
for r in "${rows[@]}"; do
    name="${r%%|*}"
    read -r -a args <<< "${r#*|}"
    a=(); b=()
    for _ in $(seq "$rounds"); do
        a+=("$(speed "$old" "$work/tree/behaviors" "${args[@]}")")
        b+=("$(speed "$new" "$root/behaviors" "${args[@]}")")
    done
    ma=$(printf '%s\n' "${a[@]}" | median)
    mb=$(printf '%s\n' "${b[@]}" | median)
    if [ -z "$ma" ] || [ -z "$mb" ]; then
        # A workload one of the two revisions does not have.
        printf '%-14s %12s %12s %8s\n' "$name" "${ma:--}" "${mb:--}" -
        continue
    fi
    printf '%-14s %12s %12s %7.2fx\n' "$name" "$ma" "$mb" "$(awk -v x="$ma" -v y="$mb" 'BEGIN { print (x > 0 ? y / x : 0) }')"
done
