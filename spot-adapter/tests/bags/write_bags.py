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
  own clouds;
- `unlinked/unlinked.mcap` and `unlinked.bag`: the first clouds in frame `lidar` beside an
  unrelated `nav_msgs/Odometry` topic with an empty child frame (a 2D simulator's ground truth),
  an IMU in a frame no transform joins, /tf between other frames and no /tf_static (see
  `unlinked_messages`);
- `gyro/gyro.mcap` and `gyro.bag`, `gyro_bad/gyro_bad.mcap` and `gyro_bad.bag`: small clouds at
  10 Hz and a 200 Hz gyro in a frame rotated against the body, from a known rotation trajectory
  (`Turn`), the second with a non-finite rate, an out-of-order stamp and a 0.7 s gap;
  `gyro_truth.txt` holds the body's orientation at every cloud's stamp (`stamp qx qy qz qw`),
  `gyro_frames.txt` the mountings (`base_T_imu` and `base_T_lidar` as `tx ty tz qx qy qz qw`).

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

    def odometry(self, stamp, values, frame="odom", child="base_link"):
        t = self.t
        zero = t["geometry_msgs/msg/Vector3"](x=0.0, y=0.0, z=0.0)
        return t["nav_msgs/msg/Odometry"](
            header=self.header(stamp, frame),
            child_frame_id=child,
            pose=t["geometry_msgs/msg/PoseWithCovariance"](pose=self.pose(values), covariance=np.zeros(36)),
            twist=t["geometry_msgs/msg/TwistWithCovariance"](
                twist=t["geometry_msgs/msg/Twist"](linear=zero, angular=zero), covariance=np.zeros(36)
            ),
        )

    def tf(self, transforms):
        return self.t["tf2_msgs/msg/TFMessage"](transforms=transforms)

    def imu(self, stamp, frame="base_link", rate=(0.0, 0.0, 0.1)):
        t = self.t
        return t["sensor_msgs/msg/Imu"](
            header=self.header(stamp, frame),
            orientation=t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
            orientation_covariance=np.zeros(9),
            angular_velocity=t["geometry_msgs/msg/Vector3"](x=rate[0], y=rate[1], z=rate[2]),
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


UNLINKED_SCANS = 5


def unlinked_messages(m, scans):
    """The first scans in frame `lidar` beside frames that do not reach it: (topic, type, stamp,
    message). As a public bag of Luminar scans beside a 2D simulator's ground truth: its odometry
    has the empty child frame, /tf joins only the simulator's frames, and there is no /tf_static."""
    for stamp, pose, points in scans[:UNLINKED_SCANS]:
        stamp += EPOCH
        for k in range(4):
            # 40 Hz ground truth up to each cloud.
            t = stamp - 0.075 + 0.025 * k
            yield "/sim/ground_truth", "nav_msgs/msg/Odometry", t, m.odometry(t, pose[1:], frame="map", child="")
            yield "/imu", "sensor_msgs/msg/Imu", t, m.imu(t, frame="imu_link")
        yield "/tf", "tf2_msgs/msg/TFMessage", stamp, m.tf([m.transform(stamp, "world", "robot2d", pose[1:])])
        yield "/luminar/points", "sensor_msgs/msg/PointCloud2", stamp, m.cloud(stamp, "lidar", lap_columns(points))


def rot_x(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def rot_y(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rot_z(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def quaternion(r):
    """[qx, qy, qz, qw] of a rotation matrix (Shepperd's method)."""
    tr = np.trace(r)
    if tr > 0:
        s = 2.0 * np.sqrt(tr + 1.0)
        q = [(r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s, s / 4]
    else:
        i = int(np.argmax(np.diag(r)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * np.sqrt(1.0 + r[i, i] - r[j, j] - r[k, k])
        q = [0.0] * 4
        q[i] = s / 4
        q[j] = (r[j, i] + r[i, j]) / s
        q[k] = (r[k, i] + r[i, k]) / s
        q[3] = (r[k, j] - r[j, k]) / s
    return [float(v) for v in q]


class Turn:
    """A body turning on a known trajectory: world_R_body = Rz(yaw) Ry(pitch) Rx(roll) with
    smooth angles of time (seconds since the start), and its angular velocity in the body frame
    from the ZYX Euler kinematics, checked here against finite differences."""

    def angles(self, t):
        yaw = 0.8 * t + 0.3 * np.sin(1.7 * t)
        pitch = 0.15 * np.sin(2.3 * t)
        roll = 0.1 * np.sin(3.1 * t + 0.5)
        rates = (0.8 + 0.51 * np.cos(1.7 * t), 0.345 * np.cos(2.3 * t), 0.31 * np.cos(3.1 * t + 0.5))
        return (yaw, pitch, roll), rates

    def rotation(self, t):
        (yaw, pitch, roll), _ = self.angles(t)
        return rot_z(yaw) @ rot_y(pitch) @ rot_x(roll)

    def body_rate(self, t):
        (_, pitch, roll), (dyaw, dpitch, droll) = self.angles(t)
        return np.array([
            droll - dyaw * np.sin(pitch),
            dpitch * np.cos(roll) + dyaw * np.cos(pitch) * np.sin(roll),
            -dpitch * np.sin(roll) + dyaw * np.cos(pitch) * np.cos(roll),
        ])

    def check(self):
        h = 1e-6
        for t in np.linspace(0.0, 4.0, 17):
            d = self.rotation(t).T @ self.rotation(t + h)
            numeric = np.array([d[2, 1] - d[1, 2], d[0, 2] - d[2, 0], d[1, 0] - d[0, 1]]) / (2 * h)
            assert np.allclose(numeric, self.body_rate(t + h / 2), atol=1e-6), (t, numeric)
        for r in (self.rotation(1.3), rot_z(np.pi / 2) @ rot_x(np.pi), rot_y(np.pi)):
            x, y, z, w = quaternion(r)
            back = np.array([
                [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
            ])
            assert np.allclose(back, r, atol=1e-12), r


GYRO_START = EPOCH
GYRO_CLOUDS = 40
GYRO_RATE = 200.0
# The IMU upside down and turned a quarter: base_T_imu; the LiDAR on top, turned 30 degrees.
BASE_T_IMU = [0.12, -0.03, 0.21] + quaternion(rot_z(np.pi / 2) @ rot_x(np.pi))
BASE_T_LIDAR = [0.0, 0.0, 0.45] + quaternion(rot_z(np.radians(-30.0)))
GYRO_GAP = (2.0, 2.7)


def gyro_cloud(stamp, m):
    a = np.linspace(0.0, 2 * np.pi, 64, endpoint=False)
    columns = [("x", 5 * np.cos(a), "f4"), ("y", 5 * np.sin(a), "f4"), ("z", np.full(64, 0.3), "f4")]
    return m.cloud(stamp, "lidar", columns)


def cloud_stamps():
    return [GYRO_START + 0.0123 + 0.1 * k for k in range(GYRO_CLOUDS)]


def gyro_messages(m, turn, bad):
    """(topic, type, stamp, message) of the turn: clouds at 10 Hz, the odometry (odom ->
    base_link) at 50 Hz, the gyro at 200 Hz in `imu_link`. With `bad`: reading 100 has a NaN
    rate, reading 200 a stamp before reading 199's, and none lies within GYRO_GAP."""
    r_bi = rot_z(np.pi / 2) @ rot_x(np.pi)
    yield "/tf_static", "tf2_msgs/msg/TFMessage", GYRO_START, m.tf([
        m.transform(GYRO_START, "base_link", "imu_link", BASE_T_IMU),
        m.transform(GYRO_START, "base_link", "lidar", BASE_T_LIDAR),
    ])
    events = []
    for j in range(int(4.2 * GYRO_RATE)):
        t = j / GYRO_RATE - 0.05
        if bad and GYRO_GAP[0] < t < GYRO_GAP[1]:
            continue
        rate = r_bi.T @ turn.body_rate(t)
        stamp = GYRO_START + t
        if bad and j == 100:
            rate = [float("nan"), rate[1], rate[2]]
        if bad and j == 200:
            stamp -= 1.5 / GYRO_RATE
        events.append((GYRO_START + t, 0, "/imu", "sensor_msgs/msg/Imu",
                       m.imu(stamp, frame="imu_link", rate=[float(v) for v in rate])))
    for j in range(int(4.2 * 50)):
        t = j / 50 - 0.05
        pose = [0.5 * t, 0.0, 0.0] + quaternion(turn.rotation(t))
        events.append((GYRO_START + t, 1, "/odom", "nav_msgs/msg/Odometry", m.odometry(GYRO_START + t, pose)))
    for stamp in cloud_stamps():
        events.append((stamp, 2, "/points", "sensor_msgs/msg/PointCloud2", gyro_cloud(stamp, m)))
    events.sort(key=lambda e: (e[0], e[1]))
    for stamp, _, topic, msgtype, msg in events:
        yield topic, msgtype, stamp, msg


def write_gyro_truth(out, turn):
    lines = [" ".join(repr(v) for v in [s] + quaternion(turn.rotation(s - GYRO_START))) for s in cloud_stamps()]
    (out / "gyro_truth.txt").write_text("\n".join(lines) + "\n")
    frames = [" ".join(["base_T_imu"] + [repr(v) for v in BASE_T_IMU]),
              " ".join(["base_T_lidar"] + [repr(v) for v in BASE_T_LIDAR])]
    (out / "gyro_frames.txt").write_text("\n".join(frames) + "\n")


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
    write_ros2(out / "unlinked", lambda m: unlinked_messages(m, scans), compress=False)
    write_ros1(out / "unlinked.bag", lambda m: unlinked_messages(m, scans))
    turn = Turn()
    turn.check()
    write_gyro_truth(out, turn)
    for name, bad in (("gyro", False), ("gyro_bad", True)):
        write_ros2(out / name, lambda m: gyro_messages(m, turn, bad), compress=False)
        write_ros1(out / f"{name}.bag", lambda m: gyro_messages(m, turn, bad))


if __name__ == "__main__":
    main()
