#!/usr/bin/env bash
# One core held busy by another process: boids and reef (10k agents) at 1 and 2 threads, for each
# shoal binary given (default: target/release/shoal). The default (2 threads) should not be slower
# than 1 thread. Prints each run, each round's ratio (2 threads over 1), and with ROUNDS > 1 the
# median ratio of each binary and workload.
# Usage: [ROUNDS=5] bench/busy.sh [TICKS] [BIN...]
set -euo pipefail
ticks=${1:-600}
shift || true
bins=("${@:-target/release/shoal}")
rounds=${ROUNDS:-1}
ratios=$(mktemp)
sh -c 'while :; do :; done' &
busy=$!
trap 'rm -f "$ratios"; kill "$busy" 2>/dev/null || true' EXIT
for round in $(seq "$rounds"); do
    for bin in "${bins[@]}"; do
        for w in boids reef; do
            one="" two=""
            for t in 1 2; do
                r=$("$bin" bench "$w" --agents 10000 --ticks "$ticks" --threads "$t" |
                    awk -v w="$w" '$1 == w { print $4 }')
                if [ -z "$r" ]; then
                    echo "busy.sh: no $w figure from $bin (threads $t)" >&2
                    exit 1
                fi
                echo "$bin $w threads=$t ticks/s=$r"
                if [ "$t" = 1 ]; then one=$r; else two=$r; fi
            done
            ratio=$(awk -v a="$two" -v b="$one" 'BEGIN { printf "%.3f", a / b }')
            echo "$bin $w round=$round 2-over-1=$ratio"
            printf '%s\t%s\t%s\n' "$bin" "$w" "$ratio" >>"$ratios"
        done
    done
done
if [ "$rounds" -gt 1 ]; then
    for bin in "${bins[@]}"; do
        for w in boids reef; do
            awk -F'\t' -v b="$bin" -v w="$w" '$1 == b && $2 == w { print $3 }' "$ratios" | sort -n |
                awk -v b="$bin" -v w="$w" '{ v[NR] = $1 } END {
                    m = (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2
                    printf "%s %s median 2-over-1 = %.3f (%s to %s, %d rounds)\n", b, w, m, v[1], v[NR], NR
                }'
        done
    done
fi
