"""Make scenes/meshes/spot_atlas.obj and spot_box_uv.obj: Keenan Crane's Spot (spot.glb: the
same positions and triangles, with the same smooth normals, the area-weighted mean of each
welded vertex's triangles', which the glb lacks) under two UV parameterisations, for paper 000
Fig. 8 on a character mesh. spot_atlas.obj has Spot's own atlas; spot_box_uv.obj the box
projection an automatic unwrapper makes:
- each triangle goes to the axis (+-x, +-y, +-z) its normal is nearest to;
- charts are the edge-connected groups of triangles of one axis; a chart of fewer than MIN_CHART
  triangles joins the neighbouring chart it shares most edges with, if all its triangles face
  that chart's axis by more than FACING (so that the projection stays one to one);
- each chart is projected orthographically along its axis (unmirrored: the basis (e1, e2) has
  e1 x e2 = the axis, so a triangle facing the axis stays counter-clockwise in UV);
- the charts are shelf-packed into the unit square at one common scale, MARGIN apart.
So charts meet at cuts turned by multiples of 90 degrees, the UV map shrinks area by up to
sqrt(3) where the surface faces away from its axis (1 / FACING in merged charts), and its charts
differ wholly from Spot's own atlas. Standard library only: python3 make_spot_parameterisations.py (run in this folder)."""
import json
import math
import struct

MIN_CHART = 40
FACING = 0.3
MARGIN = 0.01

# The basis of each axis' projection plane: (axis, e1, e2) with e1 x e2 = axis.
AXES = [
    ((1, 0, 0), (0, 1, 0), (0, 0, 1)),
    ((-1, 0, 0), (0, 0, 1), (0, 1, 0)),
    ((0, 1, 0), (0, 0, 1), (1, 0, 0)),
    ((0, -1, 0), (1, 0, 0), (0, 0, 1)),
    ((0, 0, 1), (1, 0, 0), (0, 1, 0)),
    ((0, 0, -1), (0, 1, 0), (1, 0, 0)),
]


def read_glb(path):
    """Positions and triangles of the glb's one primitive (float32 positions, u32 indices)."""
    data = open(path, "rb").read()
    json_length = struct.unpack_from("<I", data, 12)[0]
    gltf = json.loads(data[20 : 20 + json_length])
    binary = data[20 + json_length + 8 :]
    primitive = gltf["meshes"][0]["primitives"][0]

    def accessor(index, fmt, width):
        acc = gltf["accessors"][index]
        view = gltf["bufferViews"][acc["bufferView"]]
        start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
        values = struct.unpack_from("<%d%s" % (acc["count"] * width, fmt), binary, start)
        return [values[i : i + width] for i in range(0, len(values), width)]

    positions = accessor(primitive["attributes"]["POSITION"], "f", 3)
    uvs = accessor(primitive["attributes"]["TEXCOORD_0"], "f", 2)
    indices = [i[0] for i in accessor(primitive["indices"], "I", 1)]
    return positions, uvs, [tuple(indices[i : i + 3]) for i in range(0, len(indices), 3)]


def sub(a, b):
    return [a[k] - b[k] for k in range(3)]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def dot(a, b):
    return sum(a[k] * b[k] for k in range(3))


glb_positions, glb_uvs, glb_triangles = read_glb("spot.glb")
# Weld the glb's vertices (split at its own UV seams) by position.
welded, positions = {}, []
for p in glb_positions:
    if p not in welded:
        welded[p] = len(positions)
        positions.append(p)
triangles = [tuple(welded[glb_positions[i]] for i in t) for t in glb_triangles]

normals = []
vertex_normals = [[0.0, 0.0, 0.0] for _ in positions]
for a, b, c in triangles:
    n = cross(sub(positions[b], positions[a]), sub(positions[c], positions[a]))
    for v in (a, b, c):
        vertex_normals[v] = [vertex_normals[v][k] + n[k] for k in range(3)]
    length = math.sqrt(dot(n, n))
    normals.append([x / length for x in n])
vertex_normals = [[x / math.sqrt(dot(n, n)) for x in n] for n in vertex_normals]

edge_triangles = {}
for t, tri in enumerate(triangles):
    for k in range(3):
        edge = tuple(sorted((tri[k], tri[(k + 1) % 3])))
        edge_triangles.setdefault(edge, []).append(t)
neighbours = [[] for _ in triangles]
for ts in edge_triangles.values():
    for t in ts:
        neighbours[t] += [s for s in ts if s != t]

# Charts: connected components of triangles of one axis.
axis_of = [max(range(6), key=lambda a: dot(n, AXES[a][0])) for n in normals]
chart_of = [-1] * len(triangles)
charts = []
for seed in range(len(triangles)):
    if chart_of[seed] >= 0:
        continue
    chart_of[seed] = len(charts)
    members, stack = [], [seed]
    while stack:
        t = stack.pop()
        members.append(t)
        for s in neighbours[t]:
            if chart_of[s] < 0 and axis_of[s] == axis_of[seed]:
                chart_of[s] = len(charts)
                stack.append(s)
    charts.append({"axis": axis_of[seed], "triangles": members})

# Small charts join the neighbour they share most edges with, where the projection allows.
merged = True
while merged:
    merged = False
    for c, chart in enumerate(charts):
        if not chart["triangles"] or len(chart["triangles"]) >= MIN_CHART:
            continue
        shared = {}
        for t in chart["triangles"]:
            for s in neighbours[t]:
                if chart_of[s] != c:
                    shared[chart_of[s]] = shared.get(chart_of[s], 0) + 1
        for other in sorted(shared, key=lambda o: (-shared[o], o)):
            axis = AXES[charts[other]["axis"]][0]
            if all(dot(normals[t], axis) > FACING for t in chart["triangles"]):
                for t in chart["triangles"]:
                    chart_of[t] = other
                charts[other]["triangles"] += chart["triangles"]
                chart["triangles"] = []
                merged = True
                break
charts = [c for c in charts if c["triangles"]]

# Project each chart, then shelf-pack the charts' boxes at one scale, the largest that fits.
for chart in charts:
    _, e1, e2 = AXES[chart["axis"]]
    vertices = sorted({v for t in chart["triangles"] for v in triangles[t]})
    chart["uv"] = {v: (dot(positions[v], e1), dot(positions[v], e2)) for v in vertices}
    us = [uv[0] for uv in chart["uv"].values()]
    vs = [uv[1] for uv in chart["uv"].values()]
    chart["low"] = (min(us), min(vs))
    chart["size"] = (max(us) - min(us), max(vs) - min(vs))
charts.sort(key=lambda c: (-c["size"][1], -c["size"][0]))


def pack(scale):
    """Each chart's corner in the square at this scale, or None if they do not fit."""
    corners, x, y, shelf = [], MARGIN, MARGIN, 0.0
    for chart in charts:
        w, h = chart["size"][0] * scale, chart["size"][1] * scale
        if x + w + MARGIN > 1:
            x, y, shelf = MARGIN, y + shelf + MARGIN, 0.0
        if x + w + MARGIN > 1 or y + h + MARGIN > 1:
            return None
        corners.append((x, y))
        x, shelf = x + w + MARGIN, max(shelf, h)
    return corners


low, high = 0.0, 10.0
for _ in range(60):
    middle = 0.5 * (low + high)
    low, high = (middle, high) if pack(middle) else (low, middle)
scale, corners = low, pack(low)



def write_obj(path, comment, uvs, uv_of_corner):
    """Positions, smooth normals, `uvs` and the triangles, corner k of triangle t taking UV
    uv_of_corner(t, k) (1-based) and the normal of its position."""
    lines = ["# %s: made by make_spot_parameterisations.py from spot.glb (%s)" % (path, comment)]
    lines += ["v %.9g %.9g %.9g" % tuple(p) for p in positions]
    lines += ["vn %.6f %.6f %.6f" % tuple(n) for n in vertex_normals]
    lines += ["vt %.7f %.7f" % tuple(uv) for uv in uvs]
    for t, tri in enumerate(triangles):
        corners = ("%d/%d/%d" % (v + 1, uv_of_corner(t, k), v + 1) for k, v in enumerate(tri))
        lines.append("f " + " ".join(corners))
    with open(path, "w") as out:
        out.write("\n".join(lines) + "\n")


# glTF's v runs down from the image's top, OBJ's up from its bottom (tessera's DESIGN.md, UV origin).
atlas_uvs = [(u, 1 - v) for u, v in glb_uvs]
write_obj("spot_atlas.obj", "its own atlas", atlas_uvs, lambda t, k: glb_triangles[t][k] + 1)
box_uvs, uv_index = [], {}
for chart, corner in zip(charts, corners):
    for v, (u, w) in sorted(chart["uv"].items()):
        uv_index[(id(chart), v)] = len(box_uvs) + 1
        box_uvs.append((corner[0] + (u - chart["low"][0]) * scale, corner[1] + (w - chart["low"][1]) * scale))
chart_by_triangle = {t: chart for chart in charts for t in chart["triangles"]}
write_obj(
    "spot_box_uv.obj",
    "a box unwrap, %d charts" % len(charts),
    box_uvs,
    lambda t, k: uv_index[(id(chart_by_triangle[t]), triangles[t][k])],
)
print("%d triangles, %d charts, scale %.4f" % (len(triangles), len(charts), scale))
