"""Scenario interchange as independent consumers read it: junction geometry a simulator can sample, objects off the
carriageway, a scenario_runner-ready ego, participants facing as placed, the sun agreeing with the CARLA script, and
byte-identical exports. The XML is read back here with its own small reader, not with the writer's library."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from lanevil_core.case import load_case
from lanevil_core.interchange import write_interchange
from lanevil_core.interchange.opendrive import CLEARANCE_M, JUNCTION_ID, MARK_TYPES, THROUGH_ROAD_ID, junction_radius
from lanevil_core.interchange.openscenario import EGO_NAME, MODELS, category, participants
from lanevil_core.pipeline.compile import compile_scene

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "scenes"
JUNCTIONS = ["00_clean/05_t_junction_urban.json", "00_clean/06_crossroad_suburban.json"]


def _representative(type_folder: str, level: str) -> str:
    """A level of the type's representative (first) original, relative to ``scenes/``."""
    return min(SCENES.glob(f"{type_folder}/*/{level}.json")).relative_to(SCENES).as_posix()


ROADSIDE = ["00_clean/05_t_junction_urban.json", "00_clean/07_straight_tunnel_approach.json",
            _representative("30_shadow/wire_shadow", "05_level5")]
TRAFFIC = [_representative(f"20_traffic/{kind}", "05_level5") for kind in ("vehicle", "bicycle", "pedestrian")]


@pytest.fixture(scope="module")
def exports(tmp_path_factory) -> dict[str, tuple[ET.Element, ET.Element]]:
    """(road.xodr root, scenario.xosc root) of each case these tests read."""
    out = {}
    for name in sorted(set(JUNCTIONS + ROADSIDE + TRAFFIC)):
        folder = tmp_path_factory.mktemp(name.replace("/", "_").removesuffix(".json"))
        xodr, xosc = write_interchange(load_case(SCENES / name), folder, openscenario=True)
        out[name] = (ET.parse(xodr).getroot(), ET.parse(xosc).getroot())
    return out


def _connecting(root: ET.Element) -> list[ET.Element]:
    return [road for road in root.findall("road") if road.get("junction") != "-1"]


def _pose(geometry: ET.Element, ds: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """x, y, heading at ``ds`` along one line or arc geometry."""
    x0, y0, h0 = (float(geometry.attrib[key]) for key in ("x", "y", "hdg"))
    shape = geometry[0]
    k = float(shape.attrib["curvature"]) if shape.tag == "arc" else 0.0
    heading = h0 + k * ds
    if k == 0.0:
        return x0 + ds * math.cos(h0), y0 + ds * math.sin(h0), heading
    return x0 + (np.sin(heading) - math.sin(h0)) / k, y0 - (np.cos(heading) - math.cos(h0)) / k, heading


def _lane_offsets(road: ET.Element) -> dict[int, float]:
    """t of each lane's centre line (constant widths)."""
    section = road.find("lanes/laneSection")
    assert section is not None
    offsets = {}
    for side, sign in (("left", 1.0), ("right", -1.0)):
        lanes = sorted(section.findall(f"{side}/lane"), key=lambda lane: abs(int(lane.attrib["id"])))
        edge = 0.0
        for lane in lanes:
            width = float(lane.find("width").attrib["a"])  # type: ignore[union-attr]  # every lane has a width
            offsets[int(lane.attrib["id"])] = sign * (edge + width / 2)
            edge += width
    return offsets


@pytest.mark.parametrize("name", JUNCTIONS)
def test_connecting_roads_are_lines_and_arcs_wide_enough_for_their_lanes(exports, name):
    root, _ = exports[name]
    roads = _connecting(root)
    assert len(roads) == (3 if "t_junction" in name else 6)
    for road in roads:
        reach = max(abs(t) for t in _lane_offsets(road).values()) + 3.5 / 2
        for geometry in road.find("planView"):
            assert geometry[0].tag in ("line", "arc")
            if geometry[0].tag == "arc":
                assert 1.0 / abs(float(geometry[0].get("curvature"))) >= reach + 1.0


@pytest.mark.parametrize("name", JUNCTIONS)
def test_every_junction_lane_advances_without_folding_back(exports, name):
    root, _ = exports[name]
    for road in _connecting(root):
        geometry = road.find("planView")[0]
        ds = np.linspace(0.0, float(geometry.get("length")), 47)
        x, y, heading = _pose(geometry, ds)
        for t in _lane_offsets(road).values():
            px, py = x - t * np.sin(heading), y + t * np.cos(heading)
            step = np.diff(px) * np.cos(heading[:-1]) + np.diff(py) * np.sin(heading[:-1])
            assert np.all(step > 0), (road.get("id"), t)


@pytest.mark.parametrize("name", JUNCTIONS)
def test_each_connecting_road_is_one_connection_joined_to_its_ends(exports, name):
    root, _ = exports[name]
    connections = root.findall("junction/connection")
    roads = {road.get("id"): road for road in root.findall("road")}
    assert sorted(c.get("connectingRoad") for c in connections) == sorted(r.get("id") for r in _connecting(root))
    ends = {}
    for road in roads.values():  # the pose of each road's two ends
        geometry = road.find("planView")[-1]
        start = road.find("planView")[0]
        ends[(road.get("id"), "start")] = (float(start.get("x")), float(start.get("y")))
        x, y, _ = _pose(geometry, np.array([float(geometry.get("length"))]))
        ends[(road.get("id"), "end")] = (float(x[0]), float(y[0]))
    for connection in connections:
        road = roads[connection.get("connectingRoad")]
        link = road.find("link")
        predecessor, successor = link.find("predecessor"), link.find("successor")
        assert predecessor.get("elementId") == connection.get("incomingRoad")
        for element, end in ((predecessor, "start"), (successor, "end")):
            other = ends[(element.get("elementId"), element.get("contactPoint"))]
            assert math.dist(other, ends[(road.get("id"), end)]) < 0.01
        lanes = {int(lane.get("id")) for lane in road.findall("lanes/laneSection/*/lane")}
        assert {int(link.get("to")) for link in connection.findall("laneLink")} == lanes - {0}


@pytest.mark.parametrize("name", JUNCTIONS)
def test_connecting_road_marks_follow_the_case(exports, name):
    root, _ = exports[name]
    case = load_case(SCENES / name)
    center = case.road.markings[case.road.lanes_per_direction]
    mark_type, color, _ = MARK_TYPES[center.type]
    for road in _connecting(root):
        mark = road.find("lanes/laneSection/center/lane/roadMark")
        if road.get("id") == str(THROUGH_ROAD_ID):
            assert (mark.get("type"), mark.get("color")) == (mark_type.replace("_", " "), color)
        else:
            assert all(m.get("type") == "none" for m in road.findall("lanes/laneSection/*/lane/roadMark"))


def test_junction_roads_start_the_turning_radius_from_the_center(exports):
    name = JUNCTIONS[0]
    root, _ = exports[name]
    case = load_case(SCENES / name)
    radius = junction_radius(compile_scene(case).network)
    incoming = next(road for road in root.findall("road") if road.get("id") == "1")
    assert float(incoming.get("length")) == pytest.approx(case.road.junction_s - radius)
    assert root.find("junction").get("id") == str(JUNCTION_ID)


@pytest.mark.parametrize("name", ROADSIDE)
def test_objects_lie_on_their_road_and_off_the_carriageway(exports, name):
    root, _ = exports[name]
    half_width = compile_scene(load_case(SCENES / name)).network.main.half_width
    objects = 0
    for road in root.findall("road"):
        length = float(road.get("length"))
        for obj in road.findall("objects/object"):
            objects += 1
            repeat = obj.find("repeat")
            s0 = float(obj.get("s")) - (0.0 if repeat is not None else float(obj.get("length")) / 2)
            s1 = s0 + (float(repeat.get("length")) if repeat is not None else float(obj.get("length")))
            assert -0.01 <= s0 and s1 <= length + 0.01, obj.get("name")
            t, width = float(obj.get("t")), float(obj.get("width"))
            if float(obj.get("zOffset")) < CLEARANCE_M:  # standing on the ground: beside the carriageway
                assert abs(t) - width / 2 >= half_width - 0.3, (obj.get("name"), t, width)
            assert obj.get("subtype") is None and "None" not in obj.attrib.values()
    assert objects > 10


def test_street_lamps_and_utility_poles_are_written_with_their_footing(exports):
    for name in ("00_clean/05_t_junction_urban.json", ROADSIDE[2]):
        root, _ = exports[name]
        poles = [obj for obj in root.iter("object") if obj.get("type") in ("pole", "streetLamp")]
        assert poles
        for pole in poles:
            assert float(pole.get("width")) < 0.8 and float(pole.get("length")) < 0.8, pole.attrib
            signal = (pole.get("name") or "").startswith("traffic signal")  # a signal head on a 3.8 m pole
            assert float(pole.get("height")) > (3.0 if signal else 5.0), pole.attrib


def test_the_tunnel_portal_leaves_the_road_open(exports):
    root, _ = exports["00_clean/07_straight_tunnel_approach.json"]
    portal = [obj for obj in root.iter("object") if "portal" in (obj.get("name") or "")]
    over = [obj for obj in portal if abs(float(obj.get("t"))) < 7.0]
    assert len(portal) >= 3 and over
    assert all(float(obj.get("zOffset")) >= CLEARANCE_M for obj in over)


def test_exports_are_byte_identical_and_undated(tmp_path):
    case = load_case(SCENES / JUNCTIONS[0])
    first = write_interchange(case, tmp_path / "a", openscenario=True)
    second = write_interchange(case, tmp_path / "b", openscenario=True)
    for a, b in zip(first, second, strict=True):
        assert a.read_bytes() == b.read_bytes()
    assert ET.parse(first[0]).getroot().find("header").get("date") is None


@pytest.mark.parametrize("name", TRAFFIC)
def test_the_scenario_has_one_ego_and_blueprints_by_kind(exports, name):
    _, root = exports[name]
    objects = root.findall("Entities/ScenarioObject")
    egos = [o for o in objects if o.find(".//Property[@name='type'][@value='ego_vehicle']") is not None]
    assert [o.get("name") for o in egos] == [EGO_NAME]
    scene = compile_scene(load_case(SCENES / name))
    by_name = {p.name: p for p in participants(scene)}
    for obj in objects:
        if obj.get("name") == EGO_NAME:
            continue
        participant = by_name[obj.get("name")]
        vehicle = obj.find("Vehicle")
        if participant.kind == "pedestrian":
            assert obj.find("Pedestrian").get("model") == MODELS["pedestrian"]
            continue
        assert vehicle.get("name") == MODELS[participant.category]
        assert vehicle.get("vehicleCategory") == participant.category
    if "vehicle" in name:
        assert {p.category for p in by_name.values()} >= {"car", "truck"}


def test_vehicle_categories_by_size():
    assert category("vehicle", 8.0, 3.4) == "truck"
    assert category("vehicle", 5.2, 2.3) == "van"
    assert category("vehicle", 4.5, 1.45) == "car"
    assert category("bicycle", 1.8, 1.7) == "bicycle"


@pytest.mark.parametrize("name", TRAFFIC[1:])
def test_cyclists_and_pedestrians_face_as_placed(exports, name):
    _, root = exports[name]
    scene = compile_scene(load_case(SCENES / name))
    meshes = [m for m in scene.meshes if m.source >= 0 and m.kind in ("bicycle", "pedestrian")]
    assert meshes and all(m.heading is not None for m in meshes)
    placed = {p.name: p.heading for p in participants(scene)}
    expected = dict(zip(placed, (m.heading for m in meshes)))
    for private in root.findall(".//Init/Actions/Private"):
        position = private.find(".//TeleportAction/Position/WorldPosition")
        if private.get("entityRef") in expected:
            h = float(position.get("h"))
            assert abs(math.remainder(h - expected[private.get("entityRef")], 2 * math.pi)) < math.radians(1)


@pytest.mark.parametrize("name", TRAFFIC[:1] + JUNCTIONS[:1])
def test_the_sun_agrees_with_the_case_and_the_carla_script(exports, name, load_script):
    _, root = exports[name]
    case = load_case(SCENES / name)
    sun = root.find(".//Environment/Weather/Sun")
    azimuth = math.degrees(float(sun.get("azimuth")))
    assert abs(math.remainder(math.radians(azimuth - (90.0 - case.sun.azimuth)), 2 * math.pi)) < math.radians(1)
    carla_azimuth = load_script("scripts/carla_run.py").carla_sun_azimuth(case.sun.azimuth)
    assert abs(math.remainder(math.radians(azimuth - carla_azimuth), 2 * math.pi)) < math.radians(1)
    intensity = float(sun.get("intensity"))
    assert 0.0 <= intensity <= 1.0  # scenario_runner: cloudiness = 100 - 100 x intensity
    assert 100.0 - 100.0 * intensity == pytest.approx(case.weather.cloudiness)


def test_the_route_names_the_road_through_the_junction(exports):
    _, root = exports[JUNCTIONS[0]]
    roads = [int(p.get("roadId")) for p in root.iter("LanePosition")]
    assert roads == [1, THROUGH_ROAD_ID, 2]


def test_independent_readers_accept_the_exports_when_installed(exports, tmp_path):
    """The OpenDRIVE 1.6 and OpenSCENARIO 1.0 XSDs shipped with ASAM's Quality Checker (not a project dependency:
    it pins older numpy and lxml) validate every export here."""
    xmlschema = pytest.importorskip("xmlschema")
    qc_opendrive = pytest.importorskip("qc_opendrive")
    qc_openscenario = pytest.importorskip("qc_openscenario")
    odr = xmlschema.XMLSchema(str(Path(qc_opendrive.__file__).parent / "schema/1.6.1/opendrive_16_core.xsd"))
    osc = xmlschema.XMLSchema(str(Path(qc_openscenario.__file__).parent / "schema/1.0.0/OpenSCENARIO.xsd"))
    for xodr_root, xosc_root in exports.values():
        assert not list(odr.iter_errors(xodr_root))
        assert not list(osc.iter_errors(xosc_root))


def test_a_straight_grade_is_one_elevation_record():
    from lanevil_core.interchange.opendrive import elevation_records

    case = load_case(SCENES / "00_clean/03_uphill_highway.json")
    records = elevation_records(compile_scene(case).network.main.line)
    for previous, record in zip(records, records[1:]):
        straight = previous[3] == record[3] == previous[4] == record[4] == 0.0
        assert not (straight and record[2] == pytest.approx(previous[2], abs=1e-9))
