"""A fake Spot on loopback, built on the official bosdyn-api servicers, for spot-nav's wire tests.

It serves auth, directory, robot-id, time-sync, lease, robot-state, point-cloud, local-grid and
robot-command over TLS with a CA it makes at start-up, on one port: every request is decoded by
the official generated classes and logged as one JSON line (method, :authority, authorization,
the request as a dict). The robot's clock runs `--clock-offset` seconds ahead of the host's, the
body moves by the velocity commands it takes, and control lines on stdin inject faults.

Power and posture: the motors start on and standing (`--motors off`: off and sitting); a
PowerCommand powers them on in POWER_ON_SECONDS, a stand or sit takes POSTURE_SECONDS, a safe power
off sits and cuts power at once; motion with the motors off is refused STATUS_NOT_POWERED_ON.
The robot state lists one hardware E-stop, released (`--estop asserted`, or `--estop none`: no
endpoint), and the faults `--behavior-fault` (CAUSE_FALL, clearable) and `--system-fault NAME`
ask for. `--frozen` takes every command and never moves; `--refuse-motion` refuses every
velocity and trajectory command (STATUS_BEHAVIOR_FAULT); `--stale-cloud` serves the same scan
(one acquisition time) again and again. `--world room` serves, instead of the known helix, a
walled room with a floor and two pillars fixed in odom, seen from the body's current pose: the
clouds of a robot that moves, for mapping and navigating. `--lease-held` starts with the body
lease held by another client (the tablet): AcquireLease answers STATUS_RESOURCE_ALREADY_CLAIMED,
TakeLease takes it. `--odom-scale K` makes the odometry (odom_T_body in the frame tree) count
every motion K times while the clouds show the true pose. `--power-on-seconds S` makes a power-on take S seconds, `--posture-seconds S` a stand or a sit. The E-stop service
has one configuration with a `PDB_rooted` role: an endpoint registered there checks in with the
complement of the last challenge, and the robot state lists it as a software E-stop, released
while its last check-in was ESTOP_LEVEL_NONE within its timeout.

Start-up prints one line `READY <port>` on stdout once the server listens; `<dir>/ca.pem` then
holds the CA. Control lines (answered `OK <line>`): take-lease, stall-time-sync, malformed-cloud,
pose (answered `OK pose <x> <y> <yaw> <x> <y> <yaw>`, the body's true pose in odom, then
the odometry's), drop (stop serving and exit); a simulator feeds scans with `scan <file> <odom_T_body>
<body_T_lidar>` and reads the command that answered with `wait-command <seconds>`.
"""

import argparse
import datetime
import json
import math
import os
import secrets
import struct
import sys
import threading
import time
from concurrent import futures

import grpc
from cryptography import x509
from cryptography.hazmat.primitives import hashes, serialization
from cryptography.hazmat.primitives.asymmetric import ec
from cryptography.x509.oid import NameOID
from google.protobuf import json_format

from bosdyn.api import (basic_command_pb2, power_pb2, power_service_pb2_grpc, auth_pb2, auth_service_pb2_grpc, directory_pb2, directory_service_pb2_grpc,
                        geometry_pb2, lease_pb2, lease_service_pb2_grpc, local_grid_pb2,
                        local_grid_service_pb2_grpc, point_cloud_pb2, point_cloud_service_pb2_grpc,
                        robot_command_pb2, robot_command_service_pb2_grpc, robot_id_pb2,
                        robot_id_service_pb2_grpc, robot_state_pb2, robot_state_service_pb2_grpc,
                        header_pb2, time_sync_pb2, time_sync_service_pb2_grpc, estop_pb2,
                        estop_service_pb2_grpc)
from bosdyn.api.spot import robot_command_pb2 as spot_command_pb2

CLOCK_ID = "fake-spot-clock"
# The service name -> (type, authority) the fake's directory lists.
SERVICES = {
    "auth": ("bosdyn.api.AuthService", "auth.spot.robot"),
    "directory": ("bosdyn.api.DirectoryService", "api.spot.robot"),
    "robot-id": ("bosdyn.api.RobotIdService", "id.spot.robot"),
    "time-sync": ("bosdyn.api.TimeSyncService", "time-sync.spot.robot"),
    "lease": ("bosdyn.api.LeaseService", "lease.spot.robot"),
    "robot-state": ("bosdyn.api.RobotStateService", "robot-state.spot.robot"),
    "robot-command": ("bosdyn.api.RobotCommandService", "command.spot.robot"),
    "power": ("bosdyn.api.PowerService", "power.spot.robot"),
    "estop": ("bosdyn.api.EstopService", "estop.spot.robot"),
    "velodyne-point-cloud": ("bosdyn.api.PointCloudService", "velodyne.spot.robot"),
    "local-grid-service": ("bosdyn.api.LocalGridService", "local-grid.spot.robot"),
}
AUTHORITIES = sorted({a for _, a in SERVICES.values()})
# The LiDAR's mounting on the body (x, y, z), level.
BODY_T_VELODYNE = (-0.05, 0.0, 0.30)
# The vision frame's pose in odom (x, y, yaw): a fixed offset, so odom and vision differ.
ODOM_T_VISION = (0.5, -0.25, 0.1)


def known_points(n=120):
    """The cloud the fake serves: n points on a known helix (the tests recompute it)."""
    return [(0.05 * i, -0.02 * i, 0.01 * (i % 7)) for i in range(n)]


def room_points():
    """The `--world room` points in odom: walls x -2..5, y -1..5.5 from the floor (z -0.5) to
    z 1.5 every 0.1 m, the floor every 0.25 m, and two 0.4 m pillars away from the middle."""
    points = []
    x0, x1, y0, y1 = -2.0, 5.0, -1.0, 5.5
    heights = [-0.5 + 0.1 * k for k in range(21)]
    nx, ny = int(round((x1 - x0) / 0.1)), int(round((y1 - y0) / 0.1))
    for z in heights:
        for i in range(nx + 1):
            x = x0 + 0.1 * i
            points += [(x, y0, z), (x, y1, z)]
        for j in range(1, ny):
            y = y0 + 0.1 * j
            points += [(x0, y, z), (x1, y, z)]
        for cx, cy in ((3.8, 4.3), (-1.0, -0.2)):
            for k in range(5):
                d = -0.2 + 0.1 * k
                points += [(cx + d, cy - 0.2, z), (cx + d, cy + 0.2, z),
                           (cx - 0.2, cy + d, z), (cx + 0.2, cy + d, z)]
    for i in range(int((x1 - x0) / 0.25) + 1):
        for j in range(int((y1 - y0) / 0.25) + 1):
            points.append((x0 + 0.25 * i, y0 + 0.25 * j, -0.5))
    return points


def grid_value(x, y):
    """Cell (x, y) of the fake's local grids, an integer the tests recompute."""
    return (3 * x + 5 * y) % 11 if (x // 4 + y // 3) % 2 == 0 else 0


def make_certificates(directory):
    """A test CA and a server certificate for every authority, both written as PEM files."""
    now = datetime.datetime.now(datetime.timezone.utc)
    ca_key = ec.generate_private_key(ec.SECP256R1())
    ca_name = x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, "fake spot test CA")])
    ca = (x509.CertificateBuilder().subject_name(ca_name).issuer_name(ca_name)
          .public_key(ca_key.public_key()).serial_number(x509.random_serial_number())
          .not_valid_before(now - datetime.timedelta(hours=1))
          .not_valid_after(now + datetime.timedelta(days=2))
          .add_extension(x509.BasicConstraints(ca=True, path_length=None), critical=True)
          .add_extension(x509.KeyUsage(digital_signature=True, content_commitment=False,
                                       key_encipherment=False, data_encipherment=False,
                                       key_agreement=False, key_cert_sign=True, crl_sign=True,
                                       encipher_only=False, decipher_only=False), critical=True)
          .sign(ca_key, hashes.SHA256()))
    key = ec.generate_private_key(ec.SECP256R1())
    cert = (x509.CertificateBuilder()
            .subject_name(x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, "fake spot")]))
            .issuer_name(ca_name).public_key(key.public_key())
            .serial_number(x509.random_serial_number())
            .not_valid_before(now - datetime.timedelta(hours=1))
            .not_valid_after(now + datetime.timedelta(days=1))
            .add_extension(x509.SubjectAlternativeName([x509.DNSName(a) for a in AUTHORITIES]),
                           critical=False)
            .add_extension(x509.BasicConstraints(ca=False, path_length=None), critical=True)
            .sign(ca_key, hashes.SHA256()))
    pem = lambda c: c.public_bytes(serialization.Encoding.PEM)
    key_pem = key.private_bytes(serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8,
                                serialization.NoEncryption())
    with open(os.path.join(directory, "ca.pem.tmp"), "wb") as f:
        f.write(pem(ca))
    os.replace(os.path.join(directory, "ca.pem.tmp"), os.path.join(directory, "ca.pem"))
    return key_pem, pem(cert)


class Robot:
    """The fake robot's state: clock, tokens, lease, body pose and the fault switches."""

    def __init__(self, args):
        self.args = args
        self.lock = threading.Lock()
        self.log = open(os.path.join(args.dir, "requests.jsonl"), "a", buffering=1)
        self.tokens = {}  # token -> host expiry (monotonic seconds)
        self.lease_epoch = secrets.token_hex(4)
        self.lease_sequence = 0
        self.lease_owner = None
        self.time_sync_rounds = {}  # client name -> [(rtt, skew)]
        self.time_sync_stalled = False
        self.malformed_cloud = False
        self.pose = [1.0, 2.0, 0.3]  # the body's true pose in odom: x, y, yaw
        # What the odometry says (odom_T_body in the frame tree): the true pose unless
        # --odom-scale makes it over- or under-count every motion.
        self.odom_pose = list(self.pose)
        self.velocity = (0.0, 0.0, 0.0)  # body frame vx, vy, wz
        self.velocity_end = 0.0  # robot-clock seconds
        self.command_id = 0
        self.last_step = time.time()
        # Bridge mode: scans and odometry fed on stdin by a simulator, commands handed back.
        self.bridge_scan = None  # (data bytes, acquisition robot time, odom_T_body, body_T_lidar)
        self.command_arrived = threading.Condition(self.lock)
        self.last_command = None  # (kind, vx, vy, wz) of the latest accepted command
        self.motors_on = args.motors == "on"
        self.powering_on_until = None  # host time the motors will be on
        self.standing = self.motors_on
        self.posture_commands = {}  # command id -> (kind, host time it completes)
        self.started = self.now()
        # Software E-stop: the registered endpoint, its challenge, level and last check-in.
        self.estop_endpoint = None
        self.estop_challenge = None
        self.estop_level = estop_pb2.ESTOP_LEVEL_CUT
        self.estop_checked_in = 0.0  # host time

    def now(self):
        """Robot clock, seconds."""
        return time.time() + self.args.clock_offset

    def stamp(self, seconds=None):
        ts = header_pb2.RequestHeader().request_timestamp
        ts.FromNanoseconds(int(round((self.now() if seconds is None else seconds) * 1e9)))
        return ts

    def record(self, method, context, request, **decoded):
        """Log a request as the official classes decode it; `decoded` adds derived numbers."""
        metadata = dict(context.invocation_metadata())
        entry = {"method": method, "authority": authority(context),
                 "authorization": metadata.get("authorization"), "robot_time": self.now(),
                 "request": json_format.MessageToDict(request, preserving_proto_field_name=True),
                 "decoded": decoded}
        with self.lock:
            self.log.write(json.dumps(entry) + "\n")

    def header(self, request, received):
        h = header_pb2.ResponseHeader()
        h.request_header.CopyFrom(request.header)
        h.request_received_timestamp.CopyFrom(self.stamp(received))
        h.response_timestamp.CopyFrom(self.stamp())
        h.error.code = header_pb2.CommonError.CODE_OK
        return h

    def power(self):
        """The motors' state, finishing a power-on in progress."""
        if self.powering_on_until is not None and time.time() >= self.powering_on_until:
            self.powering_on_until = None
            self.motors_on = True
        if self.motors_on:
            return robot_state_pb2.PowerState.MOTOR_POWER_STATE_ON
        if self.powering_on_until is not None:
            return robot_state_pb2.PowerState.MOTOR_POWER_STATE_POWERING_ON
        return robot_state_pb2.PowerState.MOTOR_POWER_STATE_OFF

    def step(self):
        """Integrate the body velocity in force (it ends at its end time)."""
        with self.lock:
            t = time.time()
            dt, self.last_step = t - self.last_step, t
            if self.now() > self.velocity_end or self.args.frozen:
                self.velocity = (0.0, 0.0, 0.0)
            vx, vy, wz = self.velocity
            x, y, yaw = self.pose
            c, s = math.cos(yaw), math.sin(yaw)
            self.pose = [x + (c * vx - s * vy) * dt, y + (s * vx + c * vy) * dt, yaw + wz * dt]
            k = self.args.odom_scale
            x, y, yaw = self.odom_pose
            c, s = math.cos(yaw), math.sin(yaw)
            self.odom_pose = [x + (c * vx - s * vy) * dt * k, y + (s * vx + c * vy) * dt * k,
                              yaw + wz * dt * k]

    def snapshot(self):
        """Frame tree rooted at body, as Spot sends it: odom, vision and the LiDAR below it."""
        snap = geometry_pb2.FrameTreeSnapshot()
        with self.lock:
            x, y, yaw = self.odom_pose
            bridged = self.bridge_scan
        if bridged is not None:
            # Rooted at odom: the simulator's odometry and LiDAR mounting as given.
            _, _, odom_t_body, body_t_lidar = bridged
            add_edge_3d(snap, "body", "odom", odom_t_body)
            add_edge_3d(snap, "velodyne", "body", body_t_lidar)
            add_edge(snap, "odom", "", (0.0, 0.0, 0.0), 0.0)
            return snap
        # body_T_odom = inverse(odom_T_body)
        c, s = math.cos(yaw), math.sin(yaw)
        add_edge(snap, "odom", "body", (-(c * x + s * y), s * x - c * y, 0.0), -yaw)
        vx, vy, vyaw = ODOM_T_VISION
        add_edge(snap, "vision", "odom", (vx, vy, 0.0), vyaw)
        add_edge(snap, "velodyne", "body", BODY_T_VELODYNE, 0.0)
        add_edge(snap, "body", "", (0.0, 0.0, 0.0), 0.0)
        add_edge(snap, "gpe", "odom", (0.0, 0.0, -0.5), 0.0)
        return snap


def authority(context):
    """The call's HTTP/2 `:authority`: grpcio keeps it only in the call's details (no public API)."""
    host = getattr(getattr(getattr(context, "_rpc_event", None), "call_details", None), "host", None)
    return host.decode() if isinstance(host, bytes) else host


def add_edge(snap, child, parent, xyz, yaw):
    edge = snap.child_to_parent_edge_map[child]
    edge.parent_frame_name = parent
    if parent:
        edge.parent_tform_child.position.x, edge.parent_tform_child.position.y, \
            edge.parent_tform_child.position.z = xyz
        q = edge.parent_tform_child.rotation
        q.w, q.x, q.y, q.z = math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)


def add_edge_3d(snap, child, parent, pose):
    """`pose` = (x, y, z, qw, qx, qy, qz) of child in parent."""
    edge = snap.child_to_parent_edge_map[child]
    edge.parent_frame_name = parent
    p, q = edge.parent_tform_child.position, edge.parent_tform_child.rotation
    p.x, p.y, p.z, q.w, q.x, q.y, q.z = pose


def unauthenticated(message):
    def abort(request, context):
        context.abort(grpc.StatusCode.UNAUTHENTICATED, message)
    return grpc.unary_unary_rpc_method_handler(abort)


class TokenCheck(grpc.ServerInterceptor):
    """Every call but GetAuthToken must carry `authorization: Bearer <live token>`."""

    def __init__(self, robot):
        self.robot = robot

    def intercept_service(self, continuation, details):
        if details.method == "/bosdyn.api.AuthService/GetAuthToken":
            return continuation(details)
        header = dict(details.invocation_metadata).get("authorization", "")
        token = header[len("Bearer "):] if header.startswith("Bearer ") else None
        expiry = self.robot.tokens.get(token)
        if expiry is None:
            return unauthenticated("no valid token")
        if time.monotonic() > expiry:
            return unauthenticated("token expired")
        return continuation(details)


class Auth(auth_service_pb2_grpc.AuthServiceServicer):
    def __init__(self, robot):
        self.r = robot

    def GetAuthToken(self, request, context):
        received = self.r.now()
        logged = auth_pb2.GetAuthTokenRequest()
        logged.CopyFrom(request)
        if logged.password:
            logged.password = "<given>"  # the log must not hold the password itself
        self.r.record("GetAuthToken", context, logged)
        response = auth_pb2.GetAuthTokenResponse()
        good_login = request.username == self.r.args.username and \
            request.password == self.r.args.password
        good_token = request.token and request.token in self.r.tokens and \
            time.monotonic() <= self.r.tokens[request.token]
        if good_login or good_token:
            token = secrets.token_hex(16)
            self.r.tokens[token] = time.monotonic() + self.r.args.token_lifetime
            response.status = auth_pb2.GetAuthTokenResponse.STATUS_OK
            response.token = token
        elif request.token:
            response.status = auth_pb2.GetAuthTokenResponse.STATUS_INVALID_TOKEN
        else:
            response.status = auth_pb2.GetAuthTokenResponse.STATUS_INVALID_LOGIN
        response.header.CopyFrom(self.r.header(request, received))
        return response


class Directory(directory_service_pb2_grpc.DirectoryServiceServicer):
    def __init__(self, robot):
        self.r = robot

    def entries(self):
        for name, (kind, authority) in SERVICES.items():
            yield directory_pb2.ServiceEntry(name=name, type=kind, authority=authority,
                                             user_token_required=name != "auth")

    def ListServiceEntries(self, request, context):
        received = self.r.now()
        self.r.record("ListServiceEntries", context, request)
        response = directory_pb2.ListServiceEntriesResponse(service_entries=list(self.entries()))
        response.header.CopyFrom(self.r.header(request, received))
        return response

    def GetServiceEntry(self, request, context):
        received = self.r.now()
        self.r.record("GetServiceEntry", context, request)
        response = directory_pb2.GetServiceEntryResponse()
        for entry in self.entries():
            if entry.name == request.service_name:
                response.service_entry.CopyFrom(entry)
                response.status = directory_pb2.GetServiceEntryResponse.STATUS_OK
                break
        else:
            response.status = directory_pb2.GetServiceEntryResponse.STATUS_NONEXISTENT_SERVICE
        response.header.CopyFrom(self.r.header(request, received))
        return response


class RobotIdServicer(robot_id_service_pb2_grpc.RobotIdServiceServicer):
    def __init__(self, robot):
        self.r = robot

    def GetRobotId(self, request, context):
        received = self.r.now()
        self.r.record("GetRobotId", context, request)
        response = robot_id_pb2.RobotIdResponse()
        response.robot_id.serial_number = "fake-0001"
        response.robot_id.species = "spot"
        response.robot_id.version = "5.2.0"
        response.robot_id.nickname = "loopback"
        response.header.CopyFrom(self.r.header(request, received))
        return response


def seconds(ts):
    return ts.seconds + ts.nanos * 1e-9


class TimeSync(time_sync_service_pb2_grpc.TimeSyncServiceServicer):
    """Estimates the client's clock skew from its round trips, as a robot does."""

    ROUNDS_NEEDED = 3

    def __init__(self, robot):
        self.r = robot

    def TimeSyncUpdate(self, request, context):
        received = self.r.now()
        self.r.record("TimeSyncUpdate", context, request)
        response = time_sync_pb2.TimeSyncUpdateResponse(clock_identifier=CLOCK_ID)
        client = request.header.client_name
        rounds = self.r.time_sync_rounds.setdefault(client, [])
        if request.clock_identifier and request.clock_identifier != CLOCK_ID:
            rounds.clear()
        trip = request.previous_round_trip
        if trip.HasField("client_tx") and trip.HasField("client_rx"):
            ctx, srx, stx, crx = (seconds(trip.client_tx), seconds(trip.server_rx),
                                  seconds(trip.server_tx), seconds(trip.client_rx))
            rtt = (crx - ctx) - (stx - srx)
            skew = ((srx - ctx) + (stx - crx)) / 2.0
            rounds.append((rtt, skew))
            response.previous_estimate.round_trip_time.FromNanoseconds(int(rtt * 1e9))
            response.previous_estimate.clock_skew.FromNanoseconds(int(skew * 1e9))
        if self.r.time_sync_stalled:
            response.state.status = time_sync_pb2.TimeSyncState.STATUS_SERVICE_NOT_READY
        elif len(rounds) < self.ROUNDS_NEEDED:
            response.state.status = time_sync_pb2.TimeSyncState.STATUS_MORE_SAMPLES_NEEDED
        else:
            rtt, skew = min(rounds[-10:])
            response.state.status = time_sync_pb2.TimeSyncState.STATUS_OK
            response.state.best_estimate.round_trip_time.FromNanoseconds(int(rtt * 1e9))
            response.state.best_estimate.clock_skew.FromNanoseconds(int(skew * 1e9))
            response.state.measurement_time.CopyFrom(self.r.stamp())
        response.header.CopyFrom(self.r.header(request, received))
        return response


class Leases(lease_service_pb2_grpc.LeaseServiceServicer):
    """One resource, `body`; a new owner (acquire or take) bumps the sequence."""

    def __init__(self, robot):
        self.r = robot

    def current(self):
        return lease_pb2.Lease(resource="body", epoch=self.r.lease_epoch,
                               sequence=[self.r.lease_sequence],
                               client_names=[self.r.lease_owner or ""])

    def grant(self, owner):
        self.r.lease_sequence += 1
        self.r.lease_owner = owner
        return self.current()

    def check(self, lease):
        """A LeaseUseResult for using `lease` (a sublease of the current one is fine)."""
        result = lease_pb2.LeaseUseResult(attempted_lease=lease)
        result.latest_known_lease.CopyFrom(self.current())
        if self.r.lease_owner:
            result.owner.client_name = self.r.lease_owner
        if lease.resource != "body":
            result.status = lease_pb2.LeaseUseResult.STATUS_INVALID_LEASE
        elif lease.epoch != self.r.lease_epoch:
            result.status = lease_pb2.LeaseUseResult.STATUS_WRONG_EPOCH
        elif not lease.sequence or lease.sequence[0] < self.r.lease_sequence:
            result.status = lease_pb2.LeaseUseResult.STATUS_OLDER
        elif lease.sequence[0] > self.r.lease_sequence or self.r.lease_owner is None:
            result.status = lease_pb2.LeaseUseResult.STATUS_INVALID_LEASE
        else:
            result.status = lease_pb2.LeaseUseResult.STATUS_OK
        return result

    def AcquireLease(self, request, context):
        received = self.r.now()
        self.r.record("AcquireLease", context, request)
        response = lease_pb2.AcquireLeaseResponse()
        with self.r.lock:
            if request.resource != "body":
                response.status = lease_pb2.AcquireLeaseResponse.STATUS_INVALID_RESOURCE
            elif self.r.lease_owner is not None:
                response.status = lease_pb2.AcquireLeaseResponse.STATUS_RESOURCE_ALREADY_CLAIMED
                response.lease_owner.client_name = self.r.lease_owner
            else:
                response.status = lease_pb2.AcquireLeaseResponse.STATUS_OK
                response.lease.CopyFrom(self.grant(request.header.client_name))
                response.lease_owner.client_name = request.header.client_name
        response.header.CopyFrom(self.r.header(request, received))
        return response

    def TakeLease(self, request, context):
        received = self.r.now()
        self.r.record("TakeLease", context, request)
        response = lease_pb2.TakeLeaseResponse()
        with self.r.lock:
            response.status = lease_pb2.TakeLeaseResponse.STATUS_OK
            response.lease.CopyFrom(self.grant(request.header.client_name))
            response.lease_owner.client_name = request.header.client_name
        response.header.CopyFrom(self.r.header(request, received))
        return response

    def RetainLease(self, request, context):
        received = self.r.now()
        self.r.record("RetainLease", context, request)
        response = lease_pb2.RetainLeaseResponse()
        with self.r.lock:
            response.lease_use_result.CopyFrom(self.check(request.lease))
        response.header.CopyFrom(self.r.header(request, received))
        return response

    def ReturnLease(self, request, context):
        received = self.r.now()
        self.r.record("ReturnLease", context, request)
        response = lease_pb2.ReturnLeaseResponse()
        with self.r.lock:
            if self.check(request.lease).status == lease_pb2.LeaseUseResult.STATUS_OK:
                self.r.lease_owner = None
                response.status = lease_pb2.ReturnLeaseResponse.STATUS_OK
            else:
                response.status = lease_pb2.ReturnLeaseResponse.STATUS_NOT_ACTIVE_LEASE
        response.header.CopyFrom(self.r.header(request, received))
        return response

    def ListLeases(self, request, context):
        received = self.r.now()
        self.r.record("ListLeases", context, request)
        response = lease_pb2.ListLeasesResponse()
        with self.r.lock:
            if self.r.lease_owner is not None:
                resource = response.resources.add(resource="body")
                resource.lease.CopyFrom(self.current())
                resource.lease_owner.client_name = self.r.lease_owner
        response.header.CopyFrom(self.r.header(request, received))
        return response


class RobotStateServicer(robot_state_service_pb2_grpc.RobotStateServiceServicer):
    def __init__(self, robot):
        self.r = robot

    def GetRobotState(self, request, context):
        received = self.r.now()
        self.r.record("GetRobotState", context, request)
        self.r.step()
        response = robot_state_pb2.RobotStateResponse()
        state = response.robot_state
        state.power_state.motor_power_state = self.r.power()
        if self.r.args.estop != "none":
            estop = state.estop_states.add(name="hardware_estop",
                                           type=robot_state_pb2.EStopState.TYPE_HARDWARE)
            estop.state = (robot_state_pb2.EStopState.STATE_ESTOPPED
                           if self.r.args.estop == "asserted"
                           else robot_state_pb2.EStopState.STATE_NOT_ESTOPPED)
        with self.r.lock:
            endpoint = self.r.estop_endpoint
            released = (endpoint is not None
                        and self.r.estop_level == estop_pb2.ESTOP_LEVEL_NONE
                        and time.time() - self.r.estop_checked_in
                        < endpoint.timeout.seconds + endpoint.timeout.nanos * 1e-9)
        if endpoint is not None:
            software = state.estop_states.add(name=endpoint.name,
                                              type=robot_state_pb2.EStopState.TYPE_SOFTWARE)
            software.state = (robot_state_pb2.EStopState.STATE_NOT_ESTOPPED if released
                              else robot_state_pb2.EStopState.STATE_ESTOPPED)
        if self.r.args.behavior_fault:
            state.behavior_fault_state.faults.add(
                behavior_fault_id=7, cause=robot_state_pb2.BehaviorFault.CAUSE_FALL,
                status=robot_state_pb2.BehaviorFault.STATUS_CLEARABLE)
        if self.r.args.system_fault:
            state.system_fault_state.faults.add(
                name=self.r.args.system_fault, code=42,
                severity=robot_state_pb2.SystemFault.SEVERITY_CRITICAL)
        kinematic = response.robot_state.kinematic_state
        kinematic.acquisition_timestamp.CopyFrom(self.r.stamp())
        kinematic.transforms_snapshot.CopyFrom(self.r.snapshot())
        response.header.CopyFrom(self.r.header(request, received))
        return response


class PointClouds(point_cloud_service_pb2_grpc.PointCloudServiceServicer):
    """Serves `velodyne-point-cloud`: the known points (or the room), a new scan every 0.1 s."""

    def __init__(self, robot):
        self.r = robot
        self.room = None

    def GetPointCloud(self, request, context):
        received = self.r.now()
        self.r.record("GetPointCloud", context, request)
        self.r.step()
        response = point_cloud_pb2.GetPointCloudResponse()
        for wanted in request.point_cloud_requests:
            reply = response.point_cloud_responses.add()
            if wanted.point_cloud_source_name != "velodyne-point-cloud":
                reply.status = point_cloud_pb2.PointCloudResponse.STATUS_UNKNOWN_SOURCE
                continue
            reply.status = point_cloud_pb2.PointCloudResponse.STATUS_OK
            cloud = reply.point_cloud
            cloud.source.name = "velodyne-point-cloud"
            cloud.source.frame_name_sensor = "velodyne"
            cloud.encoding = point_cloud_pb2.PointCloud.ENCODING_XYZ_32F
            cloud.source.transforms_snapshot.CopyFrom(self.r.snapshot())
            with self.r.lock:
                bridged = self.r.bridge_scan
            if bridged is not None:
                data, scan_time = bridged[0], bridged[1]
                count = len(data) // 12
            elif self.r.args.world == "room":
                data, count = self.room_scan()
                scan_time = math.floor(self.r.now() * 10.0) / 10.0
            else:
                points = known_points()
                data = b"".join(struct.pack("<3f", *p) for p in points)
                scan_time = math.floor((self.r.started if self.r.args.stale_cloud
                                        else self.r.now()) * 10.0) / 10.0
                count = len(points)
            cloud.source.acquisition_time.CopyFrom(self.r.stamp(scan_time))
            cloud.num_points = count + (1 if self.r.malformed_cloud else 0)
            cloud.data = data
        response.header.CopyFrom(self.r.header(request, received))
        return response


    def room_scan(self):
        """The room's points in the LiDAR frame at the body's current pose."""
        with self.r.lock:
            x, y, yaw = self.r.pose
        if self.room is None:
            self.room = room_points()
        c, s = math.cos(yaw), math.sin(yaw)
        bx, by, bz = BODY_T_VELODYNE
        lx, ly = x + c * bx - s * by, y + s * bx + c * by
        out = []
        for px, py, pz in self.room:
            dx, dy = px - lx, py - ly
            out.append(struct.pack("<3f", c * dx + s * dy, -s * dx + c * dy, pz - bz))
        return b"".join(out), len(out)


class LocalGrids(local_grid_service_pb2_grpc.LocalGridServiceServicer):
    """`terrain`: INT16 cells sent RAW (scale 0.01, offset -0.05); `no_step`: UINT8 cells RLE."""

    NX, NY, CELL = 16, 12, 0.03

    def __init__(self, robot):
        self.r = robot

    def GetLocalGrids(self, request, context):
        received = self.r.now()
        self.r.record("GetLocalGrids", context, request)
        response = local_grid_pb2.GetLocalGridsResponse()
        values = [grid_value(x, y) for y in range(self.NY) for x in range(self.NX)]
        for wanted in request.local_grid_requests:
            reply = response.local_grid_responses.add(local_grid_type_name=wanted.local_grid_type_name)
            grid = reply.local_grid
            grid.local_grid_type_name = wanted.local_grid_type_name
            grid.acquisition_time.CopyFrom(self.r.stamp())
            grid.transforms_snapshot.CopyFrom(self.r.snapshot())
            grid.frame_name_local_grid_data = "odom"
            grid.extent.cell_size = self.CELL
            grid.extent.num_cells_x, grid.extent.num_cells_y = self.NX, self.NY
            if wanted.local_grid_type_name == "terrain":
                grid.cell_format = local_grid_pb2.LocalGrid.CELL_FORMAT_INT16
                grid.encoding = local_grid_pb2.LocalGrid.ENCODING_RAW
                grid.cell_value_scale, grid.cell_value_offset = 0.01, -0.05
                grid.data = struct.pack("<%dh" % len(values), *values)
            elif wanted.local_grid_type_name == "no_step":
                grid.cell_format = local_grid_pb2.LocalGrid.CELL_FORMAT_UINT8
                grid.encoding = local_grid_pb2.LocalGrid.ENCODING_RLE
                runs = []
                for v in values:
                    if runs and runs[-1][0] == v:
                        runs[-1][1] += 1
                    else:
                        runs.append([v, 1])
                grid.data = bytes(v for v, _ in runs)
                grid.rle_counts.extend(n for _, n in runs)
            else:
                reply.status = local_grid_pb2.LocalGridResponse.STATUS_NO_SUCH_GRID
                reply.ClearField("local_grid")
                response.num_local_grid_errors += 1
                continue
            reply.status = local_grid_pb2.LocalGridResponse.STATUS_OK
        response.header.CopyFrom(self.r.header(request, received))
        return response


def command_times(command):
    """End time, reference time (robot clock seconds) and point times of a mobility command,
    and the velocity limit and stairs mode of its MobilityParams, as the official classes
    decode them."""
    mobility = command.synchronized_command.mobility_command
    kind = mobility.WhichOneof("command")
    out = {"kind": kind or command.WhichOneof("command")}
    if kind in ("se2_velocity_request", "se2_trajectory_request"):
        request = getattr(mobility, kind)
        out["end_time"] = seconds(request.end_time)
    if kind == "se2_trajectory_request":
        trajectory = mobility.se2_trajectory_request.trajectory
        out["reference_time"] = seconds(trajectory.reference_time)
        out["point_times"] = [p.time_since_reference.ToNanoseconds() * 1e-9 for p in trajectory.points]
    if mobility.params.type_url:
        params = spot_command_pb2.MobilityParams()
        if mobility.params.Unpack(params):
            limit = params.vel_limit.max_vel
            out["max_vel"] = [limit.linear.x, limit.linear.y, limit.angular]
            out["stairs_mode"] = spot_command_pb2.MobilityParams.StairsMode.Name(params.stairs_mode)
    return out


POWER_ON_SECONDS = 0.5
POSTURE_SECONDS = 0.3


class Estop(estop_service_pb2_grpc.EstopServiceServicer):
    """One configuration, `fake-estop-config`, with a `PDB_rooted` role to register into."""

    CONFIG_ID = "fake-estop-config"

    def __init__(self, robot):
        self.r = robot

    def config(self):
        config = estop_pb2.EstopConfig(unique_id=self.CONFIG_ID)
        endpoint = config.endpoints.add(role="PDB_rooted")
        if self.r.estop_endpoint is not None:
            endpoint.CopyFrom(self.r.estop_endpoint)
        return config

    def GetEstopConfig(self, request, context):
        received = self.r.now()
        self.r.record("GetEstopConfig", context, request)
        response = estop_pb2.GetEstopConfigResponse()
        response.request.CopyFrom(request)
        with self.r.lock:
            response.active_config.CopyFrom(self.config())
        response.header.CopyFrom(self.r.header(request, received))
        return response

    def RegisterEstopEndpoint(self, request, context):
        received = self.r.now()
        self.r.record("RegisterEstopEndpoint", context, request)
        response = estop_pb2.RegisterEstopEndpointResponse()
        response.request.CopyFrom(request)
        with self.r.lock:
            if request.target_config_id != self.CONFIG_ID:
                response.status = estop_pb2.RegisterEstopEndpointResponse.STATUS_CONFIG_MISMATCH
            elif request.target_endpoint.role != "PDB_rooted" or \
                    request.new_endpoint.role != "PDB_rooted":
                response.status = estop_pb2.RegisterEstopEndpointResponse.STATUS_ENDPOINT_MISMATCH
            else:
                endpoint = estop_pb2.EstopEndpoint()
                endpoint.CopyFrom(request.new_endpoint)
                endpoint.unique_id = secrets.token_hex(4)
                self.r.estop_endpoint = endpoint
                self.r.estop_challenge = None
                self.r.estop_level = estop_pb2.ESTOP_LEVEL_CUT
                response.new_endpoint.CopyFrom(endpoint)
                response.status = estop_pb2.RegisterEstopEndpointResponse.STATUS_SUCCESS
        response.header.CopyFrom(self.r.header(request, received))
        return response

    def EstopCheckIn(self, request, context):
        received = self.r.now()
        self.r.record("EstopCheckIn", context, request,
                      answered=(self.r.estop_challenge is not None and
                                request.challenge == self.r.estop_challenge and
                                request.response == (~self.r.estop_challenge) & (2**64 - 1)))
        response = estop_pb2.EstopCheckInResponse()
        response.request.CopyFrom(request)
        with self.r.lock:
            endpoint = self.r.estop_endpoint
            if endpoint is None or request.endpoint.unique_id != endpoint.unique_id:
                response.status = estop_pb2.EstopCheckInResponse.STATUS_ENDPOINT_UNKNOWN
            elif (self.r.estop_challenge is None or request.challenge != self.r.estop_challenge
                  or request.response != (~self.r.estop_challenge) & (2**64 - 1)):
                response.status = \
                    estop_pb2.EstopCheckInResponse.STATUS_INCORRECT_CHALLENGE_RESPONSE
            else:
                response.status = estop_pb2.EstopCheckInResponse.STATUS_OK
                self.r.estop_level = request.stop_level
                self.r.estop_checked_in = time.time()
            if endpoint is not None:
                self.r.estop_challenge = secrets.randbits(64)
                response.challenge = self.r.estop_challenge
        response.header.CopyFrom(self.r.header(request, received))
        return response


class Power(power_service_pb2_grpc.PowerServiceServicer):
    """Motor power on and off; refused while E-stopped."""

    def __init__(self, robot, leases):
        self.r = robot
        self.leases = leases
        self.command_id = 0

    def PowerCommand(self, request, context):
        received = self.r.now()
        self.r.record("PowerCommand", context, request)
        response = power_pb2.PowerCommandResponse()
        with self.r.lock:
            response.lease_use_result.CopyFrom(self.leases.check(request.lease))
            if response.lease_use_result.status != lease_pb2.LeaseUseResult.STATUS_OK:
                response.status = power_pb2.STATUS_UNKNOWN
            elif self.r.args.estop == "asserted":
                response.status = power_pb2.STATUS_ESTOPPED
            elif request.request == power_pb2.PowerCommandRequest.REQUEST_ON_MOTORS:
                self.command_id += 1
                response.power_command_id = self.command_id
                if self.r.power() == robot_state_pb2.PowerState.MOTOR_POWER_STATE_ON:
                    response.status = power_pb2.STATUS_SUCCESS
                else:
                    self.r.powering_on_until = time.time() + self.r.args.power_on_seconds
                    response.status = power_pb2.STATUS_IN_PROGRESS
            elif request.request == power_pb2.PowerCommandRequest.REQUEST_OFF_MOTORS:
                self.r.motors_on = self.r.standing = False
                response.status = power_pb2.STATUS_SUCCESS
            else:
                response.status = power_pb2.INCOMPATIBLE_HARDWARE_ERROR
        response.header.CopyFrom(self.r.header(request, received))
        return response

    def PowerCommandFeedback(self, request, context):
        received = self.r.now()
        self.r.record("PowerCommandFeedback", context, request)
        response = power_pb2.PowerCommandFeedbackResponse()
        with self.r.lock:
            on = self.r.power() == robot_state_pb2.PowerState.MOTOR_POWER_STATE_ON
        response.status = power_pb2.STATUS_SUCCESS if on else power_pb2.STATUS_IN_PROGRESS
        response.header.CopyFrom(self.r.header(request, received))
        return response


class Commands(robot_command_service_pb2_grpc.RobotCommandServiceServicer):
    """Checks the lease and the time sync's clock, then walks by velocity commands."""

    def __init__(self, robot, leases):
        self.r = robot
        self.leases = leases

    def RobotCommand(self, request, context):
        received = self.r.now()
        self.r.record("RobotCommand", context, request, **command_times(request.command))
        response = robot_command_pb2.RobotCommandResponse()
        with self.r.lock:
            response.lease_use_result.CopyFrom(self.leases.check(request.lease))
        if response.lease_use_result.status != lease_pb2.LeaseUseResult.STATUS_OK:
            response.status = robot_command_pb2.RobotCommandResponse.STATUS_UNKNOWN
        elif request.clock_identifier != CLOCK_ID:
            response.status = robot_command_pb2.RobotCommandResponse.STATUS_NO_TIMESYNC
        else:
            response.status = self.apply(request.command)
        if response.status == robot_command_pb2.RobotCommandResponse.STATUS_OK:
            self.r.command_id += 1
            response.robot_command_id = self.r.command_id
            with self.r.lock:
                kind = command_times(request.command)["kind"]
                vx, vy, wz = self.r.velocity if kind == "se2_velocity_request" else (0.0, 0.0, 0.0)
                self.r.last_command = (kind, vx, vy, wz)
                self.r.command_arrived.notify_all()
        response.header.CopyFrom(self.r.header(request, received))
        return response

    def apply(self, command):
        Status = robot_command_pb2.RobotCommandResponse
        self.r.step()
        if command.HasField("full_body_command"):
            if command.full_body_command.HasField("stop_request"):
                with self.r.lock:
                    self.r.velocity = (0.0, 0.0, 0.0)
                return Status.STATUS_OK
            if command.full_body_command.HasField("safe_power_off_request"):
                with self.r.lock:
                    self.r.velocity = (0.0, 0.0, 0.0)
                    self.r.motors_on = self.r.standing = False
                    self.r.powering_on_until = None
                return Status.STATUS_OK
            return Status.STATUS_UNSUPPORTED
        with self.r.lock:
            if self.r.power() != robot_state_pb2.PowerState.MOTOR_POWER_STATE_ON:
                return Status.STATUS_NOT_POWERED_ON
            if self.r.args.behavior_fault:
                return Status.STATUS_BEHAVIOR_FAULT
        mobility = command.synchronized_command.mobility_command
        if self.r.args.refuse_motion and mobility.WhichOneof("command") in (
                "se2_velocity_request", "se2_trajectory_request"):
            return Status.STATUS_BEHAVIOR_FAULT
        if mobility.params.type_url:
            params = spot_command_pb2.MobilityParams()
            if not mobility.params.Unpack(params):
                return Status.STATUS_INVALID_REQUEST
        kind = mobility.WhichOneof("command")
        if kind == "se2_velocity_request":
            request = mobility.se2_velocity_request
            if request.se2_frame_name not in ("body", "flat_body"):
                return Status.STATUS_UNKNOWN_FRAME
            if seconds(request.end_time) < self.r.now():
                return Status.STATUS_EXPIRED
            v = request.velocity
            with self.r.lock:
                self.r.velocity = (v.linear.x, v.linear.y, v.angular)
                self.r.velocity_end = seconds(request.end_time)
            return Status.STATUS_OK
        if kind == "se2_trajectory_request":
            request = mobility.se2_trajectory_request
            if request.se2_frame_name not in ("odom", "vision"):
                return Status.STATUS_UNKNOWN_FRAME
            if seconds(request.end_time) < self.r.now():
                return Status.STATUS_EXPIRED
            return Status.STATUS_OK
        if kind == "stop_request":
            with self.r.lock:
                self.r.velocity = (0.0, 0.0, 0.0)
            return Status.STATUS_OK
        if kind in ("stand_request", "sit_request"):
            with self.r.lock:
                self.r.velocity = (0.0, 0.0, 0.0)
                self.r.posture_commands[self.r.command_id + 1] = (kind,
                                                                  time.time() + self.r.args.posture_seconds)
            return Status.STATUS_OK
        return Status.STATUS_UNSUPPORTED

    def RobotCommandFeedback(self, request, context):
        received = self.r.now()
        self.r.record("RobotCommandFeedback", context, request)
        response = robot_command_pb2.RobotCommandFeedbackResponse()
        with self.r.lock:
            kind, done_at = self.r.posture_commands.get(request.robot_command_id, (None, 0.0))
            done = time.time() >= done_at
            if kind == "stand_request" and done:
                self.r.standing = True
            elif kind == "sit_request" and done:
                self.r.standing = False
        mobility = response.feedback.synchronized_feedback.mobility_command_feedback
        mobility.status = basic_command_pb2.RobotCommandFeedbackStatus.STATUS_PROCESSING
        if kind == "stand_request":
            mobility.stand_feedback.status = (
                basic_command_pb2.StandCommand.Feedback.STATUS_IS_STANDING if done
                else basic_command_pb2.StandCommand.Feedback.STATUS_IN_PROGRESS)
        elif kind == "sit_request":
            mobility.sit_feedback.status = (
                basic_command_pb2.SitCommand.Feedback.STATUS_IS_SITTING if done
                else basic_command_pb2.SitCommand.Feedback.STATUS_IN_PROGRESS)
        else:
            mobility.status = basic_command_pb2.RobotCommandFeedbackStatus.STATUS_UNKNOWN
        response.header.CopyFrom(self.r.header(request, received))
        return response


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--dir", required=True, help="folder for ca.pem and requests.jsonl")
    parser.add_argument("--clock-offset", type=float, default=0.0,
                        help="robot clock minus host clock, seconds")
    parser.add_argument("--token-lifetime", type=float, default=3600.0, help="seconds")
    parser.add_argument("--username", default="user")
    parser.add_argument("--password", default="password")
    parser.add_argument("--motors", choices=("on", "off"), default="on",
                        help="motor power at start (on: standing, off: sitting)")
    parser.add_argument("--estop", choices=("released", "asserted", "none"), default="released",
                        help="the hardware E-stop's state, or none registered")
    parser.add_argument("--behavior-fault", action="store_true", help="report a fall fault")
    parser.add_argument("--system-fault", default="", help="report a system fault of this name")
    parser.add_argument("--frozen", action="store_true", help="take commands, never move")
    parser.add_argument("--refuse-motion", action="store_true", help="refuse every motion")
    parser.add_argument("--stale-cloud", action="store_true", help="one scan, served forever")
    parser.add_argument("--world", choices=("helix", "room"), default="helix",
                        help="the clouds: the known helix, or a room seen from the body's pose")
    parser.add_argument("--odom-scale", type=float, default=1.0,
                        help="the odometry counts every motion this many times (1.05: 5 %% long)")
    parser.add_argument("--lease-held", action="store_true",
                        help="the body lease starts held by another client (the tablet)")
    parser.add_argument("--posture-seconds", type=float, default=POSTURE_SECONDS,
                        help="how long a stand or a sit takes")
    parser.add_argument("--power-on-seconds", type=float, default=POWER_ON_SECONDS,
                        help="how long a power-on takes")
    args = parser.parse_args()
    robot = Robot(args)
    key_pem, cert_pem = make_certificates(args.dir)
    server = grpc.server(futures.ThreadPoolExecutor(max_workers=8),
                         interceptors=[TokenCheck(robot)])
    leases = Leases(robot)
    if args.lease_held:
        leases.grant("tablet")
    auth_service_pb2_grpc.add_AuthServiceServicer_to_server(Auth(robot), server)
    directory_service_pb2_grpc.add_DirectoryServiceServicer_to_server(Directory(robot), server)
    robot_id_service_pb2_grpc.add_RobotIdServiceServicer_to_server(RobotIdServicer(robot), server)
    time_sync_service_pb2_grpc.add_TimeSyncServiceServicer_to_server(TimeSync(robot), server)
    lease_service_pb2_grpc.add_LeaseServiceServicer_to_server(leases, server)
    robot_state_service_pb2_grpc.add_RobotStateServiceServicer_to_server(
        RobotStateServicer(robot), server)
    point_cloud_service_pb2_grpc.add_PointCloudServiceServicer_to_server(PointClouds(robot), server)
    local_grid_service_pb2_grpc.add_LocalGridServiceServicer_to_server(LocalGrids(robot), server)
    robot_command_service_pb2_grpc.add_RobotCommandServiceServicer_to_server(
        Commands(robot, leases), server)
    power_service_pb2_grpc.add_PowerServiceServicer_to_server(Power(robot, leases), server)
    estop_service_pb2_grpc.add_EstopServiceServicer_to_server(Estop(robot), server)
    port = server.add_secure_port("127.0.0.1:0", grpc.ssl_server_credentials([(key_pem, cert_pem)]))
    server.start()
    print("READY %d" % port, flush=True)
    for line in sys.stdin:
        line = line.strip()
        if not line.startswith(("scan ", "wait-command ")):
            with robot.lock:  # faults are logged where they happen among the requests
                robot.log.write(json.dumps({"method": "control", "line": line, "robot_time": robot.now()}) + "\n")
        if line == "take-lease":
            with robot.lock:
                leases.grant("another-client")
        elif line == "stall-time-sync":
            robot.time_sync_stalled = True
        elif line == "malformed-cloud":
            robot.malformed_cloud = True
        elif line == "pose":
            # The body's true pose in odom, then the odometry's: x y yaw x y yaw.
            robot.step()
            with robot.lock:
                pose = robot.pose + robot.odom_pose
            print("OK pose " + " ".join(repr(v) for v in pose), flush=True)
            continue
        elif line.startswith("scan "):
            # scan <file of little-endian f32 xyz> <odom_T_body: 7 numbers> <body_T_lidar: 7>
            words = line.split()
            with open(words[1], "rb") as f:
                data = f.read()
            numbers = [float(w) for w in words[2:16]]
            with robot.lock:
                robot.bridge_scan = (data, robot.now(), numbers[:7], numbers[7:])
                robot.last_command = None
        elif line.startswith("wait-command "):
            # The command that answered the last scan (or none within the timeout).
            deadline = time.time() + float(line.split()[1])
            with robot.lock:
                while robot.last_command is None and time.time() < deadline:
                    robot.command_arrived.wait(timeout=max(0.0, deadline - time.time()))
                kind, vx, vy, wz = robot.last_command or ("none", 0.0, 0.0, 0.0)
            print("OK %s %s %r %r %r" % (line, kind, vx, vy, wz), flush=True)
            continue
        elif line == "drop":
            server.stop(0)
            print("OK drop", flush=True)
            return
        print("OK " + line, flush=True)
    server.stop(0)


if __name__ == "__main__":
    main()
