#!/usr/bin/env bash
# Every `shoal bench` figure of BENCHMARKS.md's performance table for this tree beside the same
# figure of an earlier revision, in one run: builds REF in a temporary worktree, then runs each
# workload with the two binaries alternately, ROUNDS times (3 unless set), and prints the median
# ticks/s of each and their ratio (this tree / REF; above 1 is faster).
#   bench/compare.sh                 # against the newest tag, or HEAD~1 without one
#   bench/compare.sh 9e7bd01         # against any revision
#   ROUNDS=5 bench/compare.sh v0.1.0 reef boids   # only these workloads
#   COUNT=instructions bench/compare.sh 9e7bd01    # instructions per agent-update instead
# Costs: one release build of REF (about 4 minutes on 2 cores) and about 5 minutes per round.
# COUNT=instructions counts what each binary executes under `valgrind --tool=callgrind` (one
# thread, no rounds: the count is the same from run to run, whatever else the machine runs) over
# two lengths of the same run, and prints the difference per agent-update: warm-up and world
# building cancel out (and `boids` has the reference kernel it runs beside it taken out). About
# 10 minutes for boids, reference, flock and reef at 10k; the 100k and 1,500-tick reef and the
# plan workloads are left out (each would take most of an hour under valgrind).
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

count="${COUNT:-speed}"
case "$count" in
    speed) ;;
    instructions)
        command -v valgrind >/dev/null || { echo "compare.sh: COUNT=instructions needs valgrind" >&2; exit 2; }
        ;;
    *) echo "compare.sh: COUNT is speed or instructions, not $count" >&2; exit 2 ;;
esac

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

# Instructions one agent-update of workload W costs: callgrind over T1 and T2 ticks (one
# thread), the difference over (T2 − T1) × agents updates.
instructions() {
    local bin="$1" species="$2" w="$3" n="$4" t1="$5" t2="$6" c1 c2
    total() {
        valgrind --tool=callgrind --callgrind-out-file=/dev/null "$bin" bench "$w" --agents "$n" \
            --ticks "$1" --threads 1 --behaviors "$species" 2>&1 >/dev/null |
            awk '/Collected :/ { print $4 }'
    }
    c1=$(total "$t1")
    c2=$(total "$t2")
    awk -v a="$c1" -v b="$c2" -v u="$(( (t2 - t1) * n ))" 'BEGIN { if (a > 0 && b > 0) printf "%.0f", (b - a) / u }'
}
if [ "$count" = instructions ]; then
    echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'), instructions per agent-update (callgrind, 1 thread)"
    printf '%-14s %12s %12s %8s\n' figure "$ref" HEAD ratio
    # name | workload agents ticks ticks (figures without an entry here are left out)
    for r in "boids|boids 10000 20 60" "reference|reference 10000 20 60" \
        "flock|flock 10000 20 60" "reef|reef 10000 10 30"; do
        name="${r%%|*}"
        want=0
        for x in "${rows[@]}"; do [ "${x%%|*}" = "$name" ] && want=1; done
        [ $want = 1 ] || continue
        read -r w n t1 t2 <<< "${r#*|}"
        ia=$(instructions "$old" "$work/tree/behaviors" "$w" "$n" "$t1" "$t2")
        ib=$(instructions "$new" "$root/behaviors" "$w" "$n" "$t1" "$t2")
        if [ "$w" = boids ] && [ -n "$ia" ] && [ -n "$ib" ]; then
            # `bench boids` runs the reference kernel as long after it, to print the ratio.
            ra=$(instructions "$old" "$work/tree/behaviors" reference "$n" "$t1" "$t2")
            rb=$(instructions "$new" "$root/behaviors" reference "$n" "$t1" "$t2")
            ia=$(( ia - ${ra:-0} ))
            ib=$(( ib - ${rb:-0} ))
        fi
        if [ -z "$ia" ] || [ -z "$ib" ]; then
            printf '%-14s %12s %12s %8s\n' "$name" "${ia:--}" "${ib:--}" -
            continue
        fi
        # Below 1: HEAD executes fewer instructions.
        printf '%-14s %12s %12s %7.3fx\n' "$name" "$ia" "$ib" "$(awk -v x="$ia" -v y="$ib" 'BEGIN { print (x > 0 ? y / x : 0) }')"
    done
    exit 0
fi

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
