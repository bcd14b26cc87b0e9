#!/usr/bin/env python3
"""Independent topology counts of OBJ / PLY / STL files, for assets/SOURCES.md.

Welds vertices with bitwise-equal float32 positions, fans polygons (c0, ci, ci+1), drops
triangles whose welded corners repeat, and counts triangles, used vertices, edges, boundary
and non-manifold edges. Written apart from the Rust importers (plain Python, struct module)
so that `meshpaint info` can be checked against it.  Usage: mesh_counts.py FILE...
"""
import json
import struct
import sys

F32 = lambda x: struct.unpack('<f', struct.pack('<f', float(x)))[0]
TYPES = {'char': 'b', 'int8': 'b', 'uchar': 'B', 'uint8': 'B', 'short': 'h', 'int16': 'h',
         'ushort': 'H', 'uint16': 'H', 'int': 'i', 'int32': 'i', 'uint': 'I', 'uint32': 'I',
         'float': 'f', 'float32': 'f', 'double': 'd', 'float64': 'd'}


def obj(data):
    positions, polygons = [], []
    for line in data.decode('utf-8', 'replace').splitlines():
        words = line.split()
        if not words:
            continue
        if words[0] == 'v':
            positions.append(tuple(F32(w) for w in words[1:4]))
        elif words[0] == 'f':
            corners = []
            for w in words[1:]:
                i = int(w.split('/')[0])
                corners.append(i - 1 if i > 0 else len(positions) + i)
            polygons.append(corners)
    return positions, polygons


def ply(data):
    end = data.index(b'end_header') + len(b'end_header')
    end = data.index(b'\n', end) + 1
    header = data[:end].decode().split('\n')
    fmt = None
    elements = []
    for line in header:
        w = line.split()
        if not w:
            continue
        if w[0] == 'format':
            fmt = w[1]
        elif w[0] == 'element':
            elements.append((w[1], int(w[2]), []))
        elif w[0] == 'property':
            elements[-1][2].append((w[-1], w[1:-1]))
    body = data[end:]
    positions, polygons = [], []
    if fmt == 'ascii':
        tokens = body.split()
        pos = 0
        for name, count, props in elements:
            for _ in range(count):
                values = {}
                for pname, ptype in props:
                    if ptype[0] == 'list':
                        n = int(tokens[pos]); pos += 1
                        values[pname] = [int(t) for t in tokens[pos:pos + n]]; pos += n
                    else:
                        values[pname] = float(tokens[pos]); pos += 1
                store(name, values, positions, polygons)
    else:
        order = '<' if fmt == 'binary_little_endian' else '>'
        pos = 0
        for name, count, props in elements:
            for _ in range(count):
                values = {}
                for pname, ptype in props:
                    if ptype[0] == 'list':
                        cf, ef = TYPES[ptype[1]], TYPES[ptype[2]]
                        (n,) = struct.unpack_from(order + cf, body, pos); pos += struct.calcsize(cf)
                        values[pname] = list(struct.unpack_from(order + ef * n, body, pos))
                        pos += struct.calcsize(ef) * n
                    else:
                        f = TYPES[ptype[0]]
                        (values[pname],) = struct.unpack_from(order + f, body, pos); pos += struct.calcsize(f)
                store(name, values, positions, polygons)
    return positions, polygons


def store(name, values, positions, polygons):
    if name == 'vertex':
        positions.append(tuple(F32(values[a]) for a in 'xyz'))
    elif name == 'face':
        polygons.append(values.get('vertex_indices', values.get('vertex_index')))


def stl(data):
    positions, polygons = [], []
    if len(data) >= 84 and 84 + 50 * struct.unpack_from('<I', data, 80)[0] == len(data):
        for k in range(struct.unpack_from('<I', data, 80)[0]):
            v = struct.unpack_from('<12f', data, 84 + 50 * k)
            for c in range(3):
                positions.append(tuple(v[3 + 3 * c: 6 + 3 * c]))
            polygons.append([len(positions) - 3, len(positions) - 2, len(positions) - 1])
    else:
        words = data.decode().split()
        for i, w in enumerate(words):
            if w == 'vertex':
                positions.append(tuple(F32(x) for x in words[i + 1:i + 4]))
                if len(positions) % 3 == 0:
                    polygons.append([len(positions) - 3, len(positions) - 2, len(positions) - 1])
    return positions, polygons


def counts(positions, polygons):
    ids = {}
    weld = [ids.setdefault(struct.pack('<3f', *p), len(ids)) for p in positions]
    triangles, dropped = [], 0
    for poly in polygons:
        for i in range(1, len(poly) - 1):
            t = (weld[poly[0]], weld[poly[i]], weld[poly[i + 1]])
            if len(set(t)) < 3:
                dropped += 1
            else:
                triangles.append(t)
    edges = {}
    for a, b, c in triangles:
        for u, v in ((a, b), (b, c), (c, a)):
            key = (min(u, v), max(u, v))
            edges[key] = edges.get(key, 0) + 1
    used = {v for t in triangles for v in t}
    return {'triangles': len(triangles), 'vertices': len(used), 'edges': len(edges),
            'boundary_edges': sum(1 for n in edges.values() if n == 1),
            'nonmanifold_edges': sum(1 for n in edges.values() if n > 2),
            'degenerate_triangles_dropped': dropped}


if __name__ == '__main__':
    for path in sys.argv[1:]:
        data = open(path, 'rb').read()
        kind = path.lower().rsplit('.', 1)[-1]
        positions, polygons = {'obj': obj, 'ply': ply, 'stl': stl}[kind](data)
        print(path, json.dumps(counts(positions, polygons)))
