#!/usr/bin/env python3
"""Rebuilds everything in assets/ deterministically: models (OBJ + MTL), textures (PNG) and scenes (world.cfg).

Every asset is made here from scratch (no third-party or thesis media is read or copied). Models are closed,
2-manifold, consistently outward-oriented triangle meshes with shared vertices; the script verifies each one
*as written to disk* (edges, vertex links, signed volume, degenerate triangles, exact self-intersection test)
and fails (exit 1) if any check fails.

Usage: python3 scripts/make-assets.py [--check-only] [--no-textures]
Needs only the Python 3 standard library (zlib + struct write the PNGs). Output is byte-identical across runs.
"""

import math
import os
import struct
import sys
import zlib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ASSETS = os.path.join(ROOT, "assets")
MODELS = os.path.join(ASSETS, "models")
TEXTURES = os.path.join(ASSETS, "textures")
SCENES = os.path.join(ASSETS, "scenes")

Q = 1000000  # positions are stored as integers in micro-units and written with exactly six decimals


# ----------------------------------------------------------------------------------------------------------
# Mesh building
# ----------------------------------------------------------------------------------------------------------


def qi(x):
    """Quantizes a coordinate to integer micro-units (round half away from zero, deterministic)."""
    return int(math.floor(x * Q + 0.5)) if x >= 0 else -int(math.floor(-x * Q + 0.5))


def fmt(i):
    """Writes an integer micro-unit value as a decimal with six fraction digits (exact)."""
    s = "-" if i < 0 else ""
    i = abs(i)
    return "%s%d.%06d" % (s, i // Q, i % Q)


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


class MeshBuilder:
    """Collects welded vertices (exact integer keys) and triangles; polygons are ear-clipped exactly."""

    def __init__(self, name):
        self.name = name
        self.verts = []  # integer micro-unit triples
        self.index = {}
        self.tris = []

    def v(self, p):
        key = (qi(p[0]), qi(p[1]), qi(p[2]))
        i = self.index.get(key)
        if i is None:
            i = len(self.verts)
            self.index[key] = i
            self.verts.append(key)
        return i

    def tri(self, a, b, c):
        if len({a, b, c}) != 3:
            raise ValueError("%s: triangle with repeated vertex" % self.name)
        self.tris.append((a, b, c))

    def quad(self, a, b, c, d):
        """Adds quad a-b-c-d split along its shorter diagonal."""
        P = self.verts
        d1 = sub(P[a], P[c])
        d2 = sub(P[b], P[d])
        if dot(d1, d1) <= dot(d2, d2):
            self.tri(a, b, c)
            self.tri(a, c, d)
        else:
            self.tri(a, b, d)
            self.tri(b, c, d)

    def polygon(self, ids):
        """Adds a planar simple polygon (vertex ids in boundary order) by exact ear clipping."""
        ids = list(ids)
        P = [self.verts[i] for i in ids]
        n = (0, 0, 0)
        for k in range(len(P)):  # Newell normal (exact integers)
            a, b = P[k], P[(k + 1) % len(P)]
            n = (n[0] + (a[1] - b[1]) * (a[2] + b[2]), n[1] + (a[2] - b[2]) * (a[0] + b[0]),
                 n[2] + (a[0] - b[0]) * (a[1] + b[1]))
        ax = max(range(3), key=lambda k: abs(n[k]))
        u, w = [(1, 2), (2, 0), (0, 1)][ax]
        pts = [(p[u], p[w]) for p in P]
        if n[ax] < 0:  # make the projected polygon counter-clockwise
            ids.reverse()
            pts.reverse()
        for t in ear_clip(pts):
            self.tri(ids[t[0]], ids[t[1]], ids[t[2]])

    def loft(self, rings, bottom="flat", top="flat"):
        """Strips between consecutive rings (same vertex count); caps: 'flat', None, or an apex point."""
        R = [[self.v(p) for p in ring] for ring in rings]
        m = len(R[0])
        for r0, r1 in zip(R, R[1:]):
            for k in range(m):
                self.quad(r0[k], r0[(k + 1) % m], r1[(k + 1) % m], r1[k])
        for cap, ring in ((bottom, R[0]), (top, R[-1])):
            if cap is None:
                continue
            if cap == "flat":
                self.polygon(ring)
            else:
                apex = self.v(cap)
                for k in range(m):
                    self.tri(ring[k], ring[(k + 1) % m], apex)
        return R


def cross2(a, b, c):
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def in_tri2(p, a, b, c):
    d1, d2, d3 = cross2(a, b, p), cross2(b, c, p), cross2(c, a, p)
    return (d1 >= 0 and d2 >= 0 and d3 >= 0) or (d1 <= 0 and d2 <= 0 and d3 <= 0)


def ear_clip(pts):
    """Triangulates a simple CCW polygon given as exact integer 2D points; picks the best-shaped ear first."""
    idx = list(range(len(pts)))
    out = []
    while len(idx) > 3:
        best, best_q = None, None
        for k in range(len(idx)):
            i0, i1, i2 = idx[k - 1], idx[k], idx[(k + 1) % len(idx)]
            a, b, c = pts[i0], pts[i1], pts[i2]
            if cross2(a, b, c) <= 0:
                continue
            blocked = False
            for j in idx:
                if j in (i0, i1, i2) or pts[j] in (a, b, c):
                    continue
                if in_tri2(pts[j], a, b, c):
                    blocked = True
                    break
            if blocked:
                continue
            q = min_angle2(a, b, c)
            if best_q is None or q > best_q + 1e-12:
                best, best_q = k, q
        if best is None:
            raise ValueError("ear clipping failed (polygon not simple?)")
        k = best
        out.append((idx[k - 1], idx[k], idx[(k + 1) % len(idx)]))
        idx.pop(k)
    if cross2(pts[idx[0]], pts[idx[1]], pts[idx[2]]) <= 0:
        raise ValueError("ear clipping left a degenerate triangle")
    out.append(tuple(idx))
    return out


def min_angle2(a, b, c):
    def ang(p, q, r):
        v1 = (q[0] - p[0], q[1] - p[1])
        v2 = (r[0] - p[0], r[1] - p[1])
        l1 = math.hypot(*v1)
        l2 = math.hypot(*v2)
        return math.acos(max(-1.0, min(1.0, (v1[0] * v2[0] + v1[1] * v2[1]) / (l1 * l2))))

    return min(ang(a, b, c), ang(b, c, a), ang(c, a, b))


def orient_consistently(verts, tris):
    """Flips triangles so each shell is consistently oriented with positive signed volume."""
    edge_tris = {}
    for t, (a, b, c) in enumerate(tris):
        for u, w in ((a, b), (b, c), (c, a)):
            edge_tris.setdefault((min(u, w), max(u, w)), []).append(t)
    tris = [list(t) for t in tris]
    seen = [False] * len(tris)
    for start in range(len(tris)):
        if seen[start]:
            continue
        comp = [start]
        seen[start] = True
        stack = [start]
        while stack:
            t = stack.pop()
            a, b, c = tris[t]
            for u, w in ((a, b), (b, c), (c, a)):
                for o in edge_tris[(min(u, w), max(u, w))]:
                    if o == t or seen[o]:
                        continue
                    oa, ob, oc = tris[o]
                    same = (u, w) in ((oa, ob), (ob, oc), (oc, oa))
                    if same:
                        tris[o] = [oa, oc, ob]
                    seen[o] = True
                    comp.append(o)
                    stack.append(o)
        vol = sum(signed_volume6(verts, tris[t]) for t in comp)
        if vol < 0:
            for t in comp:
                a, b, c = tris[t]
                tris[t] = [a, c, b]
    return [tuple(t) for t in tris]


def signed_volume6(verts, t):
    a, b, c = verts[t[0]], verts[t[1]], verts[t[2]]
    return dot(a, cross(b, c))


def finish(mb):
    mb.tris = orient_consistently(mb.verts, mb.tris)
    return mb


# ----------------------------------------------------------------------------------------------------------
# Validation (exact integer arithmetic on the coordinates as written)
# ----------------------------------------------------------------------------------------------------------


def orient3(a, b, c, d):
    return dot(sub(b, a), cross(sub(c, a), sub(d, a)))


def drop_axis(n):
    return max(range(3), key=lambda k: abs(n[k]))


def proj(p, ax):
    u, w = [(1, 2), (2, 0), (0, 1)][ax]
    return (p[u], p[w])


def seg_seg2(p, q, a, b):
    d1, d2 = cross2(a, b, p), cross2(a, b, q)
    d3, d4 = cross2(p, q, a), cross2(p, q, b)
    if ((d1 > 0 and d2 < 0) or (d1 < 0 and d2 > 0)) and ((d3 > 0 and d4 < 0) or (d3 < 0 and d4 > 0)):
        return True

    def on(s0, s1, r):
        return min(s0[0], s1[0]) <= r[0] <= max(s0[0], s1[0]) and min(s0[1], s1[1]) <= r[1] <= max(s0[1], s1[1])

    return ((d1 == 0 and on(a, b, p)) or (d2 == 0 and on(a, b, q)) or (d3 == 0 and on(p, q, a))
            or (d4 == 0 and on(p, q, b)))


def seg_tri(p, q, a, b, c):
    """Closed segment [p,q] against closed triangle abc, exactly."""
    o1, o2 = orient3(a, b, c, p), orient3(a, b, c, q)
    if (o1 > 0 and o2 > 0) or (o1 < 0 and o2 < 0):
        return False
    ax = drop_axis(cross(sub(b, a), sub(c, a)))
    A, B, C = proj(a, ax), proj(b, ax), proj(c, ax)
    if o1 == 0 and o2 == 0:
        P2, Q2 = proj(p, ax), proj(q, ax)
        if in_tri2(P2, A, B, C) or in_tri2(Q2, A, B, C):
            return True
        return seg_seg2(P2, Q2, A, B) or seg_seg2(P2, Q2, B, C) or seg_seg2(P2, Q2, C, A)
    if o1 == 0:
        return in_tri2(proj(p, ax), A, B, C)
    if o2 == 0:
        return in_tri2(proj(q, ax), A, B, C)
    s1, s2, s3 = orient3(p, q, a, b), orient3(p, q, b, c), orient3(p, q, c, a)
    return (s1 >= 0 and s2 >= 0 and s3 >= 0) or (s1 <= 0 and s2 <= 0 and s3 <= 0)


def tris_intersect(V, t1, t2):
    """True when two mesh triangles intersect more than their shared vertices/edge allow."""
    shared = set(t1) & set(t2)
    P1 = [V[i] for i in t1]
    P2 = [V[i] for i in t2]
    if len(shared) == 3:
        return True  # duplicate triangle
    if len(shared) == 2:
        a, b = [i for i in t1 if i in shared]
        p = [i for i in t1 if i not in shared][0]
        q = [i for i in t2 if i not in shared][0]
        A, B, Pp, Qq = V[a], V[b], V[p], V[q]
        if orient3(A, B, Pp, Qq) != 0:
            return False
        ax = drop_axis(cross(sub(B, A), sub(Pp, A)))
        s1 = cross2(proj(A, ax), proj(B, ax), proj(Pp, ax))
        s2 = cross2(proj(A, ax), proj(B, ax), proj(Qq, ax))
        return (s1 > 0) == (s2 > 0)  # coplanar and folded onto each other
    if len(shared) == 1:
        s = shared.pop()
        e1 = [V[i] for i in t1 if i != s]
        e2 = [V[i] for i in t2 if i != s]
        return seg_tri(e1[0], e1[1], *P2) or seg_tri(e2[0], e2[1], *P1)
    for k in range(3):
        if seg_tri(P1[k], P1[(k + 1) % 3], *P2) or seg_tri(P2[k], P2[(k + 1) % 3], *P1):
            return True
    return False


def self_intersections(V, T):
    """Counts intersecting triangle pairs (uniform-grid broad phase, exact narrow phase)."""
    boxes = []
    for t in T:
        P = [V[i] for i in t]
        boxes.append((tuple(min(p[k] for p in P) for k in range(3)), tuple(max(p[k] for p in P) for k in range(3))))
    ext = [max(b[1][k] - b[0][k] for b in boxes) for k in range(3)]
    cell = max(1, max(ext))
    grid = {}
    for ti, (lo, hi) in enumerate(boxes):
        for x in range(lo[0] // cell, hi[0] // cell + 1):
            for y in range(lo[1] // cell, hi[1] // cell + 1):
                for z in range(lo[2] // cell, hi[2] // cell + 1):
                    grid.setdefault((x, y, z), []).append(ti)
    pairs = set()
    for lst in grid.values():
        for i in range(len(lst)):
            for j in range(i + 1, len(lst)):
                pairs.add((lst[i], lst[j]))
    bad = 0
    for i, j in pairs:
        (l1, h1), (l2, h2) = boxes[i], boxes[j]
        if any(h1[k] < l2[k] or h2[k] < l1[k] for k in range(3)):
            continue
        if tris_intersect(V, T[i], T[j]):
            bad += 1
    return bad, len(pairs)


def validate(V, T):
    """Returns (problems, stats) for integer vertices V and triangles T."""
    problems = []
    used = set(i for t in T for i in t)
    if len(used) != len(V):
        problems.append("%d unreferenced vertices" % (len(V) - len(used)))
    if len(set(V)) != len(V):
        problems.append("duplicate vertex positions")
    degenerate = [ti for ti, t in enumerate(T) if cross(sub(V[t[1]], V[t[0]]), sub(V[t[2]], V[t[0]])) == (0, 0, 0)]
    if degenerate:
        problems.append("%d degenerate triangles" % len(degenerate))
    directed = {}
    for ti, (a, b, c) in enumerate(T):
        for u, w in ((a, b), (b, c), (c, a)):
            if (u, w) in directed:
                problems.append("directed edge %d->%d used twice (orientation or non-manifold)" % (u, w))
            directed[(u, w)] = ti
    boundary = [e for e in directed if (e[1], e[0]) not in directed]
    if boundary:
        problems.append("%d edges without an opposite twin (open or inconsistently oriented)" % len(boundary))
    undirected = len({(min(u, w), max(u, w)) for (u, w) in directed})
    # vertex links: the triangles around each vertex must form exactly one fan (disc)
    nxt = {}
    for (a, b, c) in T:
        for v, p, q in ((a, b, c), (b, c, a), (c, a, b)):
            nxt.setdefault(v, {})[p] = q
    pinched = 0
    for v, m in nxt.items():
        start = next(iter(m))
        cur, steps = start, 0
        while True:
            cur = m.get(cur)
            steps += 1
            if cur is None or cur == start or steps > len(m):
                break
        if cur != start or steps != len(m):
            pinched += 1
    if pinched:
        problems.append("%d non-manifold (pinched) vertices" % pinched)
    # shells and per-shell signed volume
    parent = list(range(len(V)))

    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for a, b, c in T:
        parent[find(b)] = find(a)
        parent[find(c)] = find(a)
    shells = {}
    for t in T:
        shells.setdefault(find(t[0]), []).append(t)
    vol6 = 0
    for s in shells.values():
        sv = sum(signed_volume6(V, t) for t in s)
        if sv <= 0:
            problems.append("a shell has non-positive signed volume")
        vol6 += sv
    chi = len(V) - undirected + len(T)
    genus = (2 * len(shells) - chi) // 2
    inter, pairs = self_intersections(V, T)
    if inter:
        problems.append("%d self-intersecting triangle pairs" % inter)
    # smallest triangle quality (float, informative)
    min_ang = 180.0
    for t in T:
        P = [[c / Q for c in V[i]] for i in t]
        for k in range(3):
            a, b, c = P[k], P[(k + 1) % 3], P[(k + 2) % 3]
            u, w = sub(b, a), sub(c, a)
            cosv = dot(u, w) / math.sqrt(dot(u, u) * dot(w, w))
            min_ang = min(min_ang, math.degrees(math.acos(max(-1, min(1, cosv)))))
    lo = [min(v[k] for v in V) / Q for k in range(3)]
    hi = [max(v[k] for v in V) / Q for k in range(3)]
    stats = dict(vertices=len(V), triangles=len(T), edges=undirected, shells=len(shells), genus=genus,
                 volume=vol6 / 6.0 / Q ** 3, lo=lo, hi=hi, min_angle=min_ang, pairs=pairs)
    return problems, stats


# ----------------------------------------------------------------------------------------------------------
# OBJ / MTL writing
# ----------------------------------------------------------------------------------------------------------


def norm(v):
    length = math.sqrt(dot(v, v))
    return (v[0] / length, v[1] / length, v[2] / length)


def write_obj(mb, texture, uv_unit, smooth_deg=35.0, kd=(1.0, 1.0, 1.0), comment=""):
    """Writes models/<name>.obj and .mtl with box-projected UVs and angle-thresholded smooth normals."""
    V = mb.verts
    T = mb.tris
    Pf = [tuple(c / Q for c in v) for v in V]
    fn = []
    for t in T:
        n = cross(sub(Pf[t[1]], Pf[t[0]]), sub(Pf[t[2]], Pf[t[0]]))
        fn.append(n)
    around = {}
    for ti, t in enumerate(T):
        for v in t:
            around.setdefault(v, []).append(ti)
    cos_lim = math.cos(math.radians(smooth_deg))
    vt_index, vt_list, vn_index, vn_list, faces = {}, [], {}, [], []
    for ti, t in enumerate(T):
        n = norm(fn[ti])
        ax = drop_axis(n)
        corners = []
        for v in t:
            p = Pf[v]
            if ax == 0:
                uv = (-p[2] if n[0] > 0 else p[2], p[1])
            elif ax == 1:
                uv = (p[0], -p[2] if n[1] > 0 else p[2])
            else:
                uv = (p[0] if n[2] > 0 else -p[0], p[1])
            uvs = "%.4f %.4f" % (uv[0] / uv_unit + 0.0, uv[1] / uv_unit + 0.0)
            uvs = uvs.replace("-0.0000", "0.0000")
            if uvs not in vt_index:
                vt_index[uvs] = len(vt_list) + 1
                vt_list.append(uvs)
            acc = [0.0, 0.0, 0.0]
            for o in around[v]:
                if dot(norm(fn[o]), n) >= cos_lim:
                    for k in range(3):
                        acc[k] += fn[o][k]
            sn = norm(acc)
            ns = ("%.4f %.4f %.4f" % sn).replace("-0.0000", "0.0000")
            if ns not in vn_index:
                vn_index[ns] = len(vn_list) + 1
                vn_list.append(ns)
            corners.append("%d/%d/%d" % (v + 1, vt_index[uvs], vn_index[ns]))
        faces.append("f " + " ".join(corners))
    name = mb.name
    lines = ["# Rubble asset '%s', generated by scripts/make-assets.py (do not edit by hand)." % name]
    if comment:
        lines += ["# " + c for c in comment.split("\n")]
    lines += ["# %d vertices, %d triangles; closed, 2-manifold, outward-oriented (verified)." % (len(V), len(T)),
              "mtllib %s.mtl" % name, "o %s" % name]
    lines += ["v %s %s %s" % (fmt(v[0]), fmt(v[1]), fmt(v[2])) for v in V]
    lines += ["vt " + s for s in vt_list]
    lines += ["vn " + s for s in vn_list]
    lines += ["usemtl %s" % name, "s off"] + faces
    with open(os.path.join(MODELS, name + ".obj"), "w", newline="\n") as f:
        f.write("\n".join(lines) + "\n")
    mtl = ["# Rubble material for %s.obj (generated by scripts/make-assets.py)" % name, "newmtl %s" % name,
           "Ka 0.200000 0.200000 0.200000", "Kd %.6f %.6f %.6f" % kd, "Ks 0.100000 0.100000 0.100000",
           "Ns 16.000000", "d 1.000000", "illum 2", "map_Kd ../textures/%s" % texture]
    with open(os.path.join(MODELS, name + ".mtl"), "w", newline="\n") as f:
        f.write("\n".join(mtl) + "\n")


def read_obj_exact(path):
    """Reads back v and f lines as exact integers (micro-units) for validation."""
    V, T = [], []
    with open(path) as f:
        for line in f:
            p = line.split()
            if not p:
                continue
            if p[0] == "v":
                V.append(tuple(parse_fixed(x) for x in p[1:4]))
            elif p[0] == "f":
                ids = [int(c.split("/")[0]) - 1 for c in p[1:]]
                for k in range(1, len(ids) - 1):
                    T.append((ids[0], ids[k], ids[k + 1]))
    return V, T


def parse_fixed(s):
    neg = s.startswith("-")
    s = s.lstrip("-")
    whole, _, frac = s.partition(".")
    if len(frac) > 6:
        raise ValueError("more than six decimals: " + s)
    val = int(whole) * Q + int((frac + "000000")[:6])
    return -val if neg else val


# ----------------------------------------------------------------------------------------------------------
# Models
# ----------------------------------------------------------------------------------------------------------


def rect(hx, hz, y):
    """Rectangle footprint (counter-clockwise seen from above) at height y."""
    return [(-hx, y, hz), (hx, y, hz), (hx, y, -hz), (-hx, y, -hz)]


def tiers(rings_spec, footprint):
    rings = []
    for (a, b, y0, y1) in rings_spec:
        rings.append(footprint(a, b, y0))
        rings.append(footprint(a, b, y1))
    return rings


def make_building():
    mb = MeshBuilder("building")
    spec = [(6.4, 4.4, 0.0, 3.0),  # plinth / lobby
            (6.0, 4.0, 3.0, 16.0),
            (5.0, 3.4, 16.0, 27.0),
            (4.0, 2.8, 27.0, 36.0),
            (3.0, 2.2, 36.0, 42.0),
            (1.8, 1.4, 42.0, 45.0)]  # crown
    mb.loft(tiers(spec, rect), bottom="flat", top=(0.0, 48.0, 0.0))  # spire
    return finish(mb)


def make_pyramid():
    mb = MeshBuilder("pyramid")
    spec = []
    h = 1.1
    for k, half in enumerate((5.0, 4.2, 3.4, 2.6, 1.8)):
        spec.append((half, half, k * h, (k + 1) * h))
    spec.append((1.0, 1.0, 5 * h, 5 * h + 1.2))  # shrine on top
    mb.loft(tiers(spec, rect), bottom="flat", top="flat")
    return finish(mb)


def octagon(r, y):
    return [(r * math.cos(math.radians(22.5 + 45 * k)), y, -r * math.sin(math.radians(22.5 + 45 * k)))
            for k in range(8)]


def make_column():
    mb = MeshBuilder("column")
    rings = [octagon(1.4, 0.0), octagon(1.4, 0.6), octagon(1.0, 0.6), octagon(0.98, 4.8), octagon(0.85, 9.2),
             octagon(1.35, 9.6), octagon(1.35, 10.2)]
    mb.loft(rings, bottom="flat", top="flat")
    return finish(mb)


def make_missile():
    """Upright rocket (nose +Y, base at y=0) standing on four swept fins that are part of the lofted skin."""
    mb = MeshBuilder("missile")

    def ring(y, r, fin):
        pts = []
        for q in range(4):
            for deg, rad in ((90 * q, fin), (90 * q + 12, r), (90 * q + 45, r), (90 * q + 78, r)):
                a = math.radians(deg)
                pts.append((rad * math.cos(a), y, -rad * math.sin(a)))
        return pts

    rings = [ring(0.0, 0.9, 2.6), ring(2.5, 1.0, 2.6), ring(5.0, 1.0, 1.0), ring(14.0, 1.0, 1.0),
             ring(17.0, 0.72, 0.72)]
    mb.loft(rings, bottom="flat", top=(0.0, 20.0, 0.0))
    return finish(mb)


def make_fighter():
    """Low-poly jet, nose along -Z, up +Y: one lofted hull whose cross-sections carry the wings, the
    tailplanes, the canopy and the fin, so the whole plane is a single closed surface."""
    mb = MeshBuilder("fighter")
    # z, w (half width), h (top), hb (belly), yw (wing plane), t (wing root half thickness), s (tip x),
    # fh (fin/canopy half width at its root), ft (fin/canopy top)
    stations = [
        (-3.5, .28, .26, .22, -.02, .07, .31, .08, .29),
        (-2.5, .50, .42, .34, -.04, .10, .55, .16, .60),
        (-1.5, .60, .50, .40, -.05, .12, .66, .24, .85),
        (-0.6, .62, .50, .40, -.06, .14, .72, .18, .62),
        (0.6, .60, .48, .38, -.06, .12, 3.0, .10, .52),
        (1.3, .56, .46, .36, -.06, .10, 3.0, .08, .50),
        (1.6, .52, .44, .34, -.06, .09, .60, .07, .50),
        (2.6, .46, .40, .30, -.04, .07, .52, .06, .48),
        (3.4, .42, .38, .28, -.04, .06, 1.5, .05, 1.5),
        (3.8, .40, .36, .27, -.04, .05, 1.5, .05, 1.5),
    ]
    rings = []
    for (z, w, h, hb, yw, t, s, fh, ft) in stations:
        sec = [(s, yw), (w, yw + t), (0.7 * w, 0.75 * h), (fh, h), (0, ft), (-fh, h), (-0.7 * w, 0.75 * h),
               (-w, yw + t), (-s, yw), (-w, yw - t), (-0.55 * w, -hb), (0.55 * w, -hb), (w, yw - t)]
        rings.append([(x, y, z) for (x, y) in sec])
    mb.loft(rings, bottom=(0.0, -0.02, -4.2), top="flat")
    return finish(mb)


def make_ship():
    """Flat-bottomed hull (bow toward -Z, keel at y=0) with a two-tier superstructure merged into the deck."""
    mb = MeshBuilder("ship")
    D = 4.0
    stations = [(-16.0, 2.0, 1.6), (-10.0, 3.4, 0.4), (-2.0, 4.0, 0.0), (6.0, 4.0, 0.0), (12.0, 3.8, 0.0),
                (16.0, 3.4, 0.3)]
    bow = mb.v((0.0, D, -20.0))
    polys = []
    for (z, w, yb) in stations:
        sec = [(-w, D), (-0.92 * w, yb + 1.2), (-0.55 * w, yb), (0.55 * w, yb), (0.92 * w, yb + 1.2), (w, D)]
        polys.append([mb.v((x, y, z)) for (x, y) in sec])
    for p0, p1 in zip(polys, polys[1:]):
        for k in range(len(p0) - 1):
            mb.quad(p0[k], p0[k + 1], p1[k + 1], p1[k])
    for k in range(len(polys[0]) - 1):
        mb.tri(bow, polys[0][k + 1], polys[0][k])
    zs = stations[-1][0]
    stern_mid = mb.v((0.0, D, zs))
    mb.polygon(polys[-1] + [stern_mid])  # transom
    # superstructure (open at the bottom, standing on the deck)
    za, zb, sw = -1.0, 7.0, 2.4

    def foot(hx, z0, z1, y):
        return [(-hx, y, z0), (0.0, y, z0), (hx, y, z0), (hx, y, z1), (0.0, y, z1), (-hx, y, z1)]

    rings = [foot(sw, za, zb, D), foot(sw, za, zb, D + 3.0), foot(1.6, 0.0, 4.5, D + 3.0),
             foot(1.6, 0.0, 4.5, D + 5.2)]
    R = mb.loft(rings, bottom=None, top="flat")
    base = R[0]  # -sw@za, 0@za, sw@za, sw@zb, 0@zb, -sw@zb
    left_edge = [p[0] for p in polys]
    right_edge = [p[-1] for p in polys]
    # deck, split along x=0 into two simple polygons around the superstructure
    mb.polygon([bow] + left_edge + [stern_mid, base[4], base[5], base[0], base[1]])
    mb.polygon([bow, base[1], base[2], base[3], base[4], stern_mid] + right_edge[::-1])
    return finish(mb)


def extrude(mb, outer, inner, caps, z0, z1):
    """Prism along z from 2D loops: outer loop, optional inner loop (hole), cap pieces (2D point lists)."""
    for loop in [outer] + ([inner] if inner else []):
        n = len(loop)
        for k in range(n):
            a, b = loop[k], loop[(k + 1) % n]
            mb.quad(mb.v((a[0], a[1], z0)), mb.v((b[0], b[1], z0)), mb.v((b[0], b[1], z1)), mb.v((a[0], a[1], z1)))
    for z in (z0, z1):
        for piece in caps:
            mb.polygon([mb.v((x, y, z)) for (x, y) in piece])


def make_wall():
    """Thick crenellated wall: 16 x 6.2 x 1.6, base at y=0, centred in x and z."""
    mb = MeshBuilder("wall")
    prof = [(-8.0, 0.0), (8.0, 0.0)]
    x = 8.0
    for k in range(9):  # nine merlons 1.0 wide, eight crenels 0.875 wide, right to left
        prof += [(x, 6.2), (x - 1.0, 6.2)]
        x -= 1.0
        if k < 8:
            prof += [(x, 5.0), (x - 0.875, 5.0)]
            x -= 0.875
    extrude(mb, prof, None, [prof], -0.8, 0.8)
    return finish(mb)


def make_arch():
    """Gateway 12 x 9 x 3 with a round-headed opening above a threshold slab: genus 1 (a hole through it)."""
    mb = MeshBuilder("arch")
    seg = 12
    arc = [(3.0 * math.cos(math.pi * k / seg), 5.0 + 3.0 * math.sin(math.pi * k / seg)) for k in range(seg + 1)]
    arc[seg // 2] = (0.0, 8.0)
    outer = [(-6.0, 0.0), (0.0, 0.0), (6.0, 0.0), (6.0, 9.0), (0.0, 9.0), (-6.0, 9.0)]
    inner = [(-3.0, 1.0), (0.0, 1.0), (3.0, 1.0)] + arc[:] + []
    inner = [(-3.0, 1.0), (0.0, 1.0), (3.0, 1.0)] + arc  # arc runs from (3,5) over the top to (-3,5)
    left = [(0.0, 0.0), (0.0, 1.0), (-3.0, 1.0)] + arc[:seg // 2 - 1:-1] + [(0.0, 9.0), (-6.0, 9.0), (-6.0, 0.0)]
    right = [(0.0, 0.0), (6.0, 0.0), (6.0, 9.0), (0.0, 9.0)] + arc[seg // 2::-1] + [(3.0, 1.0), (0.0, 1.0)]
    extrude(mb, outer, inner, [left, right], -1.5, 1.5)
    return finish(mb)


def make_projectile():
    """Icosphere (one subdivision, 80 triangles) of radius 0.5 centred at the origin."""
    mb = MeshBuilder("projectile")
    g = (1 + math.sqrt(5)) / 2
    base = [(-1, g, 0), (1, g, 0), (-1, -g, 0), (1, -g, 0), (0, -1, g), (0, 1, g), (0, -1, -g), (0, 1, -g),
            (g, 0, -1), (g, 0, 1), (-g, 0, -1), (-g, 0, 1)]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
             (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11),
             (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    P = [norm(p) for p in base]

    def mid(a, b):
        return norm(((a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2))

    def s(p):
        return mb.v((0.5 * p[0], 0.5 * p[1], 0.5 * p[2]))

    for (i, j, k) in faces:
        a, b, c = P[i], P[j], P[k]
        ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
        for t in ((a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)):
            mb.tri(s(t[0]), s(t[1]), s(t[2]))
    return finish(mb)


def make_cube(n):
    """The cube [-1,1]^3 centred at the origin, each face an n x n grid of quads (12 n^2 triangles)."""
    mb = MeshBuilder("cube_%d" % (12 * n * n))

    def c(i):
        return -1.0 + 2.0 * i / n

    for axis in range(3):
        for side in (0, n):
            u, w = (axis + 1) % 3, (axis + 2) % 3
            for i in range(n):
                for j in range(n):
                    ids = []
                    for (di, dj) in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        p = [0.0, 0.0, 0.0]
                        p[axis] = c(side)
                        p[u] = c(i + di)
                        p[w] = c(j + dj)
                        ids.append(mb.v(p))
                    mb.tri(ids[0], ids[1], ids[2])
                    mb.tri(ids[0], ids[2], ids[3])
    return finish(mb)


def extrude_grid(name, occ, du, dv, w0, w1, layers, axes, centre_v=True):
    """A solid made of grid cells: occ[i][j] marks the cells of a (u, v) grid of cell size du x dv that are
    solid, extruded along w from w0 to w1 in `layers` layers. Every face is a grid quad, so the surface is
    closed with no T-junction; holes in occ become openings. axes maps (u, v, w) to model axes; u (and v when
    centre_v) is centred on 0, v otherwise starts at 0."""
    mb = MeshBuilder(name)
    nu, nv = len(occ), len(occ[0])

    def solid(i, j):
        return 0 <= i < nu and 0 <= j < nv and occ[i][j]

    def pt(i, j, k):
        v0 = -0.5 * nv * dv if centre_v else 0.0
        uvw = (-0.5 * nu * du + i * du, v0 + j * dv, w0 + (w1 - w0) * k / layers)
        p = [0.0, 0.0, 0.0]
        for src, dst in enumerate(axes):
            p[dst] = uvw[src]
        return mb.v(p)

    for i in range(nu):
        for j in range(nv):
            if not occ[i][j]:
                continue
            for k in (0, layers):  # caps
                mb.quad(pt(i, j, k), pt(i + 1, j, k), pt(i + 1, j + 1, k), pt(i, j + 1, k))
            for (di, dj, a, b) in ((-1, 0, (0, 0), (0, 1)), (1, 0, (1, 0), (1, 1)),
                                   (0, -1, (0, 0), (1, 0)), (0, 1, (0, 1), (1, 1))):
                if solid(i + di, j + dj):
                    continue
                for k in range(layers):  # side walls, one quad per layer
                    mb.quad(pt(i + a[0], j + a[1], k), pt(i + b[0], j + b[1], k), pt(i + b[0], j + b[1], k + 1),
                            pt(i + a[0], j + a[1], k + 1))
    return finish(mb)


# The demolition building: 12 x 12 m storeys of 3.5 m on a 6 m column grid. Columns stand on the slab below
# (or the ground), slab panels rest on the columns, facade panels stand between the columns under the slab
# above. Every element is its own static object (world.cfg mass 0), so the runtime's support graph finds
# which rest on which.
STOREY = 3.5
SLAB_T = 0.3
COLUMN_W = 0.6
BAY = 6.0
WALL_T = 0.25
WALL_H = STOREY - SLAB_T
WALL_L = BAY - COLUMN_W


def make_slab():
    """Floor slab panel 6 x 0.3 x 6 on a 0.3 m grid, base at y=0, centred in x and z."""
    n = 20
    return extrude_grid("slab", [[True] * n for _ in range(n)], BAY / n, BAY / n, 0.0, SLAB_T, 1, (0, 2, 1))


def make_pillar():
    """Square column 0.6 x 3.2 x 0.6, base at y=0, in 8 courses."""
    return extrude_grid("pillar", [[True] * 2 for _ in range(2)], COLUMN_W / 2, COLUMN_W / 2, 0.0, WALL_H, 8,
                        (0, 2, 1))


def facade_cells(window):
    nu, nv = 18, 11  # 0.3 m x 0.29 m cells over 5.4 x 3.2 m
    occ = [[True] * nv for _ in range(nu)]
    if window:
        for i in range(6, 12):
            for j in range(3, 9):
                occ[i][j] = False
    return occ, WALL_L / nu, WALL_H / nv


def make_facade(axis, window):
    """Facade panel 5.4 long, 3.2 high, 0.25 thick (optionally with a 1.8 x 1.75 window), base at y=0."""
    occ, du, dv = facade_cells(window)
    name = "facade_%s%s" % (axis, "_window" if window else "")
    axes = (0, 1, 2) if axis == "x" else (2, 1, 0)
    return extrude_grid(name, occ, du, dv, -0.5 * WALL_T, 0.5 * WALL_T, 1, axes, centre_v=False)


def building_lines(x0, z0, storeys, ground):
    """Object lines of one building: storeys x (9 columns, 8 facade panels, 4 slab panels), cornered at
    (x0, z0) with its footprint in +x and +z, standing on y = ground."""
    lines = []
    for s in range(storeys):
        y = ground + s * STOREY
        for a in (0, 1, 2):
            for b in (0, 1, 2):
                lines.append(obj_line("pillar", "concrete.png", x0 + a * BAY, y, z0 + b * BAY, 1, 0))
        for k in (0, 1):
            mid = (k + 0.5) * BAY
            window = (s + k) % 2 == 0
            suffix = "_window" if window else ""
            tex = "brick.png" if s == 0 else "facade.png"
            for side in (0, 2):
                lines.append(obj_line("facade_x" + suffix, tex, x0 + mid, y, z0 + side * BAY, 1, 0, "brick"))
                lines.append(obj_line("facade_z" + suffix, tex, x0 + side * BAY, y, z0 + mid, 1, 0, "brick"))
        for a in (0, 1):
            for b in (0, 1):
                lines.append(obj_line("slab", "concrete.png", x0 + (a + 0.5) * BAY, y + WALL_H,
                                      z0 + (b + 0.5) * BAY, 1, 0))
    return lines


MODEL_SPECS = [
    # builder, texture, world units per texture repeat (model space), description
    (make_building, "facade.png", 4.0, "tower with five setbacks and a spire, 12.8 x 48 x 8.8, base at y=0"),
    (make_pyramid, "concrete.png", 2.0, "stepped pyramid (five steps and a shrine), 10 x 6.7 x 10, base at y=0"),
    (make_fighter, "metal.png", 2.0, "player jet, nose along -Z, up +Y, 6 x 1.9 x 8 (one closed lofted hull)"),
    (make_missile, "metal.png", 4.0, "upright rocket on four swept fins, 5.2 x 20 x 5.2, base at y=0"),
    (make_ship, "metal.png", 4.0, "flat-bottomed ship with a two-tier superstructure, 8 x 9.2 x 36, keel at y=0"),
    (make_projectile, "metal.png", 1.0, "icosphere shot, radius 0.5, centred at the origin"),
    (make_wall, "brick.png", 2.0, "crenellated wall slab, 16 x 6.2 x 1.6, base at y=0"),
    (make_column, "concrete.png", 2.0, "octagonal column with plinth and capital, 2.6 x 10.2 x 2.6, base at y=0"),
    (make_arch, "brick.png", 2.0, "gateway with a round-headed opening (genus 1), 12 x 9 x 3, base at y=0"),
    (make_slab, "concrete.png", 2.0, "floor slab panel 6 x 0.3 x 6 (20 x 20 grid), base at y=0"),
    (make_pillar, "concrete.png", 2.0, "square column 0.6 x 3.2 x 0.6 in 8 courses, base at y=0"),
    (lambda: make_facade("x", False), "facade.png", 2.0, "facade panel 5.4 x 3.2 x 0.25 along x, base at y=0"),
    (lambda: make_facade("x", True), "facade.png", 2.0, "facade panel along x with a window, base at y=0"),
    (lambda: make_facade("z", False), "facade.png", 2.0, "facade panel 0.25 x 3.2 x 5.4 along z, base at y=0"),
    (lambda: make_facade("z", True), "facade.png", 2.0, "facade panel along z with a window, base at y=0"),
] + [(lambda n=n: make_cube(n), "concrete.png", 2.0,
      "cube [-1,1]^3 centred at the origin, faces %dx%d grids" % (n, n)) for n in (1, 3, 7, 15, 29)]


# ----------------------------------------------------------------------------------------------------------
# Textures
# ----------------------------------------------------------------------------------------------------------


def png(path, w, h, rows):
    """Writes an 8-bit RGB PNG; rows is a list of h bytearrays of length 3*w. Adaptive Sub/Up filters."""
    raw = bytearray()
    prev = bytearray(3 * w)
    for row in rows:
        sub_f = bytearray((row[i] - (row[i - 3] if i >= 3 else 0)) & 255 for i in range(3 * w))
        up_f = bytearray((row[i] - prev[i]) & 255 for i in range(3 * w))

        def cost(b):
            return sum(x if x < 128 else 256 - x for x in b)

        candidates = [(cost(row), 0, row), (cost(sub_f), 1, sub_f), (cost(up_f), 2, up_f)]
        candidates.sort(key=lambda c: (c[0], c[1]))
        raw.append(candidates[0][1])
        raw += candidates[0][2]
        prev = row

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    data = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
    data += chunk(b"IDAT", zlib.compress(bytes(raw), 9)) + chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(data)


def hash_u(*ints):
    """Deterministic integer hash to [0,1)."""
    h = 0x811C9DC5
    for i in ints:
        h = ((h ^ (i & 0xFFFFFFFF)) * 0x01000193) & 0xFFFFFFFF
        h ^= h >> 15
        h = (h * 0x2C1B3C6D) & 0xFFFFFFFF
        h ^= h >> 12
    return h / 4294967296.0


def noise_grid(size, cells, seed, octaves=4, gain=0.5):
    """Tileable fractal value noise on a size x size image, values roughly in [0,1]."""
    out = [[0.0] * size for _ in range(size)]
    amp, total = 1.0, 0.0
    for o in range(octaves):
        c = cells << o
        lat = [[hash_u(seed, o, i, j) for j in range(c)] for i in range(c)]
        for y in range(size):
            fy = y * c / size
            iy = int(fy)
            ty = fy - iy
            ty = ty * ty * (3 - 2 * ty)
            r0, r1 = lat[iy % c], lat[(iy + 1) % c]
            row = out[y]
            for x in range(size):
                fx = x * c / size
                ix = int(fx)
                tx = fx - ix
                tx = tx * tx * (3 - 2 * tx)
                a = r0[ix % c] + (r0[(ix + 1) % c] - r0[ix % c]) * tx
                b = r1[ix % c] + (r1[(ix + 1) % c] - r1[ix % c]) * tx
                row[x] += amp * (a + (b - a) * ty)
        total += amp
        amp *= gain
    return [[v / total for v in row] for row in out]


def to_rows(size, fn):
    rows = []
    for y in range(size):
        row = bytearray()
        for x in range(size):
            r, g, b = fn(x, y)
            row += bytes((max(0, min(255, int(r * 255 + 0.5))), max(0, min(255, int(g * 255 + 0.5))),
                          max(0, min(255, int(b * 255 + 0.5)))))
        rows.append(row)
    return rows


def tex_ground(size=256):
    """One 16 x 16 m tile: grass-grey ground with a strong tile line and a faint 4 m sub-grid."""
    n = noise_grid(size, 8, 11)
    fine = noise_grid(size, 32, 12, octaves=2)

    def f(x, y):
        v = 0.75 + 0.35 * (n[y][x] - 0.5) + 0.15 * (fine[y][x] - 0.5)
        col = (0.36 * v, 0.42 * v, 0.32 * v)
        if x % 64 in (0, 63) or y % 64 in (0, 63):
            col = tuple(c * 0.8 for c in col)
        if x < 2 or y < 2 or x >= size - 2 or y >= size - 2:
            col = (0.75 * 0.8, 0.76 * 0.8, 0.70 * 0.8)
        return col

    return to_rows(size, f)


def tex_concrete(size=256):
    n = noise_grid(size, 8, 21)
    s = noise_grid(size, 64, 22, octaves=1)

    def f(x, y):
        v = 0.62 + 0.25 * (n[y][x] - 0.5) + 0.10 * (s[y][x] - 0.5)
        if s[y][x] > 0.93:
            v -= 0.12  # pores
        if y % 128 == 0:
            v -= 0.08  # formwork joint
        return (v, v * 0.99, v * 0.96)

    return to_rows(size, f)


def tex_facade(size=256):
    """Concrete facade with a 4 x 4 grid of windows per repeat (one window per model unit on the tower)."""
    n = noise_grid(size, 8, 31)

    def f(x, y):
        cx, cy = x % 64, y % 64
        v = 0.64 + 0.2 * (n[y][x] - 0.5)
        if 10 <= cx < 54 and 12 <= cy < 50:
            lit = hash_u(77, x // 64, y // 64) > 0.7
            t = (cy - 12) / 38.0
            if lit:
                return (0.85 - 0.2 * t, 0.78 - 0.2 * t, 0.5 - 0.1 * t)
            return (0.18 + 0.15 * t + 0.05 * n[y][x], 0.25 + 0.15 * t, 0.34 + 0.12 * t)
        if 8 <= cx < 56 and 10 <= cy < 52:
            return (0.35, 0.36, 0.38)
        return (v, v, v * 0.97)

    return to_rows(size, f)


def tex_brick(size=256):
    """Running-bond bricks, 8 courses x 4 bricks per repeat, light mortar."""
    n = noise_grid(size, 16, 41, octaves=3)

    def f(x, y):
        course = y // 32
        off = 32 if course % 2 else 0
        bx = ((x + off) % size) // 64
        cx, cy = (x + off) % 64, y % 32
        if cx < 3 or cy < 3:
            v = 0.72 + 0.1 * (n[y][x] - 0.5)
            return (v, v * 0.97, v * 0.9)
        h = hash_u(42, course, bx)
        v = 0.8 + 0.25 * (n[y][x] - 0.5) + 0.15 * (h - 0.5)
        return (0.62 * v, 0.30 * v, 0.22 * v)

    return to_rows(size, f)


def tex_metal(size=256):
    """Brushed grey metal with panel seams and rivets."""
    streak = [hash_u(51, y) for y in range(size)]
    n = noise_grid(size, 8, 52, octaves=3)

    def f(x, y):
        v = 0.58 + 0.06 * (streak[y] - 0.5) + 0.12 * (n[y][x] - 0.5)
        px, py = x % 128, y % 64
        if px < 2 or py < 2:
            v -= 0.18
        elif (px in range(5, 8) or px in range(121, 124)) and (py % 16) in (7, 8, 9):
            v += 0.15
        return (v * 0.95, v * 0.98, v * 1.05)

    return to_rows(size, f)


def tex_interior(size=256):
    """Rough broken stone for faces created by cuts: fractal noise with dark cracks."""
    n = noise_grid(size, 4, 61, octaves=5, gain=0.55)
    r = noise_grid(size, 8, 62, octaves=3)
    g = noise_grid(size, 64, 63, octaves=1)

    def f(x, y):
        v = 0.5 + 0.5 * (n[y][x] - 0.5) + 0.12 * (g[y][x] - 0.5)
        crack = abs(r[y][x] - 0.5)
        if crack < 0.02:
            v *= 0.45 + 15 * crack
        return (0.62 * v + 0.08, 0.57 * v + 0.07, 0.50 * v + 0.06)

    return to_rows(size, f)


def sky_color(d):
    """Colour of the sky in world direction d (unit vector): gradient, sun, distant hills, clouds."""
    dx, dy, dz = d
    e = math.asin(max(-1.0, min(1.0, dy)))
    az = math.atan2(dx, -dz)
    hill = 0.035 + 0.018 * math.sin(3 * az + 1.0) + 0.012 * math.sin(7 * az + 2.0) + 0.006 * math.sin(17 * az)
    sun = norm((0.45, 0.55, -0.7))
    sd = max(0.0, dot(d, sun))
    if e < 0:
        t = min(1.0, -e / 0.5)
        col = (0.42 - 0.14 * t, 0.45 - 0.14 * t, 0.42 - 0.15 * t)
    elif e < hill:
        t = e / hill
        col = (0.46 + 0.06 * t, 0.52 + 0.07 * t, 0.58 + 0.08 * t)
    else:
        t = math.sqrt(min(1.0, e / (math.pi / 2)))
        col = (0.80 - 0.55 * t, 0.87 - 0.40 * t, 0.96 - 0.12 * t)
        c = fractal3(d[0] * 2.2, d[1] * 6.0, d[2] * 2.2)
        cover = max(0.0, min(1.0, (c - 0.52) / 0.18)) * min(1.0, (e - hill) / 0.15)
        col = tuple(col[k] * (1 - 0.85 * cover) + 0.97 * 0.85 * cover for k in range(3))
        col = tuple(col[k] + 0.5 * sd ** 64 + (0.35 if sd > 0.9995 else 0.0) for k in range(3))
    col = tuple(col[k] + 0.12 * sd ** 6 * (1.0, 0.85, 0.6)[k] for k in range(3))
    return col


def noise3(x, y, z, seed):
    ix, iy, iz = math.floor(x), math.floor(y), math.floor(z)
    tx, ty, tz = x - ix, y - iy, z - iz
    tx, ty, tz = tx * tx * (3 - 2 * tx), ty * ty * (3 - 2 * ty), tz * tz * (3 - 2 * tz)

    def h(a, b, c):
        return hash_u(seed, ix + a, iy + b, iz + c)

    x00 = h(0, 0, 0) + (h(1, 0, 0) - h(0, 0, 0)) * tx
    x10 = h(0, 1, 0) + (h(1, 1, 0) - h(0, 1, 0)) * tx
    x01 = h(0, 0, 1) + (h(1, 0, 1) - h(0, 0, 1)) * tx
    x11 = h(0, 1, 1) + (h(1, 1, 1) - h(0, 1, 1)) * tx
    y0 = x00 + (x10 - x00) * ty
    y1 = x01 + (x11 - x01) * ty
    return y0 + (y1 - y0) * tz


def fractal3(x, y, z):
    return (noise3(x, y, z, 91) * 0.57 + noise3(2 * x, 2 * y, 2 * z, 92) * 0.29 +
            noise3(4 * x, 4 * y, 4 * z, 93) * 0.14)


# Inverse of the face mapping of Irrlicht's sky box as implemented in demo/Renderer.cpp (kSkyFs):
# pixel (u, v) in [0,1]^2 of each world.cfg face -> world direction. Order: top, bottom, left, right, front, back.
SKY_FACES = [
    ("top", lambda u, v: (2 * v - 1, 1.0, 1 - 2 * u)),
    ("bottom", lambda u, v: (1 - 2 * v, -1.0, 1 - 2 * u)),
    ("left", lambda u, v: (1.0, 1 - 2 * v, 1 - 2 * u)),
    ("right", lambda u, v: (-1.0, 1 - 2 * v, 2 * u - 1)),
    ("front", lambda u, v: (1 - 2 * u, 1 - 2 * v, -1.0)),
    ("back", lambda u, v: (2 * u - 1, 1 - 2 * v, 1.0)),
]


def tex_sky(face, size=256):
    fn = dict(SKY_FACES)[face]

    def f(x, y):
        return sky_color(norm(fn((x + 0.5) / size, (y + 0.5) / size)))

    return to_rows(size, f)


TEXTURE_SPECS = [
    ("ground.png", tex_ground, "16 x 16 m ground tile (grid lines every tile, faint 4 m sub-grid)"),
    ("concrete.png", tex_concrete, "grey concrete with pores and formwork joints"),
    ("facade.png", tex_facade, "concrete facade with 4 x 4 windows (some lit)"),
    ("brick.png", tex_brick, "running-bond bricks"),
    ("metal.png", tex_metal, "brushed metal panels with seams and rivets"),
    ("interior.png", tex_interior, "rough broken stone for faces created by cuts"),
]


# ----------------------------------------------------------------------------------------------------------
# Scenes (thesis appendix A.3 world.cfg format)
# ----------------------------------------------------------------------------------------------------------

SKY_LINE = ";".join("../textures/skybox/%s.png" % f for f, _ in SKY_FACES)
GROUND_LINE = ";../textures/ground.png;0;-15;0;1000;10;1000;0"  # unit box scaled: top face at y = -10
VEHICLE_LINE = "../models/fighter.obj;../textures/metal.png;0;20;0;1;1;1;100"


def obj_line(model, texture, x, y, z, s, mass, material=None):
    sx, sy, sz = s if isinstance(s, tuple) else (s, s, s)
    vals = [x, y, z, sx, sy, sz, mass]
    line = "../models/%s.obj;../textures/%s;%s" % (model, texture, ";".join("%g" % v for v in vals))
    return line + ";" + material if material else line


def scenes():
    out = {}
    G = -10  # ground top: models with their base at y=0 stand on it
    # No comment lines: the files stay readable by a strict appendix A.3 reader (documented in README.md).
    world = [
        SKY_LINE, GROUND_LINE, VEHICLE_LINE,
        obj_line("cube_108", "concrete.png", 14, G + 4, -55, 4, 200),
        obj_line("building", "facade.png", -30, G, -80, 2, 500),
        obj_line("missile", "metal.png", 70, G, -95, 1.5, 300),
        obj_line("building", "facade.png", 38, G, -130, 2, 500),
        obj_line("wall", "brick.png", 0, G, -150, 2, 400),
        obj_line("ship", "metal.png", -85, G, -150, 1.5, 500),
        obj_line("column", "concrete.png", -24, G, -200, 1.5, 100),
        obj_line("column", "concrete.png", -8, G, -200, 1.5, 100),
        obj_line("column", "concrete.png", 8, G, -200, 1.5, 100),
        obj_line("column", "concrete.png", 24, G, -200, 1.5, 100),
        obj_line("building", "facade.png", -60, G, -230, 2, 500),
        obj_line("pyramid", "concrete.png", 65, G, -250, 3, 800),
        obj_line("arch", "brick.png", 0, G, -290, 2, 600),
        obj_line("building", "facade.png", 25, G, -340, 2, 500),
        obj_line("building", "facade.png", -25, G, -360, 2, 0),
        obj_line("wall", "brick.png", -110, G, -300, 2, 400),
        obj_line("pyramid", "concrete.png", -140, G, -60, 3, 0),
        obj_line("building", "facade.png", 240, G, -240, 2, 500),
        obj_line("building", "facade.png", -240, G, -240, 2, 500),
        obj_line("building", "facade.png", 240, G, 240, 2, 500),
        obj_line("building", "facade.png", -240, G, 240, 2, 500),
    ]
    out["world.cfg"] = world
    for n in (1, 3, 7, 15, 29):
        t = 12 * n * n
        # one cube (centred, so y=25 puts its centre where the thesis's base-at-0 cube had it), scale 5,
        # dropped onto the ground (top at y=-10); the vehicle is static (mass 0)
        lines = [
            SKY_LINE, GROUND_LINE, "../models/fighter.obj;../textures/metal.png;0;20;0;1;1;1;0",
            obj_line("cube_%d" % t, "concrete.png", 0, 25, -40, 5, 500)]
        out["cube_test_%d.cfg" % t] = lines
        if n == 1:
            out["cube_test.cfg"] = lines
    # thesis table 3.1 counts (building 7, missile 1, ship 1, plus three other objects: here our pyramid,
    # column and arch) at the thesis's positions, standing on the ground (y=-10)
    perf = [
        SKY_LINE, GROUND_LINE, VEHICLE_LINE,
        obj_line("building", "facade.png", -20, G, -30, 2, 500),
        obj_line("missile", "metal.png", 50, G, -100, 2, 500),
        obj_line("pyramid", "concrete.png", -30, G, 60, 3, 500),
        obj_line("building", "facade.png", 76, G, 50, 2, 500),
        obj_line("building", "facade.png", 30, G, -40, 2, 500),
        obj_line("building", "facade.png", 240, G, 240, 2, 500),
        obj_line("building", "facade.png", 240, G, -240, 2, 500),
        obj_line("building", "facade.png", -240, G, 240, 2, 500),
        obj_line("building", "facade.png", -240, G, -240, 2, 500),
        obj_line("column", "concrete.png", -140, G, 100, 2, 500),
        obj_line("arch", "brick.png", 200, G, 124, 2, 500),
        obj_line("ship", "metal.png", -200, G, 200, 1.5, 500),
    ]
    out["performance_test.cfg"] = perf
    # structural collapse: static (mass 0) columns, arches, walls and stacks on the ground; a cut through a
    # column drops its top and whatever rests on it
    collapse = [
        SKY_LINE, GROUND_LINE, VEHICLE_LINE,
        obj_line("column", "concrete.png", -24, G, -60, 1.5, 0),
        obj_line("column", "concrete.png", -8, G, -60, 1.5, 0),
        obj_line("column", "concrete.png", 8, G, -60, 1.5, 0),
        obj_line("column", "concrete.png", 24, G, -60, 1.5, 0),
        obj_line("column", "concrete.png", 0, G, -95, 1.5, 0),
        obj_line("cube_108", "concrete.png", 0, G + 15.3 + 2.5, -95, 2.5, 0),
        obj_line("cube_108", "concrete.png", -40, G + 3, -100, 3, 0),
        obj_line("cube_108", "concrete.png", -40, G + 9, -100, 3, 0),
        obj_line("cube_108", "concrete.png", -40, G + 15, -100, 3, 0),
        obj_line("wall", "brick.png", 40, G, -100, 1.5, 0),
        obj_line("arch", "brick.png", 0, G, -140, 2, 0),
        obj_line("wall", "brick.png", -35, G, -150, 2, 0),
        obj_line("column", "concrete.png", 35, G, -150, 2, 0),
    ]
    out["collapse_test.cfg"] = collapse
    # demolition: one seven-storey building of 151 static elements (about 100k triangles) resting on each
    # other, the vehicle in front of it
    demo = [SKY_LINE, GROUND_LINE, "../models/fighter.obj;../textures/metal.png;0;20;90;1;1;1;100"]
    demo += building_lines(-BAY, -BAY, 7, G)
    demo += [obj_line("slab", "concrete.png", (a - 0.5) * BAY, G + 7 * STOREY, (b - 0.5) * BAY, 1, 0)
             for a in (0, 1) for b in (0, 1)]  # the roof
    out["demolition.cfg"] = demo
    # demolition block: four buildings of 7 to 10 storeys around a square (about 500k triangles)
    block = [SKY_LINE, GROUND_LINE, "../models/fighter.obj;../textures/metal.png;0;30;110;1;1;1;100"]
    for (x0, z0, n) in ((-40, -40, 10), (16, -40, 8), (-40, 16, 7), (16, 16, 7)):
        block += building_lines(x0, z0, n, G)
        block += [obj_line("slab", "concrete.png", x0 + (a + 0.5) * BAY, G + n * STOREY, z0 + (b + 0.5) * BAY, 1, 0)
                  for a in (0, 1) for b in (0, 1)]
    out["demolition_block.cfg"] = block
    return out


# The material presets a world.cfg line may name in its optional 10th field (include/rubble/structure/Material.hpp).
MATERIALS = ("concrete", "brick", "stone", "wood", "glass", "steel")


def check_scene(path):
    """Checks a written scene against appendix A.3: field counts, numbers, and that every file exists."""
    problems = []
    base = os.path.dirname(path)
    with open(path) as f:
        lines = [ln.rstrip("\n") for ln in f if ln.strip()]
    if len(lines) < 3:
        return ["fewer than three lines"]
    sky = lines[0].split(";")
    if len(sky) != 6:
        problems.append("line 1: expected 6 sky-box images, got %d" % len(sky))
    for name in sky:
        if not os.path.isfile(os.path.join(base, name)):
            problems.append("line 1: missing %s" % name)
    for k, ln in enumerate(lines[1:], start=2):
        fields = ln.split(";")
        if len(fields) not in (9, 10, 11):
            problems.append("line %d: expected 9 fields (10 with a material, 11 with a roughness), got %d"
                            % (k, len(fields)))
            continue
        if len(fields) >= 10 and fields[9] not in MATERIALS and not (len(fields) == 11 and not fields[9]):
            problems.append("line %d: unknown material '%s'" % (k, fields[9]))
            continue
        if len(fields) == 11 and fields[10] != "flat":
            try:
                rough_ok = 0 <= float(fields[10]) <= 1
            except ValueError:
                rough_ok = False
            if not rough_ok:
                problems.append("line %d: roughness '%s' is neither flat nor a number in [0, 1]" % (k, fields[10]))
                continue
        try:
            nums = [float(x) for x in fields[2:9]]
        except ValueError:
            problems.append("line %d: a number does not parse" % k)
            continue
        if k == 2 and (fields[0] or nums[6] != 0):
            problems.append("line 2: the ground has no model and mass 0")
        if k > 2 and not fields[0]:
            problems.append("line %d: model missing" % k)
        for name in fields[:2]:
            if name and not os.path.isfile(os.path.join(base, name)):
                problems.append("line %d: missing %s" % (k, name))
        if any(x <= 0 for x in nums[3:6]) or nums[6] < 0:
            problems.append("line %d: scale must be positive and mass non-negative" % k)
    return problems


# ----------------------------------------------------------------------------------------------------------


def main():
    check_only = "--check-only" in sys.argv
    no_textures = "--no-textures" in sys.argv
    for d in (MODELS, TEXTURES, os.path.join(TEXTURES, "skybox"), SCENES):
        os.makedirs(d, exist_ok=True)
    ok = True
    report = []
    for builder, texture, uv_unit, desc in MODEL_SPECS:
        mb = builder()
        path = os.path.join(MODELS, mb.name + ".obj")
        if not check_only:
            write_obj(mb, texture, uv_unit, comment=desc)
        V, T = read_obj_exact(path)
        problems, st = validate(V, T)
        status = "OK" if not problems else "FAIL: " + "; ".join(problems)
        ok = ok and not problems
        line = ("%-12s %6d tris %5d verts  shells %d genus %d  volume %10.3f  bbox [%s]..[%s]  min angle %5.2f deg"
                "  pairs tested %d  %s" % (mb.name, st["triangles"], st["vertices"], st["shells"], st["genus"],
                                           st["volume"], ", ".join("%g" % v for v in st["lo"]),
                                           ", ".join("%g" % v for v in st["hi"]), st["min_angle"], st["pairs"],
                                           status))
        print(line)
        report.append(line)
    if not check_only and not no_textures:
        for name, fn, _ in TEXTURE_SPECS:
            png(os.path.join(TEXTURES, name), 256, 256, fn())
            print("texture", name)
        for face, _ in SKY_FACES:
            png(os.path.join(TEXTURES, "skybox", face + ".png"), 256, 256, tex_sky(face))
            print("texture skybox/%s.png" % face)
    if not check_only:
        for name, lines in scenes().items():
            with open(os.path.join(SCENES, name), "w", newline="\n") as f:
                f.write("\n".join(lines) + "\n")
    for name in sorted(os.listdir(SCENES)):
        if name.endswith(".cfg"):
            problems = check_scene(os.path.join(SCENES, name))
            ok = ok and not problems
            print("scene %-22s %s" % (name, "OK" if not problems else "FAIL: " + "; ".join(problems)))
    if not ok:
        print("make-assets: some models or scenes are INVALID", file=sys.stderr)
        return 1
    print("make-assets: all %d models closed, 2-manifold, outward-oriented, no self-intersections; "
          "scenes complete" % len(report))
    return 0


if __name__ == "__main__":
    sys.exit(main())
