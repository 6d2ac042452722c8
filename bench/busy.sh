#!/usr/bin/env bash
# One core held busy by another process: boids and reef (10k agents) at 1 and 2 threads, for each
# shoal binary given (default: target/release/shoal). The default (2 threads) should not be slower
# than 1 thread. Usage: bench/busy.sh [TICKS] [BIN...]
set -euo pipefail
ticks=${1:-600}
shift || true
bins=("${@:-target/release/shoal}")
sh -c 'while :; do :; done' &
busy=$!
trap 'kill $busy' EXIT
for bin in "${bins[@]}"; do
    for w in boids reef; do
        for t in 1 2; do
            r=$("$bin" bench "$w" --agents 10000 --ticks "$ticks" --threads "$t" | awk -v w="$w" '$1 == w { print $4 }')
            echo "$bin $w threads=$t ticks/s=$r"
        done
    done
done
