#!/usr/bin/env python3
"""Writes the triangles of a .glb (POSITION + indices of every triangle primitive, node
transforms ignored) as a binary little-endian PLY: how tools/format_screenshots.sh gets a
scan in PLY form (the Stanford bunny, shipped as .glb) without committing a second copy.

    tools/glb_to_ply.py IN.glb OUT.ply
"""
import json
import struct
import sys

COMPONENT = {5121: ("B", 1), 5123: ("H", 2), 5125: ("I", 4), 5126: ("f", 4)}
COUNT = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}


def read_glb(path):
    data = open(path, "rb").read()
    magic, _version, _length = struct.unpack_from("<4sII", data, 0)
    if magic != b"glTF":
        sys.exit(f"{path}: not a .glb file")
    offset, doc, binary = 12, None, b""
    while offset < len(data):
        size, kind = struct.unpack_from("<II", data, offset)
        chunk = data[offset + 8 : offset + 8 + size]
        if kind == 0x4E4F534A:
            doc = json.loads(chunk)
        elif kind == 0x004E4942:
            binary = chunk
        offset += 8 + size
    return doc, binary


def accessor(doc, binary, index):
    acc = doc["accessors"][index]
    view = doc["bufferViews"][acc["bufferView"]]
    fmt, size = COMPONENT[acc["componentType"]]
    n = COUNT[acc["type"]]
    stride = view.get("byteStride", size * n)
    base = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
    return [struct.unpack_from("<" + fmt * n, binary, base + i * stride) for i in range(acc["count"])]


def main():
    src, dst = sys.argv[1], sys.argv[2]
    doc, binary = read_glb(src)
    positions, faces = [], []
    for mesh in doc["meshes"]:
        for primitive in mesh["primitives"]:
            if primitive.get("mode", 4) != 4:
                continue
            base = len(positions)
            points = accessor(doc, binary, primitive["attributes"]["POSITION"])
            positions.extend(points)
            if "indices" in primitive:
                flat = [i[0] for i in accessor(doc, binary, primitive["indices"])]
            else:
                flat = list(range(len(points)))
            faces.extend((base + flat[k], base + flat[k + 1], base + flat[k + 2]) for k in range(0, len(flat) - 2, 3))
    header = (
        "ply\nformat binary_little_endian 1.0\ncomment converted from "
        + src.split("/")[-1]
        + f"\nelement vertex {len(positions)}\nproperty float x\nproperty float y\nproperty float z\n"
        + f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    with open(dst, "wb") as out:
        out.write(header.encode("ascii"))
        out.write(b"".join(struct.pack("<fff", *p) for p in positions))
        out.write(b"".join(struct.pack("<Biii", 3, *f) for f in faces))
    print(f"{dst}: {len(positions)} vertices, {len(faces)} triangles")


if __name__ == "__main__":
    main()
