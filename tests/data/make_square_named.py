"""Writes square_named.msh (and square_named_binary.msh): (-1,1)^2 in Gmsh MSH 4.1 (ASCII) with physical names.

Laid out as Gmsh writes a built-in-kernel model: points 1-4 (corners), curves 1 bottom,
2 right, 3 top, 4 left (p1 -> p2 -> p3 -> p4 -> p1), surface 1; node blocks per entity,
element blocks per entity. Physical groups (tags differ from the entity tags on purpose):
  Physical Curve("left") = 11 {4}, ("right") = 12 {2}, ("walls") = 13 {1, 3},
  ("sides") = 14 {4, 2}   (curves 2 and 4 in two groups each),
  Physical Surface("membrane") = 21 {1}.
The triangles are an N x N grid with perturbed interior nodes and diagonals chosen
pseudo-randomly, so the mesh is unstructured in effect. Also writes the same mesh as
binary MSH 4.1, square_named_binary.msh. Run: python3 make_square_named.py
"""

N = 6
h = 2.0 / N


def rand(i, j, k):
    # deterministic hash in [-1, 1)
    x = (i * 73856093) ^ (j * 19349663) ^ (k * 83492791)
    x = (x * 2654435761) % 2**32
    return x / 2**31 - 1.0


grid = {}
for j in range(N + 1):
    for i in range(N + 1):
        x, y = -1.0 + i * h, -1.0 + j * h
        if 0 < i < N and 0 < j < N:
            x += 0.2 * h * rand(i, j, 1)
            y += 0.2 * h * rand(i, j, 2)
        grid[i, j] = (x, y)

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


for p, k in enumerate([(0, 0), (N, 0), (N, N), (0, N)], start=1):
    take(0, p, [k])
take(1, 1, [(i, 0) for i in range(1, N)])
take(1, 2, [(N, j) for j in range(1, N)])
take(1, 3, [(i, N) for i in range(N - 1, 0, -1)])
take(1, 4, [(0, j) for j in range(N - 1, 0, -1)])
take(2, 1, [(i, j) for j in range(1, N) for i in range(1, N)])

curves = {
    1: [(i, 0) for i in range(N + 1)],
    2: [(N, j) for j in range(N + 1)],
    3: [(i, N) for i in range(N, -1, -1)],
    4: [(0, j) for j in range(N, -1, -1)],
}
triangles = []
for j in range(N):
    for i in range(N):
        a, b, c, d = (i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)
        if rand(i, j, 3) >= 0:
            triangles += [(a, b, c), (a, c, d)]
        else:
            triangles += [(a, b, d), (b, c, d)]

out = []
w = out.append
w("$MeshFormat\n4.1 0 8\n$EndMeshFormat")
w("$PhysicalNames\n6")
w('1 11 "left"\n1 12 "right"\n1 13 "walls"\n1 14 "sides"\n2 21 "membrane"\n2 22 "unused"')
w("$EndPhysicalNames")
w("$Entities\n4 4 1 0")
for p, (x, y) in enumerate([(-1, -1), (1, -1), (1, 1), (-1, 1)], start=1):
    w(f"{p} {x} {y} 0 0")
physical = {1: [13], 2: [12, 14], 3: [13], 4: [11, 14]}
ends = {1: (1, 2), 2: (2, 3), 3: (3, 4), 4: (4, 1)}
for c in range(1, 5):
    xs = [grid[k][0] for k in curves[c]]
    ys = [grid[k][1] for k in curves[c]]
    ph = physical[c]
    a, b = ends[c]
    w(f"{c} {min(xs)} {min(ys)} 0 {max(xs)} {max(ys)} 0 {len(ph)} {' '.join(map(str, ph))} 2 {a} -{b}")
w("1 -1 -1 0 1 1 0 1 21 4 1 2 3 4")
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
nlines = 4 * N
w(f"$Elements\n5 {nlines + len(triangles)} 1 {nlines + len(triangles)}")
e = 1
for c in range(1, 5):
    w(f"1 {c} 1 {N}")
    ks = curves[c]
    for m in range(N):
        w(f"{e} {tags[ks[m]]} {tags[ks[m + 1]]}")
        e += 1
w(f"2 1 2 {len(triangles)}")
for t in triangles:
    w(f"{e} {' '.join(str(tags[k]) for k in t)}")
    e += 1
w("$EndElements")
open(__file__.replace("make_square_named.py", "square_named.msh"), "w").write("\n".join(out) + "\n")

# The same mesh as binary MSH 4.1 (little endian, 8-byte size_t): square_named_binary.msh.
# $PhysicalNames stays text, as Gmsh writes it in binary files.
import struct

b = bytearray(b"$MeshFormat\n4.1 1 8\n")
b += struct.pack("<i", 1)
b += b"\n$EndMeshFormat\n$PhysicalNames\n6\n"
b += b'1 11 "left"\n1 12 "right"\n1 13 "walls"\n1 14 "sides"\n2 21 "membrane"\n2 22 "unused"\n'
b += b"$EndPhysicalNames\n$Entities\n"
size = lambda *xs: b"".join(struct.pack("<Q", x) for x in xs)
ints = lambda *xs: b"".join(struct.pack("<i", x) for x in xs)
dbl = lambda *xs: b"".join(struct.pack("<d", x) for x in xs)
b += size(4, 4, 1, 0)
for p, (x, y) in enumerate([(-1, -1), (1, -1), (1, 1), (-1, 1)], start=1):
    b += ints(p) + dbl(x, y, 0) + size(0)
for c in range(1, 5):
    xs = [grid[k][0] for k in curves[c]]
    ys = [grid[k][1] for k in curves[c]]
    a, e_ = ends[c]
    b += ints(c) + dbl(min(xs), min(ys), 0, max(xs), max(ys), 0)
    b += size(len(physical[c])) + ints(*physical[c]) + size(2) + ints(a, -e_)
b += ints(1) + dbl(-1, -1, 0, 1, 1, 0) + size(1) + ints(21) + size(4) + ints(1, 2, 3, 4)
b += b"\n$EndEntities\n$Nodes\n"
b += size(len(blocks), total, 1, total)
for dim, entity, nodes in blocks:
    b += ints(dim, entity, 0) + size(len(nodes))
    b += size(*[t for t, _ in nodes])
    for _, (x, y) in nodes:
        b += dbl(x, y, 0.0)
b += b"\n$EndNodes\n$Elements\n"
b += size(5, nlines + len(triangles), 1, nlines + len(triangles))
e = 1
for c in range(1, 5):
    b += ints(1, c, 1) + size(N)
    ks = curves[c]
    for m in range(N):
        b += size(e, tags[ks[m]], tags[ks[m + 1]])
        e += 1
b += ints(2, 1, 2) + size(len(triangles))
for t in triangles:
    b += size(e, *[tags[k] for k in t])
    e += 1
b += b"\n$EndElements\n"
open(__file__.replace("make_square_named.py", "square_named_binary.msh"), "wb").write(bytes(b))
