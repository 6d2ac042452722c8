#!/usr/bin/env bash
# Two commands' CPU time, measured with both running at once on one core, so that whatever else
# the host does (other guests, frequency changes, a busy spell) falls on both alike: the
# scheduler interleaves them every few milliseconds. Prints each round's ratio A/B (above 1: B
# takes less CPU time) and their median. On the shared 2-vCPU host of BENCHMARKS.md the same
# binary against itself gives 0.999–1.004 a round, where alternating runs spread over ±20 %.
# Meant for one-thread runs (`--threads 1`): a command's own threads would share the core too.
#   bench/same-core.sh 6 'old/shoal run scenarios/reef.ron --threads 1 --out /tmp/a -q' \
#                        'target/release/shoal run scenarios/reef.ron --threads 1 --out /tmp/b -q'
# Usage: bench/same-core.sh ROUNDS CMD_A CMD_B   (CORE=k picks the core; the last by default)
set -euo pipefail
[ $# -eq 3 ] || { echo "usage: bench/same-core.sh ROUNDS CMD_A CMD_B" >&2; exit 2; }
rounds=$1 a=$2 b=$3
core=${CORE:-$(( $(nproc) - 1 ))}
command -v taskset >/dev/null || { echo "same-core.sh: needs taskset (util-linux)" >&2; exit 2; }
[ -x /usr/bin/time ] || { echo "same-core.sh: needs GNU time at /usr/bin/time" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for _ in $(seq "$rounds"); do
    /usr/bin/time -f "%U %S" -o "$work/a" taskset -c "$core" bash -c "$a" >/dev/null 2>"$work/ea" &
    pa=$!
    /usr/bin/time -f "%U %S" -o "$work/b" taskset -c "$core" bash -c "$b" >/dev/null 2>"$work/eb" &
    pb=$!
    wait "$pa" || { echo "same-core.sh: A failed:" >&2; cat "$work/ea" >&2; exit 1; }
    wait "$pb" || { echo "same-core.sh: B failed:" >&2; cat "$work/eb" >&2; exit 1; }
    awk '{ print $1 + $2 }' "$work/a" | tail -1 >"$work/ta"
    awk '{ print $1 + $2 }' "$work/b" | tail -1 >"$work/tb"
    paste "$work/ta" "$work/tb"
done | awk '{ a[NR] = $1; b[NR] = $2; r[NR] = $1 / $2; printf "round %d: A %.3f s, B %.3f s, A/B %.3f\n", NR, $1, $2, $1 / $2 }
    END {
        n = NR
        if (n == 0) exit
        for (i = 1; i <= n; i++) for (j = i + 1; j <= n; j++) if (r[j] < r[i]) { t = r[i]; r[i] = r[j]; r[j] = t }
        m = (n % 2) ? r[(n + 1) / 2] : (r[n / 2] + r[n / 2 + 1]) / 2
        printf "median A/B %.3f (%.3f to %.3f, %d rounds)\n", m, r[1], r[n], n
    }'
