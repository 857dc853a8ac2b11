"""The official Spot SDK (bosdyn-client) runs spot-nav's flow against the fake Spot.

Authenticates, syncs time, takes the lease, reads the robot state, the point cloud and both local
grids, sends a velocity and a trajectory command and a stop, returns the lease, and prints one
JSON line with what it read. With `--power` it instead brings the robot up and down as a user's
script does: `robot.power_on`, `blocking_stand`, `blocking_sit`, `robot.power_off` (a safe power
off), then returns the lease. With `--take` it takes the lease (`LeaseClient.take`, as from the
tablet) and returns it. With `--estop SECONDS` it registers a software E-stop endpoint with that
timeout (`EstopEndpoint.register` in the active configuration), keeps it alive with
`EstopKeepAlive` for one timeout, then checks in at SETTLE_THEN_CUT and stops. The fake's log then holds the SDK's requests for the tests to compare
with spot-nav's. Any SDK exception fails the script (exit status 1).
"""

import argparse
import json
import sys
import time

import bosdyn.client
from bosdyn.client.frame_helpers import get_a_tform_b
from bosdyn.client.lease import LeaseClient
from bosdyn.client.local_grid import LocalGridClient
from bosdyn.client.point_cloud import PointCloudClient
from bosdyn.client.robot_command import (RobotCommandBuilder, RobotCommandClient, blocking_sit,
                                         blocking_stand)
from bosdyn.client.robot_state import RobotStateClient


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--port", type=int, required=True)
    parser.add_argument("--ca", required=True)
    parser.add_argument("--username", default="user")
    parser.add_argument("--password", default="password")
    parser.add_argument("--power", action="store_true", help="power on, stand, sit, power off")
    parser.add_argument("--take", action="store_true", help="take the lease and return it")
    parser.add_argument("--estop", type=float, default=0.0,
                        help="register a software E-stop with this timeout and keep it alive")
    args = parser.parse_args()

    sdk = bosdyn.client.create_standard_sdk("spot-nav-sdk-check")
    sdk.load_robot_cert(args.ca)
    robot = sdk.create_robot("127.0.0.1")
    robot.update_secure_channel_port(args.port)
    robot.authenticate(args.username, args.password, timeout=10)
    robot_id = robot.get_id()
    robot.time_sync.wait_for_sync(timeout_sec=10)
    skew = robot.time_sync.get_robot_clock_skew()
    if args.estop > 0.0:
        estop_flow(robot, args.estop)
        return
    lease_client = robot.ensure_client(LeaseClient.default_service_name)
    if args.take:
        lease = lease_client.take()
        lease_client.return_lease(lease)
        print(json.dumps({"taken": list(lease.lease_proto.sequence)}), flush=True)
        return
    lease = lease_client.acquire()
    if args.power:
        power_flow(robot, lease_client, lease)
        return
    state = robot.ensure_client(RobotStateClient.default_service_name).get_robot_state(timeout=10)
    snapshot = state.kinematic_state.transforms_snapshot
    odom_t_body = get_a_tform_b(snapshot, "odom", "body")
    clouds = robot.ensure_client("velodyne-point-cloud").get_point_cloud_from_sources(
        ["velodyne-point-cloud"], timeout=10)
    grids = robot.ensure_client(LocalGridClient.default_service_name).get_local_grids(
        ["terrain", "no_step"], timeout=10)
    commands = robot.ensure_client(RobotCommandClient.default_service_name)
    from bosdyn.client.lease import LeaseKeepAlive, LeaseWallet  # noqa: F401 (the SDK's wallet)
    robot.lease_wallet.add(lease)
    end = time.time() + 1.0
    commands.robot_command(RobotCommandBuilder.synchro_velocity_command(0.3, 0.0, 0.1),
                           end_time_secs=end, timeout=10)
    commands.robot_command(RobotCommandBuilder.synchro_se2_trajectory_point_command(
        1.5, 2.0, 0.2, "odom"), end_time_secs=time.time() + 5.0, timeout=10)
    commands.robot_command(RobotCommandBuilder.stop_command(), timeout=10)
    lease_client.return_lease(lease)
    print(json.dumps({
        "serial": robot_id.serial_number,
        "clock_skew": skew.seconds + skew.nanos * 1e-9,
        "odom_t_body": [odom_t_body.x, odom_t_body.y, odom_t_body.z],
        "num_points": clouds[0].point_cloud.num_points,
        "grids": [g.local_grid.local_grid_type_name for g in grids],
    }), flush=True)


def estop_flow(robot, timeout):
    """Register a software E-stop endpoint, keep it alive for `timeout`, then settle and cut."""
    from bosdyn.client.estop import EstopClient, EstopEndpoint, EstopKeepAlive
    client = robot.ensure_client(EstopClient.default_service_name)
    config = client.get_config()
    endpoint = EstopEndpoint(client, "spot-nav", estop_timeout=timeout)
    endpoint.register(config.unique_id)
    keep_alive = EstopKeepAlive(endpoint)
    time.sleep(timeout)
    keep_alive.settle_then_cut()
    keep_alive.shutdown()
    print(json.dumps({"estop": endpoint.unique_id}), flush=True)


def power_flow(robot, lease_client, lease):
    """Power on, stand, sit, power off, as the SDK's helpers do it, and return the lease."""
    robot.lease_wallet.add(lease)
    robot.power_on(timeout_sec=20)
    commands = robot.ensure_client(RobotCommandClient.default_service_name)
    blocking_stand(commands, timeout_sec=10)
    blocking_sit(commands, timeout_sec=10)
    robot.power_off(timeout_sec=20)
    lease_client.return_lease(lease)
    print(json.dumps({"powered": "on and off"}), flush=True)


if __name__ == "__main__":
    try:
        main()
    except Exception as error:  # report the SDK's complaint, not a traceback
        print("SDK flow failed: %r" % (error,), file=sys.stderr, flush=True)
        sys.exit(1)
