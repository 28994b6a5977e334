"""A case's drive as OpenSCENARIO 1.0 (``scenario.xosc``, what CARLA's scenario_runner reads), written with the
``scenariogeneration`` package next to the case's ``road.xodr``.

- Entities: the ego (``hero``, CARLA's ego role name, marked by the property ``type = ego_vehicle`` that
  scenario_runner looks for) and every traffic participant an illusion placed (cars, vans and trucks by their size,
  cyclists as bicycles, pedestrians), each with its bounding box, its heading as placed, and a CARLA blueprint as the
  Vehicle's ``name`` (where scenario_runner takes it from) and ``model`` property.
- Init: every entity teleported to its start pose (world x, y, z, heading); the ego at the case's speed,
  participants standing (the case's participants do not move); the case's weather and sun as the environment.
- Storyboard: the ego assigned a route along its lane (OpenDRIVE lane ``-(lane + 1)`` of the main road, from its
  start to where the case's drive ends), stopped after the drive's duration.

Units follow OpenSCENARIO: metres, seconds, radians; sun azimuth clockwise from north = world +Y (the case's is
counter-clockwise from world +X = east). The sun's intensity is written on scenario_runner's 0-1 scale (it sets
CARLA's cloudiness to 100 - 100 x intensity), so it is 1 - cloudiness / 100 of the case. The file header's date is
fixed (``FILE_DATE``) so that an export is byte-identical for the same case.
"""

from __future__ import annotations

import datetime
import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..case import Case
from ..world.scene import CompiledScene, Mesh
from .opendrive import MAIN_ROAD_ID, THROUGH_ROAD_ID, junction_radius

if TYPE_CHECKING:
    from scenariogeneration import xosc

OSC_MINOR_VERSION = 0  # OpenSCENARIO 1.0: what CARLA's scenario_runner reads
EGO_NAME = "hero"
EGO_MODEL = "vehicle.audi.a2"  # the paper drove an Audi
EGO_PROPERTY = ("type", "ego_vehicle")  # how scenario_runner tells the ego from the other vehicles
# participant category (OpenSCENARIO vehicle category, or pedestrian) -> CARLA 0.9.16 blueprint
MODELS = {"car": "vehicle.tesla.model3", "van": "vehicle.mercedes.sprinter",
          "truck": "vehicle.carlamotors.carlacola", "bicycle": "vehicle.bh.crossbike",
          "pedestrian": "walker.pedestrian.0001"}
PARTICIPANT_KINDS = ("vehicle", "bicycle", "pedestrian")  # mesh kinds that are traffic participants
TRUCK_MIN_LENGTH_M = 6.5  # a vehicle this long is a truck (the case's trucks are 8.0 m, vans 5.2 m, cars 4.5 m)
VAN_MIN_HEIGHT_M = 2.0  # a shorter vehicle this tall is a van (vans 2.3 m, cars 1.45 m)
SEDAN_BOX = (1.8, 4.5, 1.5)  # width, length, height (m)
FILE_DATE = datetime.datetime(2024, 6, 21)  # the scenario's fixed header date (the day its time of day uses)


@dataclass(frozen=True)
class Participant:
    """A traffic participant of the case: its kind, world centre (x, y, z of its base), heading (radians,
    counter-clockwise from +X) and bounding box (width, length, height in m)."""

    name: str
    kind: str
    category: str  # car, van, truck, bicycle or pedestrian: the key of its blueprint in MODELS
    x: float
    y: float
    z: float
    heading: float
    width: float
    length: float
    height: float


def _heading(mesh: Mesh, scene: CompiledScene) -> float:
    """The participant's heading as placed; for a mesh placed without one, its footprint's long axis in the
    direction nearer the road's."""
    if mesh.heading is not None:
        return mesh.heading
    xy = mesh.vertices[:, :2]
    _, _, axes = np.linalg.svd(xy - xy.mean(0), full_matrices=False)
    heading = math.atan2(axes[0][1], axes[0][0])
    s_road, _ = scene.network.main.line.station(0.5 * (xy.min(0) + xy.max(0)))
    return heading + math.pi if math.cos(heading - float(scene.network.main.line.heading_at(s_road))) < 0 else heading


def category(kind: str, length: float, height: float) -> str:
    """The participant's category (a key of ``MODELS``) from its mesh kind and size (m)."""
    if kind != "vehicle":
        return kind
    return "truck" if length >= TRUCK_MIN_LENGTH_M else "van" if height >= VAN_MIN_HEIGHT_M else "car"


def _participant(mesh: Mesh, index: int, scene: CompiledScene) -> Participant:
    p_world = mesh.vertices
    xy = p_world[:, :2]
    centre = 0.5 * (xy.min(0) + xy.max(0))
    heading = math.remainder(_heading(mesh, scene), 2 * math.pi)
    local = (xy - centre) @ np.array([[math.cos(heading), -math.sin(heading)], [math.sin(heading), math.cos(heading)]])
    length, height = float(np.ptp(local[:, 0])), float(np.ptp(p_world[:, 2]))
    return Participant(f"{mesh.kind}_{index}", mesh.kind, category(mesh.kind, length, height), float(centre[0]),
                       float(centre[1]), float(p_world[:, 2].min()), heading, float(np.ptp(local[:, 1])), length,
                       height)


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


def _vehicle(category: str, box: tuple[float, float, float], model: str, ego: bool = False) -> xosc.Vehicle:
    """A vehicle named after its CARLA blueprint (scenario_runner spawns the Vehicle's ``name``)."""
    xosc = _xosc()
    width, length, height = box
    bounding = xosc.BoundingBox(width, length, height, 0.0, 0.0, height / 2)
    wheelbase = 0.6 * length
    vehicle = xosc.Vehicle(model, getattr(xosc.VehicleCategory, category), bounding,
                           xosc.Axle(0.6, 0.8, 1.6, wheelbase / 2, 0.4), xosc.Axle(0.0, 0.8, 1.6, -wheelbase / 2, 0.4),
                           69.0, 10.0, 10.0)
    vehicle.add_property("model", model)
    if ego:
        vehicle.add_property(*EGO_PROPERTY)
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
    return _vehicle(participant.category, box, MODELS[participant.category])


def environment(case: Case) -> xosc.Environment:
    """The case's weather and sun as an OpenSCENARIO 1.0 environment."""
    xosc = _xosc()
    weather, sun = case.weather, case.sun
    clouds = ("free", "cloudy", "overcast", "rainy")
    cloud = clouds[min(3, int(weather.cloudiness // 25))] if weather.precipitation < 30 else "rainy"
    intensity = min(1.0, max(0.0, 1.0 - weather.cloudiness / 100.0))  # scenario_runner's scale, see above
    azimuth = math.radians((90.0 - sun.azimuth) % 360.0)  # clockwise from north
    elevation = math.radians(sun.altitude)
    visual_range = int(round(max(10.0, 100_000.0 * math.exp(-weather.fog_density / 10.0)))) \
        if weather.fog_density > 0 else 100_000
    rain = xosc.Precipitation(xosc.PrecipitationType.rain if weather.precipitation > 0 else xosc.PrecipitationType.dry,
                              weather.precipitation / 100.0)
    osc_weather = xosc.Weather(getattr(xosc.CloudState, cloud), sun=xosc.Sun(intensity, azimuth, elevation),
                               fog=xosc.Fog(visual_range), precipitation=rain)
    night = sun.altitude <= 0
    time_of_day = xosc.TimeOfDay(False, 2024, 6, 21, 22 if night else 12, 0, 0)
    friction = 1.0 - 0.3 * max(weather.wetness, weather.precipitation_deposits) / 100.0
    return xosc.Environment("case_environment", time_of_day, osc_weather, xosc.RoadCondition(friction))


def _road_position(case: Case, scene: CompiledScene, s_road: float) -> tuple[int, float]:
    """(OpenDRIVE road id, s on that road) of main-road station ``s_road`` (the main road is cut at a junction, whose
    through road joins its two halves)."""
    if len(scene.network.pieces) == 1:
        return MAIN_ROAD_ID, s_road
    radius = junction_radius(scene.network)
    if s_road < case.road.junction_s - radius:
        return MAIN_ROAD_ID, s_road
    if s_road <= case.road.junction_s + radius:
        return THROUGH_ROAD_ID, s_road - (case.road.junction_s - radius)
    return MAIN_ROAD_ID + 1, s_road - case.road.junction_s - radius


def route_stations(case: Case, scene: CompiledScene) -> list[float]:
    """Main-road stations of the ego's route waypoints: its start, the junction's centre when the drive crosses it
    (so that the route names the connecting road it takes), and where the drive ends."""
    s_start, s_end = case.ego.start_s, case.ego_s(case.ego.frames - 1)
    inside = len(scene.network.pieces) > 1 and s_start < case.road.junction_s < s_end
    return [s_start, case.road.junction_s, s_end] if inside else [s_start, s_end]


def scenario(case: Case, scene: CompiledScene, road_file: str = "road.xodr") -> xosc.Scenario:
    """The case as an OpenSCENARIO 1.0 scenario on ``road_file``."""
    xosc = _xosc()
    entities = xosc.Entities()
    entities.add_scenario_object(EGO_NAME, _vehicle("car", SEDAN_BOX, EGO_MODEL, ego=True))
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
    for s_road in route_stations(case, scene):
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
                         storyboard, xosc.RoadNetwork(road_file), xosc.Catalog(), osc_minor_version=OSC_MINOR_VERSION,
                         creation_date=FILE_DATE)


def write_openscenario(case: Case, out_dir: str | Path, scene: CompiledScene | None = None) -> Path:
    """Write ``out_dir/scenario.xosc`` (referring to ``road.xodr`` beside it); returns its path."""
    from ..pipeline.compile import compile_scene

    path = Path(out_dir) / "scenario.xosc"
    path.parent.mkdir(parents=True, exist_ok=True)
    scenario(case, scene if scene is not None else compile_scene(case)).write_xml(str(path))
    return path
