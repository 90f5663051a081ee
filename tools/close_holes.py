#!/usr/bin/env python3
"""Closes the holes of a triangle mesh (OBJ, positions and triangles only)
by ear clipping each hole's rim in its least-squares plane, and writes the
input's lines unchanged followed by the caps' triangles (no new vertex).

  close_holes.py IN.obj OUT.obj

Made for the Stanford bunny's 5 holes in its base
(scenes/stanford-bunny/stanford-bunny-closed.obj; docs/reproduction-lin2017.md,
"The jade bunny against Mitsuba"): a hole is a loop of boundary edges (a
directed edge a -> b whose reverse no triangle has); its cap runs the rim
backwards (b -> a), wound as the mesh is, so every edge of the result has
its reverse: the mesh is closed. Exits when a vertex has two boundary edges
leaving it (a loop that is not simple), when a rim projected on its plane is
not a simple polygon, or when the result is not closed. Prints each hole's
edges and how far its rim lies from its plane (the caps are flat only where
the rim is).
"""
import os
import sys

import numpy as np


def cross(o, a, b):
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def segments_cross(p1, p2, q1, q2):
    """Whether the segments p1-p2 and q1-q2 cross at a point inside both."""
    d1, d2 = cross(q1, q2, p1), cross(q1, q2, p2)
    d3, d4 = cross(p1, p2, q1), cross(p1, p2, q2)
    return d1 * d2 < 0 and d3 * d4 < 0


def simple(ring, pts):
    """Whether the closed polygon `ring` has no two non-adjacent edges that cross."""
    n = len(ring)
    for i in range(n):
        for j in range(i + 2, n):
            if i == 0 and j == n - 1:
                continue   # adjacent through the wrap
            if segments_cross(pts[ring[i]], pts[ring[(i + 1) % n]], pts[ring[j]], pts[ring[(j + 1) % n]]):
                return False
    return True


def ear_clip(ring, pts):
    """Triangles (in ring order, so wound as the ring) of the simple polygon
    `ring` (vertex ids, pts their 2-D positions), or None if an ear is missing."""
    area = sum(cross((0.0, 0.0), pts[ring[i]], pts[ring[(i + 1) % len(ring)]]) for i in range(len(ring)))
    sign = 1.0 if area > 0 else -1.0
    ring, tris = list(ring), []
    while len(ring) > 3:
        for i in range(len(ring)):
            a, b, d = ring[i - 1], ring[i], ring[(i + 1) % len(ring)]
            if sign * cross(pts[a], pts[b], pts[d]) <= 0:
                continue   # reflex or flat
            inside = any(
                sign * cross(pts[a], pts[b], pts[q]) >= 0 and sign * cross(pts[b], pts[d], pts[q]) >= 0
                and sign * cross(pts[d], pts[a], pts[q]) >= 0
                for q in ring if q not in (a, b, d))
            if not inside:
                tris.append((a, b, d))
                del ring[i]
                break
        else:
            return None
    a, b, d = ring
    if sign * cross(pts[a], pts[b], pts[d]) <= 0:
        return None   # the last three turn the wrong way: not a simple polygon
    tris.append((a, b, d))
    return tris


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    src, dst = sys.argv[1], sys.argv[2]
    lines = open(src).read().split("\n")
    if lines and lines[-1] == "":
        lines.pop()
    verts, faces = [], []
    for l in lines:
        p = l.split()
        if not p:
            continue
        if p[0] == "v":
            verts.append([float(x) for x in p[1:4]])
        elif p[0] == "f":
            idx = [int(x.split("/")[0]) for x in p[1:]]
            if len(idx) != 3 or any(i <= 0 for i in idx):
                sys.exit(f"{src}: only triangles with positive indices: {l}")
            faces.append([i - 1 for i in idx])
    v = np.array(verts, dtype=np.float64)
    directed = set()
    for a, b, c in faces:
        for e in ((a, b), (b, c), (c, a)):
            if e in directed:
                sys.exit(f"{src}: directed edge {e} twice (inconsistent winding)")
            directed.add(e)
    boundary = [(a, b) for (a, b) in directed if (b, a) not in directed]
    nxt = {}
    starts = {a for a, _ in boundary}
    for a, b in boundary:
        if b not in starts:
            sys.exit(f"{src}: boundary edge {a + 1} -> {b + 1} leads to a vertex no boundary edge leaves")
        if a in nxt:
            sys.exit(f"{src}: vertex {a + 1} starts two boundary edges: a hole that is not a simple loop")
        nxt[a] = b
    # loops, each from its smallest vertex (deterministic order)
    seen, loops = set(), []
    for start in sorted(nxt):
        if start in seen:
            continue
        loop, a = [], start
        while a not in seen:
            seen.add(a)
            loop.append(a)
            a = nxt[a]
        if a != start:
            sys.exit(f"{src}: boundary walk from {start + 1} does not close")
        loops.append(loop)
    new_f = []
    for k, loop in enumerate(loops):
        rim = v[loop]
        c = rim.mean(axis=0)
        # the rim's least-squares plane, and its distance from it
        _, _, vt = np.linalg.svd(rim - c)
        off = np.abs((rim - c) @ vt[2]).max()
        # the cap runs the rim backwards (each boundary edge a -> b becomes b -> a)
        ring = loop[::-1]
        pts = {i: ((v[i] - c) @ vt[0], (v[i] - c) @ vt[1]) for i in ring}
        tris = ear_clip(ring, pts) if simple(ring, pts) else None
        if tris is None:
            sys.exit(f"hole {k + 1}: its rim projected on its plane is not a simple polygon")
        new_f.extend(tris)
        # each cap triangle's tilt against the plane: the cosine of its normal with the plane's (1: in the plane)
        tilt = min(abs(np.dot(np.cross(v[b] - v[a], v[c] - v[a]), vt[2]))
                   / np.linalg.norm(np.cross(v[b] - v[a], v[c] - v[a])) for a, b, c in tris)
        print(f"hole {k + 1}: {len(loop)} edges, {len(tris)} triangles, rim within {off:.2e} of its plane "
              f"(rim extent {np.ptp(rim, axis=0).max():.2e}), least cosine of a cap triangle with the plane "
              f"{tilt:.3f}", file=sys.stderr)
    for a, b, c in new_f:
        for e in ((a, b), (b, c), (c, a)):
            if e in directed:
                sys.exit(f"patch edge {e} exists already")
            directed.add(e)
    open_edges = sum(1 for (a, b) in directed if (b, a) not in directed)
    if open_edges:
        sys.exit(f"{open_edges} edges still open")
    with open(dst, "w") as o:
        o.write(f"# {os.path.basename(src)} with its {len(loops)} holes closed by tools/close_holes.py: "
                f"{len(new_f)} triangles appended at the end (the counts in the header below are the original's)\n")
        for l in lines:
            o.write(l + "\n")
        o.write(f"# {len(loops)} holes closed by tools/close_holes.py: each rim ear-clipped in its plane "
                f"({len(new_f)} triangles, no new vertex)\n")
        for a, b, c in new_f:
            o.write(f"f {a + 1} {b + 1} {c + 1}\n")
    print(f"{dst}: {len(verts)} vertices, {len(faces) + len(new_f)} triangles, "
          f"{len(boundary)} boundary edges closed in {len(loops)} holes", file=sys.stderr)


if __name__ == "__main__":
    main()
