#!/usr/bin/env python3
"""Writes the meshes of the Mitsuba 3 mesh peer scenes (issue 39) as binary little-endian PLY,
counter-clockwise seen from outside, closed, no normals (both renderers shade with the faces'
own normals: the scenes say face_normals="true"):

  sphere.ply  a latitude-longitude sphere of radius 0.5: 48 rings x 96 segments, 9,024 triangles
  torus.ply   a torus about z, major radius 0.7, minor 0.3: 96 rings x 48 sides, 9,216 triangles

  python3 scenes/mesh-peers/make_meshes.py    # rewrites both next to this script (deterministic)
"""

import math
import os
import struct


def write_ply(path, vertices, triangles):
    header = ("ply\nformat binary_little_endian 1.0\n"
              f"element vertex {len(vertices)}\nproperty float x\nproperty float y\nproperty float z\n"
              f"element face {len(triangles)}\nproperty list uchar int vertex_indices\nend_header\n")
    with open(path, "wb") as out:
        out.write(header.encode())
        for v in vertices:
            out.write(struct.pack("<3f", *v))
        for t in triangles:
            out.write(struct.pack("<B3i", 3, *t))


def sphere(radius, rings, segments):
    vertices = [(0.0, 0.0, radius)]
    for i in range(1, rings):
        theta = math.pi * i / rings
        for j in range(segments):
            phi = 2 * math.pi * j / segments
            vertices.append((radius * math.sin(theta) * math.cos(phi),
                             radius * math.sin(theta) * math.sin(phi), radius * math.cos(theta)))
    vertices.append((0.0, 0.0, -radius))
    south = len(vertices) - 1
    at = lambda i, j: 1 + (i - 1) * segments + j % segments  # noqa: E731
    triangles = [(0, at(1, j), at(1, j + 1)) for j in range(segments)]
    for i in range(1, rings - 1):
        for j in range(segments):
            a, b, c, d = at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)
            triangles += [(a, b, c), (a, c, d)]
    triangles += [(at(rings - 1, j), south, at(rings - 1, j + 1)) for j in range(segments)]
    return vertices, triangles


def torus(major, minor, rings, sides):
    vertices = []
    for i in range(rings):
        u = 2 * math.pi * i / rings
        for j in range(sides):
            v = 2 * math.pi * j / sides
            r = major + minor * math.cos(v)
            vertices.append((r * math.cos(u), r * math.sin(u), minor * math.sin(v)))
    at = lambda i, j: (i % rings) * sides + j % sides  # noqa: E731
    triangles = []
    for i in range(rings):
        for j in range(sides):
            a, b, c, d = at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)
            triangles += [(a, b, c), (a, c, d)]
    return vertices, triangles


if __name__ == "__main__":
    here = os.path.dirname(os.path.abspath(__file__))
    write_ply(os.path.join(here, "sphere.ply"), *sphere(0.5, 48, 96))
    write_ply(os.path.join(here, "torus.ply"), *torus(0.7, 0.3, 96, 48))
