"""Write ROS bags from a spot-nav recording with the `rosbags` package (an implementation of the
ROS 1 bag and ROS 2 MCAP formats and of both serialisations that owes nothing to spot-nav).

    python write_bags.py RECORDING_DIR OUT_DIR

writes into OUT_DIR:

- `lap_ros2/lap_ros2.mcap` (ROS 2 Humble, zstd chunks) and `lap.bag` (ROS 1 Noetic, lz4
  chunks): the recording's clouds on /points (x y z float32, padding, intensity, ring uint16,
  time float32 seconds since the stamp), its odometry on /odom and on /tf (odom -> base_link),
  the LiDAR mounting on /tf_static (base_link -> velodyne), and a constant IMU reading on /imu;
- `layouts/layouts.mcap` and `layouts.bag`: the first clouds again in other drivers' layouts,
  one topic each (see `layout_messages`), so a reader can be checked against the recording's
  own clouds.

Only the recording's files are read (index.txt, calibration.txt, odometry.tum, binary PCD).
"""

import sys
from pathlib import Path

import numpy as np
from rosbags.rosbag1 import Writer as Ros1Writer
from rosbags.rosbag2 import CompressionFormat, CompressionMode, StoragePlugin
from rosbags.rosbag2 import Writer as Ros2Writer
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

PCD_TYPES = {("F", "4"): "<f4", ("F", "8"): "<f8", ("U", "2"): "<u2", ("U", "1"): "u1"}
DATATYPE = {"i1": 1, "u1": 2, "i2": 3, "u2": 4, "i4": 5, "u4": 6, "f4": 7, "f8": 8}
LAYOUT_SCANS = 3
# The layouts' stamps are put on a realistic clock (2023-11-14), where absolute and relative
# times differ.
EPOCH = 1_700_000_000.0
ZERO_POINTS = 100


def read_pcd(path):
    data = path.read_bytes()
    header, _, body = data.partition(b"DATA binary\n")
    fields = {}
    for line in header.decode().splitlines():
        key, *values = line.split()
        fields[key] = values
    dtype = [(n, PCD_TYPES[(t, s)]) for n, s, t in zip(fields["FIELDS"], fields["SIZE"], fields["TYPE"])]
    return np.frombuffer(body, dtype=np.dtype(dtype), count=int(fields["POINTS"][0]))


def read_recording(root):
    calib = next(line for line in (root / "calibration.txt").read_text().splitlines() if line.startswith("body_T_lidar"))
    mount = [float(v) for v in calib.split()[1:]]
    odometry = [
        [float(v) for v in line.split()]
        for line in (root / "odometry.tum").read_text().splitlines()
        if line.strip() and not line.startswith("#")
    ]
    scans = []
    for line, pose in zip(
        (line for line in (root / "index.txt").read_text().splitlines() if line.strip() and not line.startswith("#")),
        odometry,
    ):
        _, stamp, cloud = line.split()
        scans.append((float(stamp), pose, read_pcd(root / cloud)))
    return mount, scans


def split_stamp(seconds):
    sec = int(np.floor(seconds))
    nanosec = int(round((seconds - sec) * 1e9))
    if nanosec == 1_000_000_000:
        sec, nanosec = sec + 1, 0
    return sec, nanosec


def nanoseconds(seconds):
    sec, nanosec = split_stamp(seconds)
    return sec * 1_000_000_000 + nanosec


class Messages:
    """Message builders for one typestore (ROS 1 or ROS 2 definitions)."""

    def __init__(self, store, ros1):
        self.store = get_typestore(store)
        # tf2_msgs is not among rosbags' built-in types.
        self.store.register(get_types_from_msg("geometry_msgs/TransformStamped[] transforms", "tf2_msgs/msg/TFMessage"))
        self.t = self.store.types
        self.ros1 = ros1

    def header(self, stamp, frame):
        sec, nanosec = split_stamp(stamp)
        time = self.t["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec)
        if self.ros1:
            return self.t["std_msgs/msg/Header"](seq=0, stamp=time, frame_id=frame)
        return self.t["std_msgs/msg/Header"](stamp=time, frame_id=frame)

    def cloud(self, stamp, frame, columns, height=1, row_padding=0, big_endian=False):
        """columns: list of (name, numpy array, dtype string like 'f4'); padding as ('', n, None)."""
        order = ">" if big_endian else "<"
        names, formats, offsets, fields = [], [], [], []
        offset = 0
        for name, values, kind in columns:
            if not name:
                offset += values
                continue
            names.append(name)
            formats.append(order + kind if kind not in ("u1", "i1") else kind)
            offsets.append(offset)
            fields.append(
                self.t["sensor_msgs/msg/PointField"](name=name, offset=offset, datatype=DATATYPE[kind], count=1)
            )
            offset += np.dtype(kind).itemsize
        point_step = offset
        n = len(columns[0][1])
        width = n // height
        dtype = np.dtype({"names": names, "formats": formats, "offsets": offsets, "itemsize": point_step})
        points = np.zeros(n, dtype=dtype)
        for name, values, kind in columns:
            if name:
                points[name] = values
        rows = points.tobytes()
        row_bytes = width * point_step
        data = b"".join(rows[r * row_bytes : (r + 1) * row_bytes] + b"\xee" * row_padding for r in range(height))
        return self.t["sensor_msgs/msg/PointCloud2"](
            header=self.header(stamp, frame),
            height=height,
            width=width,
            fields=fields,
            is_bigendian=big_endian,
            point_step=point_step,
            row_step=row_bytes + row_padding,
            data=np.frombuffer(data, dtype=np.uint8),
            is_dense=False,
        )

    def pose(self, values):
        t = self.t
        return t["geometry_msgs/msg/Pose"](
            position=t["geometry_msgs/msg/Point"](x=values[0], y=values[1], z=values[2]),
            orientation=t["geometry_msgs/msg/Quaternion"](x=values[3], y=values[4], z=values[5], w=values[6]),
        )

    def transform(self, stamp, parent, child, values):
        t = self.t
        return t["geometry_msgs/msg/TransformStamped"](
            header=self.header(stamp, parent),
            child_frame_id=child,
            transform=t["geometry_msgs/msg/Transform"](
                translation=t["geometry_msgs/msg/Vector3"](x=values[0], y=values[1], z=values[2]),
                rotation=t["geometry_msgs/msg/Quaternion"](x=values[3], y=values[4], z=values[5], w=values[6]),
            ),
        )

    def odometry(self, stamp, values):
        t = self.t
        zero = t["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0)
        return t["nav_msgs/msg/Odometry"](
            header=self.header(stamp, "odom"),
            child_frame_id="base_link",
            pose=t["geometry_msgs/msg/PoseWithCovariance"](pose=self.pose(values), covariance=np.zeros(36)),
            twist=t["geometry_msgs/msg/TwistWithCovariance"](
                twist=t["geometry_msgs/msg/Twist"](linear=zero, angular=zero), covariance=np.zeros(36)
            ),
        )

    def tf(self, transforms):
        return self.t["tf2_msgs/msg/TFMessage"](transforms=transforms)

    def imu(self, stamp):
        t = self.t
        return t["sensor_msgs/msg/Imu"](
            header=self.header(stamp, "base_link"),
            orientation=t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
            orientation_covariance=np.zeros(9),
            angular_velocity=t["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.1),
            angular_velocity_covariance=np.zeros(9),
            linear_acceleration=t["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=9.81),
            linear_acceleration_covariance=np.zeros(9),
        )


def lap_columns(points):
    columns = [("x", points["x"], "f4"), ("y", points["y"], "f4"), ("z", points["z"], "f4"), ("", 4, None)]
    if "intensity" in points.dtype.names:
        columns.append(("intensity", points["intensity"], "f4"))
    columns += [("ring", points["ring"], "u2"), ("", 2, None), ("time", points["t"], "f4")]
    return columns


def lap_messages(m, mount, scans):
    """(topic, type, stamp, message) of the lap in time order."""
    yield "/tf_static", "tf2_msgs/msg/TFMessage", scans[0][0], m.tf([m.transform(scans[0][0], "base_link", "velodyne", mount)])
    for stamp, pose, points in scans:
        yield "/imu", "sensor_msgs/msg/Imu", stamp, m.imu(stamp)
        yield "/odom", "nav_msgs/msg/Odometry", stamp, m.odometry(stamp, pose[1:])
        yield "/tf", "tf2_msgs/msg/TFMessage", stamp, m.tf([m.transform(stamp, "odom", "base_link", pose[1:])])
        yield "/points", "sensor_msgs/msg/PointCloud2", stamp, m.cloud(stamp, "velodyne", lap_columns(points))


def layout_messages(m, scans):
    """The first scans in other layouts: (topic, type, stamp, message)."""
    for stamp, _, p in scans[:LAYOUT_SCANS]:
        stamp += EPOCH
        t = p["t"].astype(np.float64)
        ns = np.round(t * 1e9)
        absolute = stamp + t
        sec = np.floor(absolute)
        nsec = np.round((absolute - sec) * 1e9)
        xyz32 = [("x", p["x"], "f4"), ("y", p["y"], "f4"), ("z", p["z"], "f4")]
        xyz64 = [("x", p["x"], "f8"), ("y", p["y"], "f8"), ("z", p["z"], "f8")]
        layouts = {
            # float64 points, padding, ring uint8, time as integer nanoseconds.
            "/f64_ring8_ns": xyz64 + [("", 3, None), ("ring", p["ring"], "u1"), ("", 4, None), ("t", ns, "u4")],
            # Ouster's order: x y z pad intensity t(ns) reflectivity ring(u16).
            "/ouster": xyz32 + [("", 4, None), ("intensity", np.ones(len(p)), "f4"), ("t", ns, "u4"),
                                ("reflectivity", np.zeros(len(p)), "u2"), ("ring", p["ring"], "u2"),
                                ("", 10, None)],
            # Absolute time split over two fields.
            "/split_time": xyz32 + [("ring", p["ring"], "u2"), ("sec", sec, "u4"), ("nsec", nsec, "u4")],
            # Absolute float64 seconds (Hesai).
            "/absolute_seconds": xyz32 + [("ring", p["ring"], "u2"), ("timestamp", absolute, "f8")],
            # Relative float64 seconds under "offset_time"... as Livox, but in seconds.
            "/relative_f64": xyz32 + [("offset_time", t, "f8")],
        }
        for topic, columns in layouts.items():
            yield topic, "sensor_msgs/msg/PointCloud2", stamp, m.cloud(stamp, "velodyne", columns)
        # Big-endian data with row padding, organised in 2 rows (a point dropped if odd).
        n = len(p) - len(p) % 2
        cut = [(name, v[:n], kind) if name else (name, v, kind) for name, v, kind in
               [("x", p["x"], "f4"), ("y", p["y"], "f4"), ("z", p["z"], "f4"), ("ring", p["ring"], "u2"),
                ("", 2, None), ("time", p["t"], "f4")]]
        yield "/big_endian_rows", "sensor_msgs/msg/PointCloud2", stamp, m.cloud(
            stamp, "velodyne", cut, height=2, row_padding=6, big_endian=True)
        # No-return points: exact zeros appended.
        zeros = [(name, np.concatenate([v, np.zeros(ZERO_POINTS)]), kind) if name else (name, v, kind)
                 for name, v, kind in [("x", p["x"], "f4"), ("y", p["y"], "f4"), ("z", p["z"], "f4"),
                                       ("time", t, "f4")]]
        yield "/with_zeros", "sensor_msgs/msg/PointCloud2", stamp, m.cloud(stamp, "velodyne", zeros)
        # Bad clouds: no coordinates, and times spread over 5 s (no unit fits one scan period).
        yield "/no_xyz", "sensor_msgs/msg/PointCloud2", stamp, m.cloud(
            stamp, "velodyne", [("a", p["x"], "f4"), ("b", p["y"], "f4"), ("c", p["z"], "f4")])
        yield "/five_second_sweep", "sensor_msgs/msg/PointCloud2", stamp, m.cloud(
            stamp, "velodyne", xyz32 + [("time", np.linspace(0.0, 5.0, len(p)), "f4")])


def write_ros2(path, messages, compress):
    m = Messages(Stores.ROS2_HUMBLE, ros1=False)
    writer = Ros2Writer(path, version=8, storage_plugin=StoragePlugin.MCAP)
    if compress:
        writer.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
    connections = {}
    with writer:
        for topic, msgtype, stamp, msg in messages(m):
            if topic not in connections:
                connections[topic] = writer.add_connection(topic, msgtype, typestore=m.store)
            writer.write(connections[topic], nanoseconds(stamp), m.store.serialize_cdr(msg, msgtype))


def write_ros1(path, messages):
    m = Messages(Stores.ROS1_NOETIC, ros1=True)
    writer = Ros1Writer(path)
    writer.set_compression(Ros1Writer.CompressionFormat.LZ4)
    connections = {}
    with writer:
        for topic, msgtype, stamp, msg in messages(m):
            if topic not in connections:
                connections[topic] = writer.add_connection(topic, msgtype, typestore=m.store)
            writer.write(connections[topic], nanoseconds(stamp), m.store.serialize_ros1(msg, msgtype))


def main():
    recording, out = Path(sys.argv[1]), Path(sys.argv[2])
    out.mkdir(parents=True, exist_ok=True)
    mount, scans = read_recording(recording)
    write_ros2(out / "lap_ros2", lambda m: lap_messages(m, mount, scans), compress=True)
    write_ros1(out / "lap.bag", lambda m: lap_messages(m, mount, scans))
    write_ros2(out / "layouts", lambda m: layout_messages(m, scans), compress=False)
    write_ros1(out / "layouts.bag", lambda m: layout_messages(m, scans))


if __name__ == "__main__":
    main()
