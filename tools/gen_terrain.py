#!/usr/bin/env python3
"""Writes the demonstration valley: assets/terrain/valley.asc and valley_features.ron.

Deterministic, Python 3 standard library only. Run from the repository root:

    python3 tools/gen_terrain.py

The map is 256 x 256 cells of 2 m (512 m square); world x = 2*col + 1 and z = 2*row + 1 at cell
centres (row 0 is the north edge; yllcorner is -512 so that z runs from 0 to 512).

What is on it:
- rolling fractal hills (value-noise fBm) over the whole map;
- an east-west ridge across the middle with flanks too steep for a 30-degree species;
- a wide saddle (the pass) through the ridge in the east, gentle enough for a wedge;
- a slot canyon through the ridge in the west, 4 cells (8 m) wide between vertical walls (the
  cells against the walls count as steep, so 2 cells are passable): wide enough for a column,
  too narrow for a wedge;
- a river valley meandering west-east across the south, with a river along its floor;
- a road from the northern village through the pass, over a bridge, to the southern hamlet;
- woods, a pond, buildings, and a small patch without data (a quarry) in the north-east.
"""

import math
import os

COLS = ROWS = 256
CELL = 2.0
SEED = 20070419

RIDGE_ROW = 118  # centre row of the ridge
RIDGE_HALF = 14  # half-width of the ridge crest zone (cells)
RIDGE_HEIGHT = 70.0
PASS_COL, PASS_HALF = 220, 26  # saddle centre and half-width
GAP_COLS = range(58, 62)  # slot canyon floor: 4 cells (8 m) between vertical walls


def mix(z):
    z &= 0xFFFFFFFFFFFFFFFF
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & 0xFFFFFFFFFFFFFFFF
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & 0xFFFFFFFFFFFFFFFF
    return z ^ (z >> 31)


def lattice(seed, x, z):
    return (mix(seed ^ mix((x * 0x9E3779B1) ^ ((z * 0x85EBCA77) << 21))) >> 40) / float(1 << 24)


def value_noise(seed, x, z):
    x0, z0 = math.floor(x), math.floor(z)
    tx, tz = x - x0, z - z0
    sx, sz = tx * tx * (3 - 2 * tx), tz * tz * (3 - 2 * tz)
    a = lattice(seed, x0, z0)
    b = lattice(seed, x0 + 1, z0)
    c = lattice(seed, x0, z0 + 1)
    d = lattice(seed, x0 + 1, z0 + 1)
    top = a + (b - a) * sx
    bottom = c + (d - c) * sx
    return top + (bottom - top) * sz


def fbm(x, z, octaves=5, feature=48.0):
    total, amp, freq, norm = 0.0, 1.0, 1.0 / feature, 0.0
    for o in range(octaves):
        total += amp * value_noise(SEED + o, x * freq, z * freq)
        norm += amp
        amp *= 0.5
        freq *= 2.0
    return total / norm


def smoothstep(e0, e1, x):
    t = min(1.0, max(0.0, (x - e0) / (e1 - e0)))
    return t * t * (3 - 2 * t)


def river_row(col):
    """Row of the river's centre line at a column: a meander across the south."""
    return 196 + 14 * math.sin(col / 37.0) + 6 * math.sin(col / 11.0 + 1.3)


def height(col, row):
    h = 18.0 * fbm(col, row)
    # The ridge: a plateau with steep flanks.
    d = abs(row - RIDGE_ROW)
    ridge = RIDGE_HEIGHT * (1.0 - smoothstep(RIDGE_HALF, RIDGE_HALF + 22, d))
    # The pass: a wide saddle lowering the ridge to a gentle hump.
    saddle = 1.0 - smoothstep(PASS_HALF * 0.35, PASS_HALF, abs(col - PASS_COL))
    ridge *= 1.0 - 0.9 * saddle
    h += ridge
    # The slot canyon: the ridge cut away down to the rolling ground, leaving vertical walls.
    if col in GAP_COLS:
        h -= ridge
    # The river valley: a broad trough along the meander.
    rd = abs(row - river_row(col))
    h -= 10.0 * (1.0 - smoothstep(2.0, 26.0, rd))
    return h


def world(col, row):
    return (2.0 * col + 1.0, 2.0 * row + 1.0)


def write_asc(path):
    quarry = {(c, r) for c in range(228, 234) for r in range(20, 25)}
    lines = [
        "ncols         %d" % COLS,
        "nrows         %d" % ROWS,
        "xllcorner     0.0",
        "yllcorner     -512.0",
        "cellsize      %g" % CELL,
        "NODATA_value  -9999",
    ]
    for r in range(ROWS):
        row = []
        for c in range(COLS):
            if (c, r) in quarry:
                row.append("-9999")
            else:
                row.append("%.2f" % height(c, r))
        lines.append(" ".join(row))
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def pts(cells):
    return "[" + ", ".join("(%.1f, %.1f)" % world(c, r) for c, r in cells) + "]"


def rect(c0, r0, c1, r1):
    return [(c0, r0), (c1, r0), (c1, r1), (c0, r1)]


def write_features(path):
    items = []
    # Road: village (north-east) -> pass -> bridge -> hamlet (south-west).
    road = [(205, 30), (210, 60), (220, 92), (220, 118), (218, 146), (190, 170),
            (140, round(river_row(140))), (110, 222), (60, 232), (30, 236)]
    items.append("    Road(points: %s, width: 4.0)," % pts(road))
    # River along the valley floor, west to east.
    river = [(c, round(river_row(c))) for c in range(0, 256, 8)] + [(255, round(river_row(255)))]
    items.append("    River(points: %s, width: 6.0)," % pts(river))
    # Woods.
    items.append("    Vegetation(polygon: %s, density: 0.6)," % pts([(20, 20), (70, 14), (96, 40), (60, 70), (24, 60)]))
    items.append("    Vegetation(polygon: %s, density: 0.3)," % pts([(120, 150), (160, 148), (165, 175), (125, 180)]))
    items.append("    Vegetation(polygon: %s, density: 0.8)," % pts([(210, 228), (250, 222), (252, 250), (214, 252)]))
    # Pond.
    items.append("    Water(polygon: %s)," % pts([(100, 60), (112, 58), (116, 68), (104, 72)]))
    # Village in the north-east, hamlet in the south-west.
    for c0, r0 in [(206, 26), (214, 30), (206, 38), (184, 40)]:
        items.append("    Building(polygon: %s)," % pts(rect(c0, r0, c0 + 4, r0 + 3)))
    for c0, r0 in [(26, 242), (40, 240)]:
        items.append("    Building(polygon: %s)," % pts(rect(c0, r0, c0 + 3, r0 + 3)))
    items.append("    Point(at: (%.1f, %.1f), kind: Building)," % world(150, 60))
    items.append("    Point(at: (%.1f, %.1f), kind: Vegetation(0.9))," % world(90, 160))
    with open(path, "w") as f:
        f.write("// Generated by tools/gen_terrain.py; world (x, z) in metres.\n")
        f.write("Features(items: [\n" + "\n".join(items) + "\n])\n")


def main():
    out = os.path.join("assets", "terrain")
    os.makedirs(out, exist_ok=True)
    write_asc(os.path.join(out, "valley.asc"))
    write_features(os.path.join(out, "valley_features.ron"))


if __name__ == "__main__":
    main()
