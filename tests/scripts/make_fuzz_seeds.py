#!/usr/bin/env python3
"""Writes the small seed inputs of the fuzz targets in tests/fuzz/seeds/<target>/: one valid
file of each layout the readers and parsers take (the committed seeds were made with this).

Usage: python3 tests/scripts/make_fuzz_seeds.py [profiles.json from a tiny symmetrize run]
"""
import json
import pathlib
import struct
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
SEEDS = ROOT / "tests" / "fuzz" / "seeds"

# An octahedron of human size (metres, Y up), outward triangles.
V = [(0, 0, 0), (0.2, 0.85, 0), (0, 0.85, 0.1), (-0.2, 0.85, 0), (0, 0.85, -0.1), (0, 1.7, 0)]
F = [(0, 2, 1), (0, 3, 2), (0, 4, 3), (0, 1, 4), (5, 1, 2), (5, 2, 3), (5, 3, 4), (5, 4, 1)]


def put(target, name, data):
    d = SEEDS / target
    d.mkdir(parents=True, exist_ok=True)
    (d / name).write_bytes(data if isinstance(data, bytes) else data.encode())


def obj():
    text = "# units: m\n# up: +y\n" + "".join(f"v {x} {y} {z}\n" for x, y, z in V)
    put("obj_read", "octahedron.obj", text + "".join(f"f {a+1} {b+1} {c+1}\n" for a, b, c in F))
    # Quads, groups, negative indices, texture/normal parts, CR line endings.
    quads = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\ng a\nf 1/1/1 2/1/1 3//1 4\ng b\nf -4 -3 -1\n"
    put("obj_read", "quads.obj", quads.replace("\n", "\r"))


def ply_header(fmt, vertex_props, face_props, extra=""):
    h = f"ply\nformat {fmt} 1.0\ncomment units: m\nelement vertex {len(V)}\n"
    h += "".join(f"property {p}\n" for p in vertex_props)
    h += f"element face {len(F)}\n" + "".join(f"property {p}\n" for p in face_props)
    return h + extra + "end_header\n"


def ply():
    xyz = ["float x", "float y", "float z"]
    idx = ["list uchar int vertex_indices"]
    text = ply_header("ascii", xyz, idx) + "".join(f"{x} {y} {z}\n" for x, y, z in V)
    put("ply_read", "ascii.ply", text + "".join(f"3 {a} {b} {c}\n" for a, b, c in F))
    for fmt, e in [("binary_little_endian", "<"), ("binary_big_endian", ">")]:
        b = ply_header(fmt, ["double x", "double y", "double z", "uchar red"], idx).encode()
        b += b"".join(struct.pack(e + "dddB", x, y, z, 200) for x, y, z in V)
        b += b"".join(struct.pack(e + "Biii", 3, *f) for f in F)
        put("ply_read", f"{fmt}.ply", b)
    # Faces with a flag byte, a quad and a second list: the one-number-at-a-time path.
    faces = ["uchar flags", "list uchar int vertex_indices", "list uchar float texcoord"]
    b = ply_header("binary_little_endian", xyz, faces, "element edge 1\nproperty int a\n").encode()
    b = b.replace(f"element face {len(F)}".encode(), b"element face 2")
    b += b"".join(struct.pack("<fff", *v) for v in V)
    b += struct.pack("<BBiiii", 7, 4, 1, 2, 3, 4) + struct.pack("<Bff", 2, 0.5, 0.5)
    b += struct.pack("<BBiii", 7, 3, 0, 2, 1) + struct.pack("<B", 0)
    b += struct.pack("<i", 9)
    put("ply_read", "lists.ply", b)


def stl():
    b = b"binary STL seed".ljust(80, b" ") + struct.pack("<I", len(F))
    for f in F:
        b += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *V[i]) for i in f) + b"\0\0"
    put("stl_read", "binary.stl", b)
    text = "solid seed\n"
    for f in F:
        text += "facet normal 0 0 0\nouter loop\n" + "".join(
            "vertex {} {} {}\n".format(*V[i]) for i in f) + "endloop\nendfacet\n"
    put("stl_read", "ascii.stl", text + "endsolid seed\n")


def glb():
    positions = b"".join(struct.pack("<3f", *v) for v in V)
    indices = b"".join(struct.pack("<3H", *f) for f in F)
    bin_chunk = positions + indices + b"\0" * (-len(indices) % 4)
    lo = [min(v[k] for v in V) for k in range(3)]
    hi = [max(v[k] for v in V) for k in range(3)]
    doc = {
        "asset": {"version": "2.0", "extras": {"comments": ["units: m", "up: +y"]}},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"children": [1], "translation": [0, 0.1, 0]}, {"mesh": 0, "scale": [1, 1, 1]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": len(bin_chunk)}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": len(positions)},
            {"buffer": 0, "byteOffset": len(positions), "byteLength": len(indices)},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(V), "type": "VEC3", "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5123, "count": 3 * len(F), "type": "SCALAR"},
        ],
    }
    j = json.dumps(doc).encode()
    j += b" " * (-len(j) % 4)
    total = 12 + 8 + len(j) + 8 + len(bin_chunk)
    b = b"glTF" + struct.pack("<II", 2, total) + struct.pack("<I", len(j)) + b"JSON" + j
    b += struct.pack("<I", len(bin_chunk)) + b"BIN\0" + bin_chunk
    put("glb_read", "octahedron.glb", b)


def setpoints():
    ok = {"format": "dressform-setpoints/1", "form": "reference",
          "positions_mm": {"chest-l1": 23.5, "waist-front": 0}}
    put("setpoints", "valid.json", json.dumps(ok, indent=2))
    ok["positions_mm"] = {"chest-l1": 75, "neck-front": -2, "ghost": 1}
    put("setpoints", "out_of_stroke.json", json.dumps(ok))


def form():
    put("form", "reference.toml", (ROOT / "form-description" / "forms" / "reference.toml").read_bytes())


def profiles(path):
    # Keep the file small: round the numbers.
    p = json.loads(pathlib.Path(path).read_text())
    rounded = json.dumps(p, separators=(",", ":"))
    put("profiles", "tiny.json", json.dumps(json.loads(rounded, parse_float=lambda s: round(float(s), 2))))


obj()
ply()
stl()
glb()
setpoints()
form()
if len(sys.argv) > 1:
    profiles(sys.argv[1])
print("seeds in", SEEDS)
