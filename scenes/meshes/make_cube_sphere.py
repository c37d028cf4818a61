"""Make scenes/meshes/cube_sphere.obj: the unit sphere as a cube's six faces, each subdivided
into 16 x 16 quads (two triangles each) and pushed onto the sphere, with a cube-map UV atlas:
each face its own chart, a square of side 0.3 in a 3 x 2 layout, turned by a multiple of 90
degrees, the last face mirrored, so that every cube edge is a UV cut whose two sides are turned
against each other (paper 000 Fig. 8's second parameterisation). Standard library only:
python3 make_cube_sphere.py"""
import math

N = 16
# Each face: origin corner and the two edge vectors (counter-clockwise seen from outside).
FACES = [
    ((1, -1, 1), (0, 0, -2), (0, 2, 0)),  # +x
    ((-1, -1, -1), (0, 0, 2), (0, 2, 0)),  # -x
    ((-1, 1, 1), (2, 0, 0), (0, 0, -2)),  # +y
    ((-1, -1, -1), (2, 0, 0), (0, 0, 2)),  # -y
    ((-1, -1, 1), (2, 0, 0), (0, 2, 0)),  # +z
    ((1, -1, -1), (-2, 0, 0), (0, 2, 0)),  # -z
]
TURNS = [0, 1, 2, 3, 1, 0]
MIRRORED = [False, False, False, False, False, True]
SIDE = 0.3

lines = ["# cube_sphere.obj: made by make_cube_sphere.py"]
positions, uvs, faces = [], [], []
for f, (origin, du, dv) in enumerate(FACES):
    col, row = f % 3, f // 3
    centre = ((col + 0.5) / 3, (row + 0.5) / 2)
    base = len(positions)
    for j in range(N + 1):
        for i in range(N + 1):
            a, b = i / N, j / N
            p = [origin[k] + a * du[k] + b * dv[k] for k in range(3)]
            length = math.sqrt(sum(c * c for c in p))
            positions.append([c / length for c in p])
            x, y = a - 0.5, b - 0.5
            if MIRRORED[f]:
                y = -y
            for _ in range(TURNS[f]):
                x, y = -y, x
            uvs.append((centre[0] + SIDE * x, centre[1] + SIDE * y))
    for j in range(N):
        for i in range(N):
            v00 = base + j * (N + 1) + i
            v10, v01, v11 = v00 + 1, v00 + N + 1, v00 + N + 2
            faces += [(v00, v10, v11), (v00, v11, v01)]
for p in positions:
    lines.append("v %.6f %.6f %.6f" % tuple(p))
for u in uvs:
    lines.append("vt %.6f %.6f" % u)
for t in faces:
    lines.append("f " + " ".join("%d/%d" % (v + 1, v + 1) for v in t))
with open("cube_sphere.obj", "w") as out:
    out.write("\n".join(lines) + "\n")
