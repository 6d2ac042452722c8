#!/usr/bin/env bash
# Runs every figure BENCHMARKS.md records, printing each command before its output.
#   bench/report.sh            # everything (about 5 minutes on 2 cores once bench/peers has
#                              # installed Mesa in its virtualenv, which the first run does)
#   bench/report.sh quick      # without the scaling sweeps and the peer comparison
# Each `shoal bench` line measures REPEAT times (3 unless set) and prints the run of median
# speed with the slowest and fastest (`--repeat`); memory is the first run's. The tick workloads
# print, under each row, the median run's time per tick in each stage (`--stages`).
set -uo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
cargo build --release -q
shoal=./target/release/shoal
repeat="${REPEAT:-3}"
run() {
    echo
    echo "\$ $*   # load average: $(cut -d' ' -f1-3 /proc/loadavg)"
    "$@"
}
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC')"
echo "commit: $(git rev-parse --short HEAD 2>/dev/null || echo '?')"
echo "nproc: $(nproc)"
lscpu | grep -E '^(Model name|CPU\(s\)|Thread|L1d|L2|L3|Hypervisor)' || true
run $shoal bench boids --repeat "$repeat" --stages
run $shoal bench boids --threads 1 --repeat "$repeat" --stages
run $shoal bench flock --repeat "$repeat" --stages
run $shoal bench reef --repeat "$repeat" --stages
run $shoal bench reef-native --repeat "$repeat" --stages
run $shoal bench reef --agents 100000 --ticks 20 --repeat "$repeat" --stages
run $shoal bench reef-native --agents 100000 --ticks 20 --repeat "$repeat" --stages
run $shoal bench decide --repeat "$repeat"
run $shoal bench decide --threads 1 --repeat "$repeat"
run $shoal bench decide-native --threads 1 --repeat "$repeat"
run $shoal bench perceive --repeat "$repeat"
run $shoal bench plan --repeat "$repeat"
if [ "${1:-}" != quick ]; then
    # One process per size: the memory column is then not blurred by what earlier sizes left in
    # the allocator.
    for w in boids reef; do
        for n in 1000 2000 5000 10000 20000 50000 100000 200000; do
            run $shoal bench $w --agents $n --ticks 20 --repeat "$repeat"
        done
    done
    run bench/peers/run.sh --repeat 3 1000:100
    run bench/peers/run.sh 10000:10
fi
