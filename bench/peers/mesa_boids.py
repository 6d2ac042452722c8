"""Times Mesa's BoidFlockers example (Mesa 3.3.x API) on a given workload.

Usage: python mesa_boids.py AGENTS SIDE VISION STEPS SEED
Prints one line: `mesa agents=N side=S vision=V steps=T seconds=X neighbors=K`, where seconds
covers the steps only (the model is built before the clock starts) and neighbors is the mean
number of other boids within vision after the last step.
"""

import sys
import time

import numpy as np
from mesa.examples.basic.boid_flockers.model import BoidFlockers


def main():
    n, side, vision, steps, seed = (
        int(sys.argv[1]),
        float(sys.argv[2]),
        float(sys.argv[3]),
        int(sys.argv[4]),
        int(sys.argv[5]),
    )
    model = BoidFlockers(
        population_size=n, width=side, height=side, vision=vision, seed=seed
    )
    t0 = time.perf_counter()
    for _ in range(steps):
        model.step()
    seconds = time.perf_counter() - t0
    pos = np.array([a.position for a in model.agents])
    # Torus distances, as the model's space measures them.
    d = np.abs(pos[:, None, :] - pos[None, :, :]) if n <= 5000 else None
    if d is not None:
        d = np.minimum(d, side - d)
        dist = np.sqrt((d**2).sum(axis=2))
        neighbors = ((dist <= vision).sum(axis=1) - 1).mean()
    else:
        neighbors = float("nan")
    print(
        f"mesa agents={n} side={side:g} vision={vision:g} steps={steps} "
        f"seconds={seconds:.3f} neighbors={neighbors:.1f}"
    )


if __name__ == "__main__":
    main()
