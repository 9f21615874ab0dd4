#!/usr/bin/python3
"""Regenerates the malformed-file corpus: every file here must make readCloud throw a FileError
whose message names the file (tests/io/MalformedCorpusTest.cpp). Run from any folder:
    /usr/bin/python3 tests/data/malformed/make_corpus.py
Crashers found by fuzzing are added by hand under <format>/fuzz_*.<ext>."""
import os
import struct

ROOT = os.path.dirname(os.path.abspath(__file__))


def write(folder, name, data):
    os.makedirs(os.path.join(ROOT, folder), exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(ROOT, folder, name), "wb") as f:
        f.write(data)


PLY_HEAD = "ply\nformat {fmt} 1.0\nelement vertex {n}\nproperty float x\nproperty float y\nproperty float z\nend_header\n"


def ply_head(fmt, n):
    return PLY_HEAD.format(fmt=fmt, n=n)


# --- PLY ---
write("ply", "empty.ply", b"")
write("ply", "wrong_magic.ply", "plx\nformat ascii 1.0\nend_header\n")
write("ply", "no_end_header.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n")
write("ply", "no_format.ply", "ply\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n")
write("ply", "bad_format.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n")
write("ply", "bad_property_type.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n")
write("ply", "float_list_count.ply", "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list float int v\nend_header\n1 0\n")
write("ply", "missing_vertex.ply", "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n3 0 1 2\n")
write("ply", "missing_z.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n")
write("ply", "duplicate_property.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3 4\n")
write("ply", "lying_count_ascii.ply", ply_head("ascii", 10) + "1 2 3\n4 5 6\n")
write("ply", "huge_count_ascii.ply", ply_head("ascii", 10**18) + "1 2 3\n")
write("ply", "huge_count_binary.ply", ply_head("binary_little_endian", 2**62) + "\0" * 24)
write("ply", "overflow_count_binary.ply", ply_head("binary_little_endian", 18446744073709551615) + "\0" * 24)
write("ply", "count_too_big.ply", ply_head("ascii", "99999999999999999999999") + "1 2 3\n")
write("ply", "truncated_binary.ply", ply_head("binary_little_endian", 3).encode() + struct.pack("<8f", *range(8)))
write("ply", "truncated_big_endian.ply", ply_head("binary_big_endian", 2).encode() + struct.pack(">5f", *range(5)))
write("ply", "huge_list_binary.ply",
      ("ply\nformat binary_little_endian 1.0\nelement face 1\nproperty list uint int vertex_indices\n"
       "element vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n").encode()
      + struct.pack("<I", 0xFFFFFFFF) + b"\0" * 8)
write("ply", "negative_list_count.ply",
      ("ply\nformat binary_little_endian 1.0\nelement face 1\nproperty list char int vertex_indices\n"
       "element vertex 0\nproperty float x\nproperty float y\nproperty float z\nend_header\n").encode()
      + struct.pack("<b", -3) + b"\0" * 12)
write("ply", "nan_coordinates.ply", ply_head("ascii", 2) + "1 2 3\nnan 5 6\n")
write("ply", "inf_binary.ply", ply_head("binary_little_endian", 1).encode() + struct.pack("<3f", 1, float("inf"), 3))
write("ply", "text_in_ascii.ply", ply_head("ascii", 1) + "1 two 3\n")
write("ply", "too_many_values.ply", ply_head("ascii", 1) + "1 2 3 4\n")
write("ply", "uchar_out_of_range.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nproperty uchar c\nend_header\n1 2 3 300\n")
write("ply", "garbage.ply", b"ply\n" + bytes((i * 97 + 13) % 256 for i in range(300)))
write("ply", "binary_garbage.ply", bytes((i * 31 + 7) % 256 for i in range(200)))

# --- XYZ / TXT / CSV ---
write("xyz", "nan.xyz", "1 2 3\n4 nan 6\n")
write("xyz", "inf.csv", "x,y,z\n1,2,3\n-inf,0,0\n")
write("xyz", "ragged.csv", "1,2,3\n4,5,6,7\n")
write("xyz", "two_columns.txt", "1 2\n3 4\n")
write("xyz", "header_without_z.csv", "x,y,intensity\n1,2,3\n")
write("xyz", "text_in_data.xyz", "1 2 3\n4 5 six\n")
write("xyz", "empty_field.csv", "1,,3\n")
write("xyz", "duplicate_header.csv", "x,y,z,x\n1,2,3,4\n")
write("xyz", "binary_garbage.xyz", bytes((i * 53 + 11) % 256 for i in range(256)))
write("xyz", "inf_by_overflow.xyz", "1 2 1e999\n")

# --- OFF ---
write("off", "empty.off", b"")
write("off", "wrong_magic.off", "OFX\n3 1 0\n")
write("off", "missing_counts.off", "OFF\n")
write("off", "huge_counts.off", "OFF\n4000000000 4000000000 0\n0 0 0\n")
write("off", "truncated.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n")
write("off", "missing_faces.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
write("off", "bad_index.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n")
write("off", "negative_index.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n")
write("off", "face_too_short.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n")
write("off", "face_count_lies.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n5 0 1 2\n")
write("off", "nan_vertex.off", "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n")
write("off", "short_vertex.off", "OFF\n1 0 0\n0 0\n")
write("off", "binary_garbage.off", b"OFF\n" + bytes((i * 7 + 3) % 256 for i in range(128)))

# --- OBJ ---
write("obj", "bad_face.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\n")
write("obj", "index_zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n")
write("obj", "negative_too_far.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n")
write("obj", "short_vertex.obj", "v 1 2\n")
write("obj", "text_vertex.obj", "v 1 2 three\n")
write("obj", "face_two_corners.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n")
write("obj", "bad_normal_ref.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//2 3//1\n")
write("obj", "nan_vertex.obj", "v 0 0 0\nv inf 0 0\n")

# --- STL ---
STL_FACET = "facet normal 0 0 1\nouter loop\n{v}endloop\nendfacet\n"


def stl_ascii(*facets, end="endsolid s\n"):
    body = "".join(STL_FACET.format(v="".join("vertex %s\n" % c for c in f)) for f in facets)
    return "solid s\n" + body + end


TRI = ("0 0 0", "1 0 0", "0 1 0")
write("stl", "empty.stl", b"")
write("stl", "truncated_binary.stl", b"\0" * 80 + struct.pack("<I", 2) + b"\0" * 50)
write("stl", "binary_garbage.stl", bytes((i * 13 + 5) % 256 for i in range(300)))
write("stl", "four_vertices.stl", stl_ascii(TRI + ("1 1 0",)))
write("stl", "two_vertices.stl", stl_ascii(TRI[:2]))
write("stl", "bad_number.stl", stl_ascii(("0 0 0", "1 x 0", "0 1 0")))
write("stl", "short_vertex.stl", stl_ascii(("0 0 0", "1 0", "0 1 0")))
write("stl", "no_endsolid.stl", stl_ascii(TRI, end=""))
write("stl", "unknown_keyword.stl", stl_ascii(TRI).replace("outer loop", "outer hoop"))
write("stl", "nan_vertex.stl", stl_ascii(("0 0 0", "nan 0 0", "0 1 0")))

# --- LAS ---
def las(minor=2, fmt=0, reclen=20, count=1, offset=None, header_size=None, scale=(0.01, 0.01, 0.01),
        records=None, count64=None):
    size = header_size or (375 if minor >= 4 else 235 if minor == 3 else 227)
    h = bytearray((375 if minor >= 4 else 235 if minor == 3 else 227))
    h[0:4] = b"LASF"
    h[24] = 1
    h[25] = minor
    struct.pack_into("<HIIBHI", h, 94, size, offset if offset is not None else len(h), 0, fmt, reclen, count)
    struct.pack_into("<6d", h, 131, *scale, 0.0, 0.0, 0.0)
    if minor >= 4:
        struct.pack_into("<Q", h, 247, count if count64 is None else count64)
    body = records if records is not None else b"\0" * (reclen * count)
    return bytes(h) + body

write("las", "empty.las", b"")
write("las", "wrong_magic.las", b"LASX" + b"\0" * 300)
write("las", "truncated_header.las", las()[:150])
write("las", "huge_count.las", las(count=4000000000, records=b"\0" * 40))
write("las", "huge_count64.las", las(minor=4, fmt=6, reclen=30, count=0, count64=2**63, records=b"\0" * 60))
write("las", "truncated_points.las", las(count=3, records=b"\0" * 50))
write("las", "laz_bit.las", las(fmt=0x83, reclen=34))
write("las", "waveform_format.las", las(minor=3, fmt=4, reclen=57))
write("las", "format6_in_12.las", las(minor=2, fmt=6, reclen=30))
write("las", "bad_offset.las", las(offset=100000))
write("las", "offset_inside_header.las", las(offset=100))
write("las", "header_size_too_small.las", las(header_size=100))
write("las", "short_record.las", las(reclen=12))
write("las", "version_2.las", las(minor=2)[:24] + b"\x02\x00" + las(minor=2)[26:])
write("las", "zero_scale.las", las(scale=(0.01, 0.0, 0.01)))
write("las", "nan_scale.las", las(scale=(float("nan"), 0.01, 0.01)))
write("las", "counts_disagree.las", las(minor=4, fmt=6, reclen=30, count=1, count64=2, records=b"\0" * 60))
write("las", "compressed.laz", las())
write("las", "binary_garbage.las", b"LASF" + bytes((i * 11 + 5) % 256 for i in range(400)))

# --- PCD ---
PCD_HEAD = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
write("pcd", "empty.pcd", b"")
write("pcd", "no_version.pcd", "FIELDS x y z\nDATA ascii\n")
write("pcd", "no_data_line.pcd", PCD_HEAD + "WIDTH 1\nPOINTS 1\n")
write("pcd", "width_height_mismatch.pcd", PCD_HEAD + "WIDTH 2\nHEIGHT 2\nPOINTS 3\nDATA ascii\n")
write("pcd", "lying_points_ascii.pcd", PCD_HEAD + "WIDTH 5\nPOINTS 5\nDATA ascii\n1 2 3\n")
write("pcd", "huge_points_binary.pcd", PCD_HEAD + "WIDTH 4000000000\nHEIGHT 4000000000\nDATA binary\n" + "\0" * 24)
write("pcd", "overflow_width_height.pcd", PCD_HEAD + "WIDTH 18446744073709551615\nHEIGHT 2\nDATA binary\n")
write("pcd", "truncated_binary.pcd", PCD_HEAD.encode() + b"WIDTH 2\nPOINTS 2\nDATA binary\n" + b"\0" * 20)
write("pcd", "lzf_lying_size.pcd", PCD_HEAD.encode() + b"WIDTH 1\nPOINTS 1\nDATA binary_compressed\n" + struct.pack("<II", 3, 1000) + b"\x02abc")
write("pcd", "lzf_bad_reference.pcd", PCD_HEAD.encode() + b"WIDTH 1\nPOINTS 1\nDATA binary_compressed\n" + struct.pack("<II", 3, 12) + b"\xe0\xff\x00")
write("pcd", "lzf_truncated.pcd", PCD_HEAD.encode() + b"WIDTH 1\nPOINTS 1\nDATA binary_compressed\n" + struct.pack("<II", 13, 12) + b"\x0b" + b"\0" * 5)
write("pcd", "lzf_huge_ratio.pcd", PCD_HEAD.encode() + b"WIDTH 100000000\nPOINTS 100000000\nDATA binary_compressed\n" + struct.pack("<II", 4, 1200000000) + b"\x00\x00\xe0\xff")
write("pcd", "int64_field.pcd", "VERSION 0.7\nFIELDS x y z t\nSIZE 4 4 4 8\nTYPE F F F I\nWIDTH 1\nDATA ascii\n1 2 3 4\n")
write("pcd", "mismatched_fields.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 1\nDATA ascii\n1 2 3\n")
write("pcd", "no_z.pcd", "VERSION 0.7\nFIELDS x y\nSIZE 4 4\nTYPE F F\nWIDTH 1\nDATA ascii\n1 2\n")
write("pcd", "unknown_key.pcd", PCD_HEAD + "COLOUR 1\nWIDTH 1\nDATA ascii\n1 2 3\n")
write("pcd", "unknown_data.pcd", PCD_HEAD + "WIDTH 1\nDATA zip\n1 2 3\n")
write("pcd", "nan.pcd", PCD_HEAD + "WIDTH 1\nDATA ascii\nnan 2 3\n")
write("pcd", "zero_count.pcd", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 0 1\nWIDTH 1\nDATA ascii\n1 2\n")
write("pcd", "binary_garbage.pcd", bytes((i * 29 + 1) % 256 for i in range(256)))
