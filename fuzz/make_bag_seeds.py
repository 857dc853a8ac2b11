#!/usr/bin/env python3
"""Write the seed corpora of the bag and ROS message targets (fuzz/seeds/ros1_bag, mcap_bag,
point_cloud2, ros_message) with the Python `rosbags` package (an implementation of both bag
formats and both serialisations that owes nothing to spot-nav), from real data bundled in the
repository: the first points of the Ouster OS1-128 frame (`slam-core/tests/data`, x y z
intensity ring t) and the first poses of its KITTI trajectory. Run from fuzz/ with the python of
a venv holding `spot-adapter/tests/bags/requirements.txt` (the one `cargo test --test bags`
makes under target/ will do):

    ../target/rosbags-venv-0.11.9/bin/python make_bag_seeds.py

Bags are three scans of 16 points (every 48th return, so each spans the sweep); each seed is a
few kilobytes.
"""
import os
import shutil
import struct
import tempfile
from pathlib import Path

import numpy as np
from rosbags.rosbag1 import Writer as Ros1Writer
from rosbags.rosbag2 import CompressionFormat, CompressionMode, StoragePlugin
from rosbags.rosbag2 import Writer as Ros2Writer
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "fuzz" / "seeds"
POINTS = 16
SCANS = 3
# Ouster's PCD stamps are relative; the bags are put on a realistic clock (2023-11-14).
EPOCH = 1_700_000_000.0
PERIOD = 0.1
DATATYPE = {"i1": 1, "u1": 2, "i2": 3, "u2": 4, "i4": 5, "u4": 6, "f4": 7, "f8": 8}


def out(target, name, data):
    (OUT / target).mkdir(parents=True, exist_ok=True)
    (OUT / target / name).write_bytes(data)


def ouster_scans():
    """SCANS clouds of POINTS returns each from the Ouster frame, each spread over its sweep."""
    raw = (ROOT / "slam-core/tests/data/os1_128_frame_00_fid1795.pcd").read_bytes()
    header, _, body = raw.partition(b"DATA binary\n")
    fields = {}
    for line in header.decode().splitlines():
        if line and not line.startswith("#"):
            key, *values = line.split()
            fields[key] = values
    kinds = {("F", "4"): "<f4", ("U", "2"): "<u2"}
    dtype = np.dtype([(n, kinds[(t, s)]) for n, s, t in zip(fields["FIELDS"], fields["SIZE"], fields["TYPE"])])
    cloud = np.frombuffer(body, dtype=dtype, count=int(fields["POINTS"][0]))
    returns = cloud[(cloud["x"] != 0) | (cloud["y"] != 0) | (cloud["z"] != 0)]
    picked = returns[np.linspace(0, len(returns) - 1, SCANS * POINTS).astype(int)]
    return [picked[k::SCANS] for k in range(SCANS)]


def kitti_poses():
    """The first SCANS poses (x y z qx qy qz qw) of the Ouster trajectory."""
    poses = []
    for line in (ROOT / "slam-core/tests/data/os1_128_poses_kitti.txt").read_text().splitlines()[:SCANS]:
        m = [float(v) for v in line.split()]
        r = np.array([m[0:3], m[4:7], m[8:11]])
        w = np.sqrt(max(0.0, 1 + np.trace(r))) / 2
        q = [(r[2, 1] - r[1, 2]) / (4 * w), (r[0, 2] - r[2, 0]) / (4 * w), (r[1, 0] - r[0, 1]) / (4 * w), w]
        poses.append([m[3], m[7], m[11], *q])
    return poses


def split_stamp(seconds):
    sec = int(np.floor(seconds))
    return sec, min(int(round((seconds - sec) * 1e9)), 999_999_999)


class Messages:
    """Message builders for one typestore (ROS 1 or ROS 2 definitions)."""

    def __init__(self, store, ros1):
        self.store = get_typestore(store)
        self.store.register(get_types_from_msg("geometry_msgs/TransformStamped[] transforms", "tf2_msgs/msg/TFMessage"))
        self.t = self.store.types
        self.ros1 = ros1

    def serialize(self, msg, msgtype):
        if self.ros1:
            return self.store.serialize_ros1(msg, msgtype)
        return self.store.serialize_cdr(msg, msgtype)

    def header(self, stamp, frame):
        sec, nanosec = split_stamp(stamp)
        time = self.t["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec)
        if self.ros1:
            return self.t["std_msgs/msg/Header"](seq=0, stamp=time, frame_id=frame)
        return self.t["std_msgs/msg/Header"](stamp=time, frame_id=frame)

    def cloud(self, stamp, columns, height=1, big_endian=False):
        """columns: (name, values, kind) with kind a numpy type like 'f4'; ('', n, None) pads."""
        order = ">" if big_endian else "<"
        names, formats, offsets, fields, offset = [], [], [], [], 0
        for name, values, kind in columns:
            if not name:
                offset += values
                continue
            names.append(name)
            formats.append(kind if kind in ("u1", "i1") else order + kind)
            offsets.append(offset)
            fields.append(self.t["sensor_msgs/msg/PointField"](name=name, offset=offset, datatype=DATATYPE[kind], count=1))
            offset += np.dtype(kind).itemsize
        n = len(columns[0][1])
        points = np.zeros(n, dtype=np.dtype({"names": names, "formats": formats, "offsets": offsets, "itemsize": offset}))
        for name, values, _ in columns:
            if name:
                points[name] = values
        return self.t["sensor_msgs/msg/PointCloud2"](
            header=self.header(stamp, "os_sensor"),
            height=height,
            width=n // height,
            fields=fields,
            is_bigendian=big_endian,
            point_step=offset,
            row_step=offset * (n // height),
            data=np.frombuffer(points.tobytes(), dtype=np.uint8),
            is_dense=False,
        )

    def quaternion(self, q):
        return self.t["geometry_msgs/msg/Quaternion"](x=q[0], y=q[1], z=q[2], w=q[3])

    def vector(self, v):
        return self.t["geometry_msgs/msg/Vector3"](x=v[0], y=v[1], z=v[2])

    def transform(self, stamp, parent, child, pose):
        return self.t["geometry_msgs/msg/TransformStamped"](
            header=self.header(stamp, parent),
            child_frame_id=child,
            transform=self.t["geometry_msgs/msg/Transform"](translation=self.vector(pose), rotation=self.quaternion(pose[3:])),
        )

    def tf(self, transforms):
        return self.t["tf2_msgs/msg/TFMessage"](transforms=transforms)

    def odometry(self, stamp, pose):
        t = self.t
        return t["nav_msgs/msg/Odometry"](
            header=self.header(stamp, "odom"),
            child_frame_id="base_link",
            pose=t["geometry_msgs/msg/PoseWithCovariance"](
                pose=t["geometry_msgs/msg/Pose"](
                    position=t["geometry_msgs/msg/Point"](x=pose[0], y=pose[1], z=pose[2]),
                    orientation=self.quaternion(pose[3:]),
                ),
                covariance=np.zeros(36),
            ),
            twist=t["geometry_msgs/msg/TwistWithCovariance"](
                twist=t["geometry_msgs/msg/Twist"](linear=self.vector([0, 0, 0]), angular=self.vector([0, 0, 0])),
                covariance=np.zeros(36),
            ),
        )

    def imu(self, stamp, orientation_known=True):
        t = self.t
        covariance = np.zeros(9)
        if not orientation_known:
            covariance[0] = -1.0
        return t["sensor_msgs/msg/Imu"](
            header=self.header(stamp, "os_imu"),
            orientation=self.quaternion([0.0, 0.0, 0.0, 1.0]),
            orientation_covariance=covariance,
            angular_velocity=self.vector([0.0, 0.0, 0.1]),
            angular_velocity_covariance=np.zeros(9),
            linear_acceleration=self.vector([0.0, 0.0, 9.81]),
            linear_acceleration_covariance=np.zeros(9),
        )


MOUNT = [0.2, 0.0, 0.15, 0.0, 0.0, 0.0, 1.0]


def layouts(p):
    """The clouds' field layouts, by name: (columns, height, big endian)."""
    t = p["t"].astype(np.float64)  # the PCD's t: seconds since the scan's start
    xyz = [("x", p["x"], "f4"), ("y", p["y"], "f4"), ("z", p["z"], "f4")]
    return {
        # Ouster's driver: x y z pad intensity t(ns) reflectivity ring(u16) pad.
        "ouster": (xyz + [("", 4, None), ("intensity", p["intensity"], "f4"), ("t", np.round(t * 1e9), "u4"),
                          ("reflectivity", np.zeros(len(p)), "u2"), ("ring", p["ring"], "u2"), ("", 8, None)], 1, False),
        # Velodyne's: x y z pad intensity ring(u16) pad time (f32 seconds since the stamp).
        "velodyne": (xyz + [("", 4, None), ("intensity", p["intensity"], "f4"), ("ring", p["ring"], "u2"),
                            ("", 2, None), ("time", t, "f4")], 1, False),
        # float64 coordinates, ring uint8, absolute float64 seconds (Hesai).
        "f64_absolute": ([("x", p["x"], "f8"), ("y", p["y"], "f8"), ("z", p["z"], "f8"),
                          ("ring", p["ring"] % 256, "u1"), ("", 7, None), ("timestamp", None, "f8")], 1, False),
        # Absolute time split into two uint32 fields.
        "split_time": (xyz + [("sec", None, "u4"), ("nsec", None, "u4")], 1, False),
        # Big-endian, two rows.
        "big_endian_rows": (xyz + [("ring", p["ring"], "u2"), ("", 2, None), ("time", t, "f4")], 2, True),
    }


def cloud_message(m, stamp, p, layout):
    columns, height, big_endian = layouts(p)[layout]
    absolute = stamp + p["t"].astype(np.float64)
    filled = []
    for name, values, kind in columns:
        if name == "timestamp":
            values = absolute
        elif name == "sec":
            values = np.floor(absolute)
        elif name == "nsec":
            values = np.round((absolute - np.floor(absolute)) * 1e9)
        filled.append((name, values, kind))
    return m.cloud(stamp, filled, height=height, big_endian=big_endian)


def lap(m, scans, poses, layout, odometry):
    """(topic, type, stamp, message) of a short run: the mounting on /tf_static, then per scan
    an IMU reading, the odometry (on /odom and /tf, or /tf only) and the cloud."""
    t0 = EPOCH
    yield "/tf_static", "tf2_msgs/msg/TFMessage", t0, m.tf([m.transform(t0, "base_link", "os_sensor", MOUNT)])
    for k, (p, pose) in enumerate(zip(scans, poses)):
        stamp = t0 + k * PERIOD
        yield "/imu", "sensor_msgs/msg/Imu", stamp, m.imu(stamp, orientation_known=k % 2 == 0)
        if odometry in ("topic", "both"):
            yield "/odom", "nav_msgs/msg/Odometry", stamp, m.odometry(stamp, pose)
        if odometry in ("tf", "both"):
            yield "/tf", "tf2_msgs/msg/TFMessage", stamp, m.tf([m.transform(stamp, "odom", "base_link", pose)])
        yield "/points", "sensor_msgs/msg/PointCloud2", stamp, cloud_message(m, stamp, p, layout)
    # The odometry after the last cloud's stamp, so that every cloud lies within it.
    end = t0 + SCANS * PERIOD
    if odometry in ("topic", "both"):
        yield "/odom", "nav_msgs/msg/Odometry", end, m.odometry(end, poses[-1])
    if odometry in ("tf", "both"):
        yield "/tf", "tf2_msgs/msg/TFMessage", end, m.tf([m.transform(end, "odom", "base_link", poses[-1])])


def nanoseconds(seconds):
    sec, nanosec = split_stamp(seconds)
    return sec * 1_000_000_000 + nanosec


def write_ros1(messages, compression):
    m = Messages(Stores.ROS1_NOETIC, ros1=True)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "seed.bag"
        writer = Ros1Writer(path)
        if compression:
            writer.set_compression(compression)
        connections = {}
        with writer:
            for topic, msgtype, stamp, msg in messages(m):
                if topic not in connections:
                    connections[topic] = writer.add_connection(topic, msgtype, typestore=m.store)
                writer.write(connections[topic], nanoseconds(stamp), m.serialize(msg, msgtype))
        return path.read_bytes()


def write_mcap(messages, compress):
    m = Messages(Stores.ROS2_HUMBLE, ros1=False)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "seed"
        writer = Ros2Writer(path, version=8, storage_plugin=StoragePlugin.MCAP)
        if compress:
            writer.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
        connections = {}
        with writer:
            for topic, msgtype, stamp, msg in messages(m):
                if topic not in connections:
                    connections[topic] = writer.add_connection(topic, msgtype, typestore=m.store)
                writer.write(connections[topic], nanoseconds(stamp), m.serialize(msg, msgtype))
        (mcap,) = path.glob("*.mcap")
        return mcap.read_bytes()


def bag_seeds(scans, poses):
    runs = {
        "ouster_odom": ("ouster", "both"),
        "velodyne_tf": ("velodyne", "tf"),
        "split_time_lidar_only": ("split_time", "none"),
    }
    for name, (layout, odometry) in runs.items():
        messages = lambda m, layout=layout, odometry=odometry: lap(m, scans, poses, layout, odometry)
        out("ros1_bag", f"{name}.bag", write_ros1(messages, None))
        out("mcap_bag", f"{name}.mcap", write_mcap(messages, compress=False))
    messages = lambda m: lap(m, scans, poses, "ouster", "topic")
    out("ros1_bag", "ouster_odom_lz4.bag", write_ros1(messages, Ros1Writer.CompressionFormat.LZ4))
    out("ros1_bag", "ouster_odom_bz2.bag", write_ros1(messages, Ros1Writer.CompressionFormat.BZ2))
    out("mcap_bag", "ouster_odom_zstd.mcap", write_mcap(messages, compress=True))


def message_seeds(scans, poses):
    """Selector byte (bit 0: 0 ROS 1, 1 CDR; then the target's choice) and one payload."""
    stamp = EPOCH
    for wire, ros1 in (("ros1", True), ("cdr", False)):
        m = Messages(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE, ros1=ros1)
        bit = 0 if ros1 else 1
        cloud = "sensor_msgs/msg/PointCloud2"
        for layout in layouts(scans[0]):
            payload = m.serialize(cloud_message(m, stamp, scans[0], layout), cloud)
            out("point_cloud2", f"{layout}_{wire}", bytes([bit]) + payload)
        # The Ouster cloud with its unit given (integer nanoseconds since the stamp: 2).
        payload = m.serialize(cloud_message(m, stamp, scans[0], "ouster"), cloud)
        out("point_cloud2", f"ouster_unit_given_{wire}", bytes([bit | 2 << 1]) + payload)
        odometry = m.serialize(m.odometry(stamp, poses[1]), "nav_msgs/msg/Odometry")
        out("ros_message", f"odometry_{wire}", bytes([bit]) + odometry)
        tf = m.tf([m.transform(stamp, "odom", "base_link", poses[1]), m.transform(stamp, "base_link", "os_sensor", MOUNT)])
        out("ros_message", f"tf_{wire}", bytes([bit | 1 << 1]) + m.serialize(tf, "tf2_msgs/msg/TFMessage"))
        imu = m.serialize(m.imu(stamp), "sensor_msgs/msg/Imu")
        out("ros_message", f"imu_{wire}", bytes([bit | 2 << 1]) + imu)


def main():
    for target in ("ros1_bag", "mcap_bag", "point_cloud2", "ros_message"):
        shutil.rmtree(OUT / target, ignore_errors=True)
    scans, poses = ouster_scans(), kitti_poses()
    bag_seeds(scans, poses)
    message_seeds(scans, poses)


if __name__ == "__main__":
    main()
