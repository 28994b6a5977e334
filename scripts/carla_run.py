#!/usr/bin/env python3
"""Replay a LanEvil case in CARLA from the files ``lanevil export --opendrive --openscenario`` writes.

Not run in CI: it needs a running CARLA server (0.9.14 or later) and its ``carla`` Python package; for the
scenario, also a checkout of CARLA's scenario_runner.

    lanevil export scenes/10_road_damage/tire_marks/00_straight_highway_noon/05_level5.json --out out/tire_marks \
        --openscenario
    python scripts/carla_run.py out/tire_marks                      # the road as a CARLA world, weather, ego
    python scripts/carla_run.py out/tire_marks --scenario-runner ~/scenario_runner   # the .xosc, via scenario_runner

Without ``--scenario-runner`` the script builds the world from ``road.xodr`` (``generate_opendrive_world``),
sets the case's weather numbers from ``case.json`` when present (CARLA's WeatherParameters are the case's own
fields), spawns the ego at the case's start pose with the case's camera (1280x720, 90 deg, 1 m ahead and 3 m up)
and lets CARLA's autopilot drive it along the lane while saving the camera frames. With ``--scenario-runner`` it
hands ``scenario.xosc`` to scenario_runner (``scenario_runner.py --openscenario``), which loads the road itself.

What does not carry over (see docs/interchange.md): illusion surface textures (cracks, repairs, tyre marks,
puddles), the exact shapes of props and participants (CARLA blueprints stand in), and in the standalone
OpenDRIVE mode lane markings are not drawn by CARLA.
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import time
from pathlib import Path

XODR_FILE = "road.xodr"
XOSC_FILE = "scenario.xosc"
CASE_FILE = "case.json"
WEATHER_FIELDS = ("cloudiness", "precipitation", "precipitation_deposits", "wetness", "fog_density", "fog_distance")


def parse_arguments(argv: list[str] | None = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", type=Path, help="folder with road.xodr (and scenario.xosc, case.json)")
    parser.add_argument("--host", default="localhost")
    parser.add_argument("--port", type=int, default=2000)
    parser.add_argument("--seconds", type=float, default=10.0, help="how long to drive (default 10)")
    parser.add_argument("--frames", type=Path, default=None, help="save the ego camera's frames here")
    parser.add_argument("--scenario-runner", type=Path, default=None,
                        help="scenario_runner checkout: run scenario.xosc with it instead")
    return parser.parse_args(argv)


def run_scenario_runner(folder: Path, runner: Path, host: str, port: int) -> int:
    """Hand the .xosc to scenario_runner (it loads road.xodr itself through the scenario's RoadNetwork)."""
    command = [sys.executable, str(runner / "scenario_runner.py"), "--openscenario", str(folder / XOSC_FILE),
               "--host", host, "--port", str(port), "--output"]
    return subprocess.call(command, cwd=folder)


def load_world(client, xodr_text: str):  # noqa: ANN001, ANN201 - carla types
    """A CARLA world generated from the OpenDRIVE text (no map assets needed)."""
    import carla

    parameters = carla.OpendriveGenerationParameters(
        vertex_distance=2.0, max_road_length=500.0, wall_height=0.0, additional_width=0.6,
        smooth_junctions=True, enable_mesh_visibility=True)
    return client.generate_opendrive_world(xodr_text, parameters)


def carla_sun_azimuth(case_azimuth: float) -> float:
    """CARLA's ``sun_azimuth_angle`` (degrees) for the case's sun azimuth (degrees counter-clockwise from world +X):
    the OpenSCENARIO azimuth (clockwise from north = world +Y), which is what scenario_runner hands CARLA unchanged
    from ``scenario.xosc``, so that both ways of running a case put the sun in the same place."""
    return (90.0 - case_azimuth) % 360.0


def apply_case(world, case: dict) -> None:  # noqa: ANN001
    """The case's weather numbers and sun (azimuth as in ``carla_sun_azimuth``)."""
    import carla

    weather = carla.WeatherParameters(**{key: float(case["weather"][key]) for key in WEATHER_FIELDS})
    weather.sun_altitude_angle = float(case["sun"]["altitude"])
    weather.sun_azimuth_angle = carla_sun_azimuth(float(case["sun"]["azimuth"]))
    world.set_weather(weather)


def spawn_ego(world, case: dict | None):  # noqa: ANN001, ANN201
    """The ego at the first waypoint of its lane (OpenDRIVE lane -(lane + 1) of road 1, at the start station)."""
    carla_map = world.get_map()
    lane_id = -((case or {}).get("ego", {}).get("lane", 0) + 1)
    start_s = float((case or {}).get("ego", {}).get("start_s", 10.0))
    waypoint = carla_map.get_waypoint_xodr(1, lane_id, start_s)
    if waypoint is None:
        waypoint = carla_map.generate_waypoints(5.0)[0]
    transform = waypoint.transform
    transform.location.z += 0.5
    blueprint = world.get_blueprint_library().find("vehicle.audi.a2")
    blueprint.set_attribute("role_name", "hero")
    return world.spawn_actor(blueprint, transform)


def attach_camera(world, ego, case: dict | None, out: Path):  # noqa: ANN001, ANN201
    """The case camera on the ego, saving every frame under ``out``."""
    import carla

    camera = (case or {}).get("camera", {})
    blueprint = world.get_blueprint_library().find("sensor.camera.rgb")
    blueprint.set_attribute("image_size_x", str(camera.get("width", 1280)))
    blueprint.set_attribute("image_size_y", str(camera.get("height", 720)))
    blueprint.set_attribute("fov", str(camera.get("fov", 90.0)))
    mount = carla.Transform(carla.Location(x=camera.get("x", 1.0), y=-camera.get("y", 0.0), z=camera.get("z", 3.0)),
                            carla.Rotation(pitch=-camera.get("pitch", 0.0)))
    sensor = world.spawn_actor(blueprint, mount, attach_to=ego)
    out.mkdir(parents=True, exist_ok=True)
    sensor.listen(lambda image: image.save_to_disk(str(out / f"{image.frame:06d}.png")))
    return sensor


def drive(args: argparse.Namespace) -> int:
    import carla

    folder = args.folder
    case = json.loads((folder / CASE_FILE).read_text()) if (folder / CASE_FILE).is_file() else None
    client = carla.Client(args.host, args.port)
    client.set_timeout(60.0)
    world = load_world(client, (folder / XODR_FILE).read_text(encoding="utf-8"))
    if case is not None:
        apply_case(world, case)
    fps = float((case or {}).get("ego", {}).get("fps", 10.0))
    settings = world.get_settings()
    settings.synchronous_mode, settings.fixed_delta_seconds = True, 1.0 / fps
    world.apply_settings(settings)
    ego = spawn_ego(world, case)
    sensor = attach_camera(world, ego, case, args.frames) if args.frames is not None else None
    speed = float((case or {}).get("ego", {}).get("speed", 10.0))
    traffic_manager = client.get_trafficmanager()
    traffic_manager.set_synchronous_mode(True)
    ego.set_autopilot(True, traffic_manager.get_port())
    traffic_manager.set_desired_speed(ego, speed * 3.6)
    traffic_manager.auto_lane_change(ego, False)
    try:
        for _ in range(int(math.ceil(args.seconds * fps))):
            world.tick()
        time.sleep(0.5)  # let the last frames reach the disk
    finally:
        if sensor is not None:
            sensor.destroy()
        ego.destroy()
        settings.synchronous_mode = False
        world.apply_settings(settings)
    return 0


def main(argv: list[str] | None = None) -> int:
    args = parse_arguments(argv)
    if not (args.folder / XODR_FILE).is_file():
        print(f"carla_run: {args.folder / XODR_FILE} is missing (lanevil export CASE --out DIR --openscenario)",
              file=sys.stderr)
        return 2
    if args.scenario_runner is not None:
        return run_scenario_runner(args.folder, args.scenario_runner, args.host, args.port)
    try:
        import carla  # noqa: F401
    except ImportError:
        print("carla_run: the carla Python package is not installed (it comes with CARLA)", file=sys.stderr)
        return 2
    return drive(args)


if __name__ == "__main__":
    sys.exit(main())
