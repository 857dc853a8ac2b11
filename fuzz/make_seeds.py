#!/usr/bin/env python3
"""Write the seed corpora (fuzz/seeds/<target>/) from real files bundled in the repository's
test data: each seed is a real file cut to a few records (libFuzzer mutates small inputs far
faster than megabyte scans) or converted into another of our formats. Run from fuzz/:
`python3 make_seeds.py`. Sources are named in README.md."""
import math, os, struct

ROOT = os.path.dirname(os.path.abspath(__file__)) + "/.."
OUT = ROOT + "/fuzz/seeds"

def out(target, name, data):
    os.makedirs(f"{OUT}/{target}", exist_ok=True)
    with open(f"{OUT}/{target}/{name}", "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())

def pcd_header_and_data(path):
    raw = open(path, "rb").read()
    pos, lines = 0, []
    while True:
        end = raw.index(b"\n", pos)
        line = raw[pos:end].decode()
        lines.append(line)
        pos = end + 1
        if line.startswith("DATA"):
            return lines, raw[pos:]

def cut_pcd(path, n):
    """The header with WIDTH/POINTS set to n, the first n binary records, and the record size."""
    lines, data = pcd_header_and_data(path)
    fields = dict((l.split()[0], l.split()[1:]) for l in lines if l and not l.startswith("#"))
    sizes = [int(s) for s in fields["SIZE"]]
    counts = [int(c) for c in fields.get("COUNT", ["1"] * len(sizes))]
    rec = sum(s * c for s, c in zip(sizes, counts))
    head = []
    for l in lines:
        k = l.split()[0] if l else ""
        head.append({"WIDTH": f"WIDTH {n}", "HEIGHT": "HEIGHT 1", "POINTS": f"POINTS {n}"}.get(k, l))
    return head, data[: n * rec], fields, sizes, counts, rec

def lzf_literals(b):
    """A valid LZF stream of literal runs only (what PCL's decoder reads)."""
    out = bytearray()
    for i in range(0, len(b), 32):
        chunk = b[i : i + 32]
        out.append(len(chunk) - 1)
        out += chunk
    return bytes(out)

def pcd_seeds():
    for name, path, n in [
        ("garage", "slam-core/tests/data/hdl32e_garage_1503604882.703390000.pcd", 12),
        ("ouster", "slam-core/tests/data/os1_128_frame_00_fid1795.pcd", 12),
    ]:
        head, data, fields, sizes, counts, rec = cut_pcd(f"{ROOT}/{path}", n)
        body = "\n".join(head[:-1]) + "\n"
        out("pcd", f"{name}_binary.pcd", (body + "DATA binary\n").encode() + data)
        # Column layout for binary_compressed: each field's values for all points in turn.
        cols, off = b"", 0
        for s, c in zip(sizes, counts):
            cols += b"".join(data[i * rec + off : i * rec + off + s * c] for i in range(n))
            off += s * c
        comp = lzf_literals(cols)
        out("pcd", f"{name}_compressed.pcd",
            (body + "DATA binary_compressed\n").encode() + struct.pack("<II", len(comp), len(cols)) + comp)
        # Ascii: every value of every field, as PCL prints them.
        types = fields["TYPE"]
        fmt = {("F", 4): "f", ("F", 8): "d", ("U", 1): "B", ("U", 2): "H", ("U", 4): "I",
               ("I", 1): "b", ("I", 2): "h", ("I", 4): "i"}
        rows = []
        for i in range(n):
            vals, off = [], i * rec
            for t, s, c in zip(types, sizes, counts):
                for _ in range(c):
                    v = struct.unpack("<" + fmt[(t, s)], data[off : off + s])[0]
                    vals.append(repr(v) if t == "F" else str(v))
                    off += s
            rows.append(" ".join(vals))
        out("pcd", f"{name}_ascii.pcd", body + "DATA ascii\n" + "\n".join(rows) + "\n")
    return cut_pcd(f"{ROOT}/slam-core/tests/data/os1_128_frame_00_fid1795.pcd", 12)

def ply_seeds():
    raw = open(f"{ROOT}/slam-core/tests/data/hdl32e_pair_target.ply", "rb").read()
    end = raw.index(b"end_header\n") + len(b"end_header\n")
    head = raw[:end].decode().splitlines()
    n = 12
    head = [f"element vertex {n}" if l.startswith("element vertex") else l for l in head]
    data = raw[end : end + n * 16]
    out("ply", "small_gicp_binary.ply", ("\n".join(head) + "\n").encode() + data)
    rows = [" ".join(repr(v) for v in struct.unpack("<4f", data[i * 16 : i * 16 + 16])) for i in range(n)]
    ascii_head = [l.replace("binary_little_endian", "ascii") for l in head]
    out("ply", "small_gicp_ascii.ply", "\n".join(ascii_head) + "\n" + "\n".join(rows) + "\n")
    big = [l.replace("binary_little_endian", "binary_big_endian") for l in head]
    be = b"".join(struct.pack(">4f", *struct.unpack("<4f", data[i * 16 : i * 16 + 16])) for i in range(n))
    out("ply", "small_gicp_big_endian.ply", ("\n".join(big) + "\n").encode() + be)

def kitti_bin_seed(ouster):
    head, data, fields, sizes, counts, rec = ouster
    # The Ouster scan's x y z intensity (its first four F4 fields) as a KITTI velodyne record.
    pts = b"".join(data[i * rec : i * rec + 16] for i in range(len(data) // rec))
    out("kitti_bin", "ouster_xyzi.bin", pts)

def pose_seeds():
    text = open(f"{ROOT}/slam-core/tests/data/os1_128_poses_kitti.txt").read()
    out("kitti_poses", "ouster_poses.txt", text)
    lines = []
    for k, l in enumerate(text.split("\n")):
        if not l.strip():
            continue
        m = [float(v) for v in l.split()]
        r = [[m[0], m[1], m[2]], [m[4], m[5], m[6]], [m[8], m[9], m[10]]]
        w = math.sqrt(max(0.0, 1 + r[0][0] + r[1][1] + r[2][2])) / 2
        x = math.copysign(math.sqrt(max(0.0, 1 + r[0][0] - r[1][1] - r[2][2])) / 2, r[2][1] - r[1][2])
        y = math.copysign(math.sqrt(max(0.0, 1 - r[0][0] + r[1][1] - r[2][2])) / 2, r[0][2] - r[2][0])
        z = math.copysign(math.sqrt(max(0.0, 1 - r[0][0] - r[1][1] + r[2][2])) / 2, r[1][0] - r[0][1])
        lines.append(f"{0.1 * k!r} {m[3]!r} {m[7]!r} {m[11]!r} {x!r} {y!r} {z!r} {w!r}")
    out("tum", "ouster_poses.tum", "# timestamp tx ty tz qx qy qz qw\n" + "\n".join(lines) + "\n")

def graph_seeds():
    out("g2o", "tinyGrid3D.g2o", open(f"{ROOT}/posegraph/tests/data/tinyGrid3D.g2o", "rb").read())
    m3500 = open(f"{ROOT}/posegraph/tests/data/input_M3500_g2o.g2o").read().splitlines()
    verts = [l for l in m3500 if l.startswith("VERTEX")][:20]
    edges = [l for l in m3500 if l.startswith("EDGE")]
    ids = {l.split()[1] for l in verts}
    edges = [l for l in edges if l.split()[1] in ids and l.split()[2] in ids][:30]
    out("g2o", "M3500_first20.g2o", "\n".join(verts + edges) + "\n")
    # TORO: the same SE(2) graph in TORO's lines (information reordered xx xy yy tt xt yt).
    toro = []
    for l in verts:
        toro.append("VERTEX2 " + " ".join(l.split()[1:]))
    for l in edges:
        w = l.split()
        xx, xy, xt, yy, yt, tt = w[6:12]
        toro.append(" ".join(["EDGE2"] + w[1:6] + [xx, xy, yy, tt, xt, yt]))
    out("toro", "M3500_first20.graph", "\n".join(toro) + "\n")

def movingai_seeds():
    d = f"{ROOT}/pathfind/tests/data"
    out("movingai_map", "arena.map", open(f"{d}/arena.map", "rb").read())
    out("movingai_scen", "arena.map.scen", "".join(open(f"{d}/arena.map.scen").readlines()[:30]))
    # A version 1.0 header with lines of the same form (two decimals), from arena's queries.
    v1 = ["version 1.0"] + [
        "\t".join(l.split("\t")[:8] + [f"{float(l.split()[8]):.2f}"])
        for l in open(f"{d}/arena.map.scen").read().splitlines()[1:20]
    ]
    out("movingai_scen", "arena_v1.0.map.scen", "\n".join(v1) + "\n")
    return open(f"{d}/arena.map").read().splitlines()

def ros_map_seed(arena):
    rows = arena[4:]
    h, w = len(rows), len(rows[0])
    pix = bytes(0 if c in "@OTW" else 254 for r in rows for c in r)
    pgm = f"P5\n{w} {h}\n255\n".encode() + pix
    yaml = "image: arena.pgm\nmode: trinary\nresolution: 0.05\norigin: [-1.2, 3.5, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
    out("ros_map", "arena_pgm", yaml.encode() + b"\0" + pgm)

def recording_seeds():
    out("recording_index", "index.txt",
        "# spot-nav recording v1\n# index stamp cloud\n" + "".join(f"{i} {0.1 * i!r} clouds/{i:06}.pcd\n" for i in range(6)))
    out("recording_calibration", "calibration.txt",
        "# LiDAR pose in Spot's body frame: tx ty tz qx qy qz qw\nbody_T_lidar 0.1 0 0.45 0 0 0.008726535498373935 0.9999619230641713\n")

ouster = pcd_seeds()
ply_seeds()
kitti_bin_seed(ouster)
pose_seeds()
graph_seeds()
ros_map_seed(movingai_seeds())
recording_seeds()
