"""A case's drive as OpenSCENARIO 1.0 (``scenario.xosc``, what CARLA's scenario_runner reads), written with the
``scenariogeneration`` package next to the case's ``road.xodr``.

- Entities: the ego (``hero``, CARLA's ego role name) and every traffic participant an illusion placed (vehicles,
  cyclists as bicycles, pedestrians), each with its bounding box and a CARLA blueprint as its ``model`` property.
- Init: every entity teleported to its start pose (world x, y, z, heading); the ego at the case's speed,
  participants standing (the case's participants do not move); the case's weather and sun as the environment.
- Storyboard: the ego assigned a route along its lane (OpenDRIVE lane ``-(lane + 1)`` of the main road, from its
  start to where the case's drive ends), stopped after the drive's duration.

Units follow OpenSCENARIO: metres, seconds, radians; sun azimuth clockwise from north (the case's is
counter-clockwise from world +X = east), sun intensity in lux.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..case import Case
from ..scene import CompiledScene, Mesh
from .opendrive import MAIN_ROAD_ID

if TYPE_CHECKING:
    from scenariogeneration import xosc

OSC_MINOR_VERSION = 0  # OpenSCENARIO 1.0: what CARLA's scenario_runner reads
EGO_NAME = "hero"
EGO_MODEL = "vehicle.audi.a2"  # the paper drove an Audi
MODELS = {"vehicle": "vehicle.tesla.model3", "bicycle": "vehicle.bh.crossbike",
          "pedestrian": "walker.pedestrian.0001"}
PARTICIPANT_KINDS = tuple(MODELS)
CLEAR_NOON_LUX = 100_000.0
SEDAN_BOX = (1.8, 4.5, 1.5)  # width, length, height (m)


@dataclass(frozen=True)
class Participant:
    """A traffic participant of the case: its kind, world centre (x, y, z of its base), heading (radians,
    counter-clockwise from +X) and bounding box (width, length, height in m)."""

    name: str
    kind: str
    x: float
    y: float
    z: float
    heading: float
    width: float
    length: float
    height: float


def _participant(mesh: Mesh, index: int, scene: CompiledScene) -> Participant:
    p_world = mesh.vertices
    xy = p_world[:, :2]
    centre = 0.5 * (xy.min(0) + xy.max(0))
    # The footprint's long axis is the heading; of its two directions the one nearer the road's is taken.
    _, _, axes = np.linalg.svd(xy - xy.mean(0), full_matrices=False)
    heading = math.atan2(axes[0][1], axes[0][0])
    line = scene.network.main.line
    s_road, t_road = line.station(centre)
    road_heading = float(line.heading_at(s_road)) + (math.pi if t_road > 0 and mesh.kind == "vehicle" else 0.0)
    if math.cos(heading - road_heading) < 0:
        heading += math.pi
    heading = math.atan2(math.sin(heading), math.cos(heading))
    local = (xy - centre) @ np.array([[math.cos(heading), -math.sin(heading)], [math.sin(heading), math.cos(heading)]])
    return Participant(f"{mesh.kind}_{index}", mesh.kind, float(centre[0]), float(centre[1]),
                       float(p_world[:, 2].min()), heading, float(np.ptp(local[:, 1])), float(np.ptp(local[:, 0])),
                       float(np.ptp(p_world[:, 2])))


def participants(scene: CompiledScene) -> list[Participant]:
    """Every vehicle, bicycle and pedestrian the case's illusions placed, numbered per kind."""
    counts: dict[str, int] = {}
    found = []
    for mesh in scene.meshes:
        if mesh.source >= 0 and mesh.kind in PARTICIPANT_KINDS:
            counts[mesh.kind] = counts.get(mesh.kind, 0) + 1
            found.append(_participant(mesh, counts[mesh.kind], scene))
    return found


def _xosc():  # noqa: ANN202 - the module, imported only when writing
    from scenariogeneration import xosc

    return xosc


def _vehicle(name: str, category: str, box: tuple[float, float, float], model: str) -> xosc.Vehicle:
    xosc = _xosc()
    width, length, height = box
    bounding = xosc.BoundingBox(width, length, height, 0.0, 0.0, height / 2)
    wheelbase = 0.6 * length
    vehicle = xosc.Vehicle(name, getattr(xosc.VehicleCategory, category), bounding,
                           xosc.Axle(0.6, 0.8, 1.6, wheelbase / 2, 0.4), xosc.Axle(0.0, 0.8, 1.6, -wheelbase / 2, 0.4),
                           69.0, 10.0, 10.0)
    vehicle.add_property("model", model)
    return vehicle


def _entity(participant: Participant) -> xosc.Vehicle | xosc.Pedestrian:
    xosc = _xosc()
    box = (max(participant.width, 0.3), max(participant.length, 0.3), max(participant.height, 0.5))
    if participant.kind == "pedestrian":
        bounding = xosc.BoundingBox(*box, 0.0, 0.0, box[2] / 2)
        pedestrian = xosc.Pedestrian(participant.name, 75.0, xosc.PedestrianCategory.pedestrian, bounding,
                                     MODELS["pedestrian"])
        pedestrian.add_property("model", MODELS["pedestrian"])
        return pedestrian
    category = "bicycle" if participant.kind == "bicycle" else "car"
    return _vehicle(participant.name, category, box, MODELS[participant.kind])


def environment(case: Case) -> xosc.Environment:
    """The case's weather and sun as an OpenSCENARIO 1.0 environment."""
    xosc = _xosc()
    weather, sun = case.weather, case.sun
    clouds = ("free", "cloudy", "overcast", "rainy")
    cloud = clouds[min(3, int(weather.cloudiness // 25))] if weather.precipitation < 30 else "rainy"
    lux = CLEAR_NOON_LUX * sun.intensity if sun.altitude > 0 else 0.0
    azimuth = math.radians((90.0 - sun.azimuth) % 360.0)  # clockwise from north
    elevation = math.radians(sun.altitude)
    visual_range = int(round(max(10.0, 100_000.0 * math.exp(-weather.fog_density / 10.0)))) \
        if weather.fog_density > 0 else 100_000
    rain = xosc.Precipitation(xosc.PrecipitationType.rain if weather.precipitation > 0 else xosc.PrecipitationType.dry,
                              weather.precipitation / 100.0)
    osc_weather = xosc.Weather(getattr(xosc.CloudState, cloud), sun=xosc.Sun(lux, azimuth, elevation),
                               fog=xosc.Fog(visual_range), precipitation=rain)
    night = sun.altitude <= 0
    time_of_day = xosc.TimeOfDay(False, 2024, 6, 21, 22 if night else 12, 0, 0)
    friction = 1.0 - 0.3 * max(weather.wetness, weather.precipitation_deposits) / 100.0
    return xosc.Environment("case_environment", time_of_day, osc_weather, xosc.RoadCondition(friction))


def _road_position(case: Case, scene: CompiledScene, s_road: float) -> tuple[int, float]:
    """(OpenDRIVE road id, s on that road) of main-road station ``s_road`` (the main road is cut at a junction)."""
    if len(scene.network.pieces) == 1:
        return MAIN_ROAD_ID, s_road
    reach = scene.network.main.half_width
    if s_road < case.road.junction_s - reach:
        return MAIN_ROAD_ID, s_road
    return MAIN_ROAD_ID + 1, max(0.0, s_road - case.road.junction_s - reach)


def scenario(case: Case, scene: CompiledScene, road_file: str = "road.xodr") -> xosc.Scenario:
    """The case as an OpenSCENARIO 1.0 scenario on ``road_file``."""
    xosc = _xosc()
    entities = xosc.Entities()
    entities.add_scenario_object(EGO_NAME, _vehicle("ego_vehicle", "car", SEDAN_BOX, EGO_MODEL))
    init = xosc.Init()
    init.add_global_action(xosc.EnvironmentAction(environment(case)))
    line = scene.network.main.line
    t_ego = scene.network.lane_center_t(case.ego.lane)
    p_world = line.to_world(case.ego.start_s, t_ego)
    init.add_init_action(EGO_NAME, xosc.TeleportAction(xosc.WorldPosition(
        float(p_world[0]), float(p_world[1]), float(p_world[2]), float(line.heading_at(case.ego.start_s)))))
    step = xosc.TransitionDynamics(xosc.DynamicsShapes.step, xosc.DynamicsDimension.time, 0.0)
    init.add_init_action(EGO_NAME, xosc.AbsoluteSpeedAction(case.ego.speed, step))
    for participant in participants(scene):
        entities.add_scenario_object(participant.name, _entity(participant))
        init.add_init_action(participant.name, xosc.TeleportAction(xosc.WorldPosition(
            participant.x, participant.y, participant.z, participant.heading)))
        if participant.kind != "pedestrian":
            init.add_init_action(participant.name, xosc.AbsoluteSpeedAction(0.0, step))
    duration = case.ego.frames / case.ego.fps
    lane_id = -(case.ego.lane + 1)
    route = xosc.Route("ego_lane")
    for s_road in (case.ego.start_s, case.ego_s(case.ego.frames - 1)):
        road_id, s_local = _road_position(case, scene, s_road)
        route.add_waypoint(xosc.LanePosition(s_local, 0.0, lane_id, road_id), xosc.RouteStrategy.shortest)
    start = xosc.ValueTrigger("drive_starts", 0.0, xosc.ConditionEdge.none,
                              xosc.SimulationTimeCondition(0.0, xosc.Rule.greaterThan))
    event = xosc.Event("follow_the_lane", xosc.Priority.overwrite)
    event.add_action("assign_lane_route", xosc.AssignRouteAction(route))
    event.add_trigger(start)
    maneuver = xosc.Maneuver("lane_keeping")
    maneuver.add_event(event)
    group = xosc.ManeuverGroup("ego_drives")
    group.add_actor(EGO_NAME)
    group.add_maneuver(maneuver)
    act = xosc.Act("drive", start)
    act.add_maneuver_group(group)
    story = xosc.Story("case_drive")
    story.add_act(act)
    stop = xosc.ValueTrigger("drive_ends", 0.0, xosc.ConditionEdge.rising,
                             xosc.SimulationTimeCondition(duration, xosc.Rule.greaterThan), "stop")
    storyboard = xosc.StoryBoard(init, stop)
    storyboard.add_story(story)
    return xosc.Scenario(case.title or "lanevil case", "LanEvil Studio", xosc.ParameterDeclarations(), entities,
                         storyboard, xosc.RoadNetwork(road_file), xosc.Catalog(), osc_minor_version=OSC_MINOR_VERSION)


def write_openscenario(case: Case, out_dir: str | Path, scene: CompiledScene | None = None) -> Path:
    """Write ``out_dir/scenario.xosc`` (referring to ``road.xodr`` beside it); returns its path."""
    from ..compile import compile_scene

    path = Path(out_dir) / "scenario.xosc"
    path.parent.mkdir(parents=True, exist_ok=True)
    scenario(case, scene if scene is not None else compile_scene(case)).write_xml(str(path))
    return path
