#!/usr/bin/python3
"""Writes small valid seed files for the fuzz targets (fuzz/corpus/<format>/).
    /usr/bin/python3 fuzz/corpus/make_seeds.py"""
import os
import struct

ROOT = os.path.dirname(os.path.abspath(__file__))


def write(folder, name, data):
    os.makedirs(os.path.join(ROOT, folder), exist_ok=True)
    with open(os.path.join(ROOT, folder, name), "wb") as f:
        f.write(data.encode() if isinstance(data, str) else data)


head = ("ply\nformat {} 1.0\ncomment seed\nelement vertex 2\nproperty float x\nproperty float y\n"
        "property double z\nproperty uchar red\nproperty float nx\nproperty float ny\nproperty float nz\n"
        "property list uchar int extra\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n")
write("ply", "ascii.ply", head.format("ascii") + "1 2 3 255 0 0 1 2 5 6\n4 5 6 7 1 0 0 0\n3 0 1 1\n")
for name, fmt, e in (("le.ply", "binary_little_endian", "<"), ("be.ply", "binary_big_endian", ">")):
    body = b""
    for p in ((1, 2, 3, 255, 0, 0, 1), (4, 5, 6, 7, 1, 0, 0)):
        body += struct.pack(e + "ffdBfff", *p) + struct.pack(e + "B", 1) + struct.pack(e + "i", 9)
    body += struct.pack(e + "B3i", 3, 0, 1, 1)
    write("ply", name, head.format(fmt).encode() + body)

write("xyz", "plain.xyz", "# comment\n1 2 3\n4 5 6\n")
write("xyz", "normals.xyz", "1 2 3 0 0 1\n4 5 6 1 0 0\n")
write("xyz", "header.csv", "x,y,z,intensity,nx,ny,nz\n1,2,3,4,0,0,1\n5,6,7,8,1,0,0\n")

write("off", "quad.off", "OFF\n# quad\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n")
write("off", "noff.off", "NOFF 3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n")
write("obj", "tri.obj", "o t\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2//1 -1//1\n")
write("obj", "quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")


def las(minor, fmt, reclen, n):
    size = 375 if minor >= 4 else 227
    h = bytearray(size)
    h[0:4] = b"LASF"
    h[24], h[25] = 1, minor
    struct.pack_into("<HIIBHI", h, 94, size, size, 0, fmt, reclen, 0 if fmt >= 6 else n)
    struct.pack_into("<6d", h, 131, 0.01, 0.01, 0.01, 1000.0, 2000.0, 0.0)
    if minor >= 4:
        struct.pack_into("<Q", h, 247, n)
    body = b""
    for i in range(n):
        r = bytearray(reclen)
        struct.pack_into("<3iH", r, 0, i, 2 * i, 3 * i, 100 * i)
        r[14] = 0x11 if fmt < 6 else 0x21
        r[16 if fmt >= 6 else 15] = 2
        body += bytes(r)
    return bytes(h) + body

write("las", "v12_f3.las", las(2, 3, 34, 3))
write("las", "v12_f0.las", las(2, 0, 20, 2))
write("las", "v14_f8.las", las(4, 8, 38, 3))

pcd = "VERSION 0.7\nFIELDS x y z rgb normal_x normal_y normal_z\nSIZE 4 4 4 4 4 4 4\nTYPE F F F U F F F\nCOUNT 1 1 1 1 1 1 1\nWIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA {}\n"
write("pcd", "ascii.pcd", pcd.format("ascii") + "1 2 3 16711680 0 0 1\n4 5 6 255 1 0 0\n")
write("pcd", "binary.pcd", pcd.format("binary").encode() + struct.pack("<3fI3f3fI3f", 1, 2, 3, 16711680, 0, 0, 1, 4, 5, 6, 255, 1, 0, 0))
soa = struct.pack("<2f2f2f2I2f2f2f", 1, 4, 2, 5, 3, 6, 16711680, 255, 0, 1, 0, 0, 1, 0)
write("pcd", "compressed.pcd", pcd.format("binary_compressed").encode() + struct.pack("<II", len(soa) + 2, len(soa)) + b"\x1f" + soa[:32] + b"\x17" + soa[32:])
