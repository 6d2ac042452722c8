#!/usr/bin/env bash
# Peer comparison on one machine, in one run: Mesa's BoidFlockers example (Python) against
# `shoal bench boids` on the same agent count, space, vision radius and step count.
#
#   bench/peers/run.sh                 # 1,000 agents × 100 steps and 10,000 agents × 10 steps
#   bench/peers/run.sh 1000:500 2000:50
#   bench/peers/run.sh --repeat 3 1000:100
#
# Steps: fewer than `shoal bench boids` times (500 at 1,000 agents, 200 at 10,000). Mesa's flock
# contracts as it runs: after 100 steps a boid has ~37 others within its vision (shoal's: ~30),
# after 500 steps ~217 (shoal's: ~32), so Mesa's per-step work grows sevenfold and a longer run
# no longer compares the same work. At 10,000 agents, 200 Mesa steps would also take 10–20 min.
#
# With --repeat K each pair is run K times, Mesa and shoal alternating, and the row gives the
# median of each side (the ratio is of the medians); the single runs are printed above it.
# Each shoal figure of a run is itself the median of SHOAL_RUNS runs (default 5).
#
# Mesa is installed from PyPI into bench/peers/.venv on first use (MESA_VENV overrides the path).
# Both sides: N agents, a square of side sqrt(N / 0.1) (0.1 agent per unit², Mesa's 1,000 on
# 100×100), vision radius 10, the same number of steps, model construction not timed. Mesa runs
# in one Python process (it is single-threaded); shoal runs on all cores and, for reference, on 1.
set -euo pipefail

here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
venv="${MESA_VENV:-$here/.venv}"
mesa_version="3.3.1"
seed=1

if [ ! -x "$venv/bin/python" ] || ! "$venv/bin/python" -c "import mesa" 2>/dev/null; then
    echo "installing mesa[network]==$mesa_version into $venv" >&2
    python3 -m venv "$venv"
    "$venv/bin/pip" install -q "mesa[network]==$mesa_version"
fi
(cd "$root" && cargo build --release -q)
shoal="$root/target/release/shoal"

repeat=1
if [ "${1:-}" = --repeat ]; then
    repeat="${2:?--repeat needs a count}"
    shift 2
fi
runs=("$@")
if [ ${#runs[@]} -eq 0 ]; then
    runs=(1000:100 10000:10)
fi

echo "date: $(date -u '+%Y-%m-%d %H:%M UTC')   machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p')"
echo "mesa $("$venv/bin/python" -c 'import mesa; print(mesa.__version__)'), python $("$venv/bin/python" -c 'import sys; print(sys.version.split()[0])'); shoal $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo '?')"
printf '%-7s %-6s %-6s %-10s %-12s %-6s %-10s %-12s %-6s %-12s %-9s %-9s\n' \
    agents side steps mesa_s mesa_upd/s m_nbrs shoal_s shoal_upd/s s_nbrs shoal1_upd/s ratio ratio_1t
# A shoal run of 1,000 agents × 100 steps lasts 50 ms, where one preemption shows: each shoal
# figure is the run of median speed among SHOAL_RUNS (5 unless set), `shoal bench --repeat`.
# Prints "agent-updates/s neighbors".
shoal_median() {
    # Columns of `shoal bench`: workload agents ticks ticks/s agent-upd/s ms/tick ns/upd nbrs
    # B/agent [slowest fastest].
    "$shoal" bench boids --agents "$1" --ticks "$2" --threads "$3" --repeat "${SHOAL_RUNS:-5}" |
        tail -1 | awk '{print $5, $8}'
}

for run in "${runs[@]}"; do
    n="${run%%:*}"
    steps="${run##*:}"
    side=$(python3 -c "import math; print(f'{max(math.sqrt($n / 0.1), 10.0):g}')")
    samples=()
    for ((r = 1; r <= repeat; r++)); do
        m=$("$venv/bin/python" "$here/mesa_boids.py" "$n" "$side" 10 "$steps" "$seed")
        m_s=$(sed -n 's/.*seconds=\([^ ]*\).*/\1/p' <<<"$m")
        m_k=$(sed -n 's/.*neighbors=\([^ ]*\).*/\1/p' <<<"$m")
        s=$(shoal_median "$n" "$steps" "$(nproc)")
        s1=$(shoal_median "$n" "$steps" 1)
        samples+=("$m_s $m_k $s $(awk '{print $1}' <<<"$s1")")
    done
    python3 - "$n" "$side" "$steps" "${samples[@]}" <<'PY'
import statistics
import sys
n, side, steps = int(sys.argv[1]), sys.argv[2], int(sys.argv[3])
runs = [a.split() for a in sys.argv[4:]]


def row(label, m_s, m_k, s_ups, s_k, s1_ups):
    m_ups = n * steps / m_s
    s_s = n * steps / s_ups
    print(f"{n:<7} {side:<6} {steps:<6} {m_s:<10.3f} {m_ups:<12.0f} {m_k:<6} {s_s:<10.4f} "
          f"{s_ups:<12.0f} {s_k:<6} {s1_ups:<12.0f} {s_ups / m_ups:<9.0f} {s1_ups / m_ups:<9.0f}"
          + (f" {label}" if label else ""))


if len(runs) > 1:
    for k, (m_s, m_k, s_ups, s_k, s1_ups) in enumerate(runs, 1):
        row(f"run {k}", float(m_s), m_k, float(s_ups), s_k, float(s1_ups))
med = lambda c: statistics.median(float(r[c]) for r in runs)
row("median" if len(runs) > 1 else "", med(0), runs[0][1], med(2), runs[0][3], med(4))
PY
done
