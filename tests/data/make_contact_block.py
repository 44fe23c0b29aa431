"""Writes contact_block.msh: the block (0,2) x (0,1) in Gmsh MSH 4.1 (ASCII) for the
contact scene files (tests/contact_scene_files.rs).

Laid out as Gmsh writes a built-in-kernel model: points 1-4 (corners), curves 1 bottom,
2 right, 3 top, 4 left (p1 -> p2 -> p3 -> p4 -> p1), curve 5 the segment y = 1/2 inside
the block (an embedded curve: its lines lie on interior edges), surface 1. Physical
groups (tags differ from the entity tags on purpose):
  Physical Curve("foundation") = 31 {1}, ("side") = 32 {2}, ("top") = 33 {3},
  ("axis") = 34 {4}, ("midline") = 35 {5},  Physical Surface("block") = 41 {1}.
The triangles are an 2N x N grid with perturbed interior nodes (the row y = 1/2 kept
straight) and diagonals chosen pseudo-randomly. Run: python3 make_contact_block.py

With an angle in degrees (python3 make_contact_block.py 30) it writes
contact_block_turned30.msh, the same block turned by that angle about the origin (a
body on a foundation that is along neither axis).
"""
import math
import sys

ANGLE = float(sys.argv[1]) if len(sys.argv) > 1 else 0.0

N = 4
NX, NY = 2 * N, N
h = 1.0 / N
MID = NY // 2


def rand(i, j, k):
    # deterministic hash in [-1, 1)
    x = (i * 73856093) ^ (j * 19349663) ^ (k * 83492791)
    x = (x * 2654435761) % 2**32
    return x / 2**31 - 1.0


grid = {}
for j in range(NY + 1):
    for i in range(NX + 1):
        x, y = i * h, j * h
        if 0 < i < NX and 0 < j < NY:
            x += 0.2 * h * rand(i, j, 1)
            if j != MID:
                y += 0.2 * h * rand(i, j, 2)
        grid[i, j] = (x, y)

c_, s_ = math.cos(math.radians(ANGLE)), math.sin(math.radians(ANGLE))
for k, (x, y) in grid.items():
    grid[k] = (c_ * x - s_ * y, s_ * x + c_ * y) if ANGLE else (x, y)

tags = {}
blocks = []  # (dim, entity, [(tag, (x, y))])
next_tag = 1


def take(dim, entity, keys):
    global next_tag
    nodes = []
    for k in keys:
        tags[k] = next_tag
        nodes.append((next_tag, grid[k]))
        next_tag += 1
    blocks.append((dim, entity, nodes))


for p, k in enumerate([(0, 0), (NX, 0), (NX, NY), (0, NY)], start=1):
    take(0, p, [k])
take(1, 1, [(i, 0) for i in range(1, NX)])
take(1, 2, [(NX, j) for j in range(1, NY)])
take(1, 3, [(i, NY) for i in range(NX - 1, 0, -1)])
take(1, 4, [(0, j) for j in range(NY - 1, 0, -1)])
take(1, 5, [(i, MID) for i in range(1, NX)])
take(2, 1, [(i, j) for j in range(1, NY) for i in range(1, NX) if j != MID])

curves = {
    1: [(i, 0) for i in range(NX + 1)],
    2: [(NX, j) for j in range(NY + 1)],
    3: [(i, NY) for i in range(NX, -1, -1)],
    4: [(0, j) for j in range(NY, -1, -1)],
    5: [(i, MID) for i in range(NX + 1)],
}
triangles = []
for j in range(NY):
    for i in range(NX):
        a, b, c, d = (i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)
        if rand(i, j, 3) >= 0:
            triangles += [(a, b, c), (a, c, d)]
        else:
            triangles += [(a, b, d), (b, c, d)]

out = []
w = out.append
w("$MeshFormat\n4.1 0 8\n$EndMeshFormat")
w("$PhysicalNames\n6")
w('1 31 "foundation"\n1 32 "side"\n1 33 "top"\n1 34 "axis"\n1 35 "midline"\n2 41 "block"')
w("$EndPhysicalNames")
w("$Entities\n4 5 1 0")
for p, k in enumerate([(0, 0), (NX, 0), (NX, NY), (0, NY)], start=1):
    x, y = grid[k]
    w(f"{p} {x!r} {y!r} 0 0")
physical = {1: 31, 2: 32, 3: 33, 4: 34, 5: 35}
ends = {1: (1, 2), 2: (2, 3), 3: (3, 4), 4: (4, 1)}
for c in range(1, 6):
    xs = [grid[k][0] for k in curves[c]]
    ys = [grid[k][1] for k in curves[c]]
    bounding = f"2 {ends[c][0]} -{ends[c][1]}" if c in ends else "0"
    w(f"{c} {min(xs)} {min(ys)} 0 {max(xs)} {max(ys)} 0 1 {physical[c]} {bounding}")
xs = [p[0] for p in grid.values()]
ys = [p[1] for p in grid.values()]
w(f"1 {min(xs)!r} {min(ys)!r} 0 {max(xs)!r} {max(ys)!r} 0 1 41 4 1 2 3 4")
w("$EndEntities")
total = sum(len(b[2]) for b in blocks)
w(f"$Nodes\n{len(blocks)} {total} 1 {total}")
for dim, entity, nodes in blocks:
    w(f"{dim} {entity} 0 {len(nodes)}")
    for t, _ in nodes:
        w(str(t))
    for _, (x, y) in nodes:
        w(f"{x!r} {y!r} 0")
w("$EndNodes")
lines = {c: len(curves[c]) - 1 for c in curves}
nlines = sum(lines.values())
w(f"$Elements\n6 {nlines + len(triangles)} 1 {nlines + len(triangles)}")
e = 1
for c in range(1, 6):
    w(f"1 {c} 1 {lines[c]}")
    ks = curves[c]
    for m in range(lines[c]):
        w(f"{e} {tags[ks[m]]} {tags[ks[m + 1]]}")
        e += 1
w(f"2 1 2 {len(triangles)}")
for t in triangles:
    w(f"{e} {' '.join(str(tags[k]) for k in t)}")
    e += 1
w("$EndElements")
name = f"contact_block_turned{ANGLE:g}.msh" if ANGLE else "contact_block.msh"
open(__file__.replace("make_contact_block.py", name), "w").write("\n".join(out) + "\n")
