#!/usr/bin/env python3
"""Writes the committed seed corpora (corpus/<target>/) and regression inputs
(regressions/<target>/) of the libFuzzer targets in this folder. Rerun after changing an input
format; the files are small and committed. Usage: test/fuzz/make_seeds.py"""
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
EXT = {"obj": 0, "stl": 1, "ply": 2, "off": 3, "dae": 4, "gltf": 5, "cao": 6}


def put(kind, target, name, data):
    folder = os.path.join(HERE, kind, target)
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, name), "wb") as f:
        f.write(data)


def cube_obj(offset=(0.0, 0.0, 0.0), scale=1.0):
    lines = []
    for i in range(8):
        p = [(0.5 if i & 1 else -0.5), (0.5 if i & 2 else -0.5), (0.5 if i & 4 else -0.5)]
        lines.append("v %.17g %.17g %.17g" % tuple(scale * c + o for c, o in zip(p, offset)))
    lines += ["f 1 3 4", "f 1 4 2", "f 5 6 8", "f 5 8 7", "f 1 2 6", "f 1 6 5",
              "f 3 7 8", "f 3 8 4", "f 1 5 7", "f 1 7 3", "f 2 4 8", "f 2 8 6"]
    return ("\n".join(lines) + "\n").encode()


def mesh(kind, name, ext, data):
    put(kind, "mesh_loading", name, bytes([EXT[ext]]) + data)


# ---- mesh_loading ---------------------------------------------------------------------------
mesh("corpus", "cube.obj", "obj", cube_obj())
mesh("corpus", "textured.obj", "obj", b"mtllib none.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\n"
     b"vt 1 0\nvt 0 1\nvn 0 0 1\nusemtl x\nf 1/1/1 2/2/1 3/3/1\n")
mesh("corpus", "triangle_ascii.stl", "stl", b"solid t\nfacet normal 0 0 1\nouter loop\n"
     b"vertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n")
mesh("corpus", "triangle_binary.stl", "stl", b"\0" * 80 + struct.pack("<I", 1) +
     struct.pack("<12fH", 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0))
mesh("corpus", "tetra_ascii.ply", "ply", b"ply\nformat ascii 1.0\nelement vertex 4\n"
     b"property float x\nproperty float y\nproperty float z\nelement face 4\n"
     b"property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
     b"3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n")
mesh("corpus", "tetra_binary.ply", "ply", b"ply\nformat binary_little_endian 1.0\n"
     b"element vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
     b"element face 4\nproperty list uchar int vertex_indices\nend_header\n" +
     struct.pack("<12f", 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1) +
     b"".join(bytes([3]) + struct.pack("<3i", *f) for f in [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]))
mesh("corpus", "tetra.off", "off", b"OFF\n4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
     b"3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n")
# Issue 8 finding 5 and 4: the inputs that found undefined behaviour, leaks and huge allocations.
mesh("regressions", "cube_shifted_1e6.obj", "obj", cube_obj((1e6, -1e6, 1e6)))
mesh("regressions", "cube_shifted_1e14_x.obj", "obj", cube_obj((1e14, 0, 0)))
mesh("regressions", "cube_1e30.obj", "obj", cube_obj(scale=1e30))
mesh("regressions", "collinear.obj", "obj", b"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n")
mesh("regressions", "ply_100M_vertices.ply", "ply", b"ply\nformat binary_little_endian 1.0\n"
     b"element vertex 100000000\nproperty float x\nproperty float y\nproperty float z\n"
     b"element face 1\nproperty list uchar int vertex_indices\nend_header\n" + b"\0" * 64)
mesh("regressions", "stl_4G_facets.stl", "stl", b"x" * 80 + struct.pack("<I", 4000000000) + b"\0" * 100)
mesh("regressions", "stl_corrupt_ascii.stl", "stl", b"solid x\nfacet normal 0 0 1\nouter loop\n"
     b"vertex 0 0 0\nvertex 1 0\nendsolid\n")
mesh("regressions", "stl_truncated_binary.stl", "stl", b"\0" * 80 + struct.pack("<I", 2) + b"\0" * 60)

# ---- sequence_reader: K.txt 0xff pose.txt 0xff 000000.png -----------------------------------
K = b"600 0 319.5\n0 600 239.5\n0 0 1\n"
POSE = b"1 0 0 0 1 0 0 0 1 0 0 0.5\n"
PNG_64 = (b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR" + struct.pack(">II", 64, 48) + b"\x08\x00\x00\x00\x00"
          + b"\0\0\0\0")
put("corpus", "sequence_reader", "valid", K + b"\xff" + POSE * 3 + b"\xff" + PNG_64)
put("corpus", "sequence_reader", "commas", b"600,0,320,0,600,240,0,0,1" + b"\xff" + b"# c\n" + POSE + b"\xff")
put("regressions", "sequence_reader", "pose_one_line", K + b"\xff" + POSE + b"\xff" + PNG_64)
put("regressions", "sequence_reader", "k_fx_1e-300", b"1e-300 0 320 0 600 240 0 0 1\xff" + POSE + b"\xff" + PNG_64)
put("regressions", "sequence_reader", "png_20000x20000", K + b"\xff" + POSE + b"\xff" +
    PNG_64.replace(struct.pack(">II", 64, 48), struct.pack(">II", 20000, 20000)))
put("regressions", "sequence_reader", "pose_z_1e300", K + b"\xff" + b"1 0 0 0 1 0 0 0 1 1e300 0 1e300\n" + b"\xff")


# ---- image_conversion -----------------------------------------------------------------------
ENC = ["mono8", "mono16", "bgr8", "rgb8", "bgra8", "rgba8", "bayer_rggb8", "bayer_bggr16",
       "32FC1", "yuv422", "16UC1", "bgr16"]
MODELS = ["plumb_bob", "rational_polynomial", "equidistant", ""]


def pair(w, h, step, encoding, data, bigendian=0, info_size=None, K=None, P=None, D=(),
         model="plumb_bob", rectified=0, binning=(0, 0), roi=(0, 0, 0, 0)):
    iw, ih = info_size or (w, h)
    K = K or [0.9 * iw, 0, iw / 2, 0, 0.9 * iw, ih / 2, 0, 0, 1]
    P = P or [K[0], 0, K[2], 0, 0, K[4], K[5], 0, 0, 0, 1, 0]
    out = struct.pack("<IIIB", w, h, step, bigendian)
    if encoding in ENC:
        out += bytes([ENC.index(encoding)])
    else:
        enc = encoding.encode()
        out += bytes([255]) + struct.pack("<H", len(enc)) + enc
    out += struct.pack("<8I", iw, ih, binning[0], binning[1], *roi)
    out += bytes([MODELS.index(model), len(D), rectified])
    out += struct.pack("<9d", *K) + struct.pack("<12d", *P) + struct.pack("<%dd" % len(D), *D)
    return out + data


put("corpus", "image_conversion", "mono8_32", pair(32, 32, 32, "mono8", bytes(range(256)) * 4))
put("corpus", "image_conversion", "bgr8_40x32", pair(40, 32, 120, "bgr8", b"\x10\x20\x30" * 1280))
put("corpus", "image_conversion", "rgba8_32", pair(32, 32, 128, "rgba8", b"\x01\x02\x03\xff" * 1024))
put("corpus", "image_conversion", "mono16_32", pair(32, 32, 64, "mono16", b"\x00\x80" * 1024))
put("corpus", "image_conversion", "bayer16_32_be", pair(32, 32, 64, "bayer_bggr16", b"\x12\x34" * 1024, 1))
put("corpus", "image_conversion", "distorted_raw", pair(32, 32, 32, "mono8", b"\x7f" * 1024,
    D=(-0.2, 0.05, 0.001, 0.002, 0.01)))
put("corpus", "image_conversion", "fisheye", pair(32, 32, 32, "mono8", b"\x7f" * 1024,
    D=(0.1, 0.01, 0.0, 0.0), model="equidistant"))
put("corpus", "image_conversion", "binned_roi", pair(32, 32, 32, "mono8", b"\x7f" * 1024,
    info_size=(128, 128), binning=(2, 2), roi=(16, 16, 64, 64)))
# Issue 8 findings 4 and 6.
put("regressions", "image_conversion", "mono16_odd_step", pair(32, 32, 65, "mono16", b"\x00\x80" * 1040))
put("regressions", "image_conversion", "mono16_big_endian", pair(32, 32, 64, "mono16", b"\x80\x00" * 1024, 1))
put("regressions", "image_conversion", "encoding_10000", pair(32, 32, 32, "e" * 10000, b"\0" * 1024))
put("regressions", "image_conversion", "size_2e32", pair(32, 32, 32, "mono8", b"\0" * 1024,
    info_size=(0xffffffff, 0xffffffff)))
put("regressions", "image_conversion", "fx_1e-300", pair(32, 32, 32, "mono8", b"\0" * 1024,
    K=[1e-300, 0, 16, 0, 30, 16, 0, 0, 1]))
put("regressions", "image_conversion", "cx_1e12", pair(32, 32, 32, "mono8", b"\0" * 1024,
    K=[30, 0, 1e12, 0, 30, 16, 0, 0, 1]))
put("regressions", "image_conversion", "one_pixel", pair(1, 1, 1, "mono8", b"\0"))
put("regressions", "image_conversion", "100000x1", pair(100000, 1, 100000, "mono8", b"\0" * 100))
put("regressions", "image_conversion", "huge_header", pair(20000, 20000, 20000, "mono8", b"\0" * 100))
