"""Scenario interchange: the written OpenDRIVE re-parsed against the case, the OpenSCENARIO names every entity."""

from __future__ import annotations

import math
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from lanevil_core import cli
from lanevil_core.case import load_case, save_case
from lanevil_core.interchange import write_interchange
from lanevil_core.interchange.opendrive import MARK_TYPES, junction_radius, opendrive, xodr_text
from lanevil_core.interchange.openscenario import EGO_NAME, participants
from lanevil_core.pipeline.compile import compile_scene

SCENES = Path(__file__).resolve().parents[2] / "scenes"
CLEAN = sorted((SCENES / "00_clean").glob("*.json"))
CM = 0.01


def _geometry_end(geometry: ET.Element) -> tuple[float, float, float]:
    """End pose of one planView geometry, integrated here from its own attributes (independent of the writer)."""
    x, y, hdg, length = (float(geometry.attrib[key]) for key in ("x", "y", "hdg", "length"))
    kind = geometry[0]
    if kind.tag == "line":
        k0 = k1 = 0.0
    elif kind.tag == "arc":
        k0 = k1 = float(kind.attrib["curvature"])
    else:
        assert kind.tag == "spiral"
        k0, k1 = float(kind.attrib["curvStart"]), float(kind.attrib["curvEnd"])
    u = np.linspace(0.0, length, 20001)
    heading = hdg + k0 * u + 0.5 * (k1 - k0) / length * u**2
    du = np.diff(u)
    mid = 0.5 * (heading[1:] + heading[:-1])
    return x + float(np.sum(du * np.cos(mid))), y + float(np.sum(du * np.sin(mid))), float(heading[-1])


def _main_roads(root: ET.Element) -> list[ET.Element]:
    return [road for road in root.findall("road") if road.get("junction") == "-1" and
            (road.get("name") or "").startswith("main")]


@pytest.fixture(scope="module")
def exported() -> dict[str, tuple[Path, ET.Element]]:
    """The road of every clean case (without roadside objects, which ``write_interchange`` adds)."""
    return {path.stem: (path, ET.fromstring(xodr_text(opendrive(load_case(path))))) for path in CLEAN}


@pytest.mark.parametrize("path", CLEAN, ids=lambda p: p.stem)
def test_opendrive_matches_the_case_within_a_centimeter(exported, path):
    case = load_case(path)
    network = compile_scene(case).network
    _, root = exported[path.stem]
    header = root.find("header")
    assert header.get("revMajor") == "1" and int(header.get("revMinor")) >= 6
    mains = _main_roads(root)
    reach = junction_radius(network) if len(mains) == 2 else 0.0
    assert sum(float(road.get("length")) for road in mains) + 2 * reach == pytest.approx(case.road.length, abs=CM)
    # The reference line: every geometry starts where the case's line is, and the last one ends where it ends.
    line = network.main.line
    s_offset = 0.0
    for road in mains:
        for geometry in road.find("planView"):
            s_road = s_offset + float(geometry.get("s"))
            p_world = line.to_world(s_road, 0.0)
            assert math.hypot(float(geometry.get("x")) - p_world[0], float(geometry.get("y")) - p_world[1]) < CM
        s_offset += float(road.get("length")) + 2 * reach
    x_end, y_end, heading_end = _geometry_end(mains[-1].find("planView")[-1])
    p_end = line.to_world(line.length, 0.0)
    assert math.hypot(x_end - p_end[0], y_end - p_end[1]) < CM
    assert abs(math.remainder(heading_end - float(line.heading_at(line.length)), 2 * math.pi)) < 1e-3
    # Elevation: the cubic records reproduce the road's height.
    records = [[float(e.get(key)) for key in "sabcd"] for e in mains[0].find("elevationProfile")]
    for s_road in np.linspace(0.0, float(mains[0].get("length")) - 0.01, 37):
        s0, a, b, c, d = max((r for r in records if r[0] <= s_road), key=lambda r: r[0])
        ds = s_road - s0
        assert a + b * ds + c * ds**2 + d * ds**3 == pytest.approx(float(line.z_at(s_road)), abs=CM)
    # Lanes: n each way with the case's width; every boundary's mark with its type, colour, width and dashes.
    section = mains[0].find("lanes/laneSection")
    n, markings = case.road.lanes_per_direction, case.road.markings
    left = sorted(section.findall("left/lane"), key=lambda lane: int(lane.get("id")))
    right = sorted(section.findall("right/lane"), key=lambda lane: -int(lane.get("id")))
    assert [int(lane.get("id")) for lane in left] == list(range(1, n + 1))
    assert [int(lane.get("id")) for lane in right] == list(range(-1, -n - 1, -1))
    for lane in left + right:
        assert float(lane.find("width").get("a")) == pytest.approx(case.road.lane_width, abs=CM)
    lanes_by_boundary = [*reversed(left), section.find("center/lane"), *right]  # boundary k, left to right
    for lane, marking in zip(lanes_by_boundary, markings, strict=True):
        mark = lane.find("roadMark")
        mark_type, color, lines = MARK_TYPES[marking.type]
        assert mark.get("type") == mark_type.replace("_", " ") and mark.get("color") == color
        assert float(mark.get("width")) == pytest.approx(marking.width, abs=CM)
        written = mark.findall("type/line")
        assert len(written) == len(lines)
        for line_element, kind in zip(written, lines):
            if kind == "broken":
                assert float(line_element.get("length")) == pytest.approx(marking.dash, abs=CM)
                assert float(line_element.get("space")) == pytest.approx(marking.gap, abs=CM)


def test_junction_cases_have_arms_and_a_junction(exported):
    _, root = exported["06_crossroad_suburban"]
    assert len(root.findall("junction")) == 1
    arms = [road for road in root.findall("road") if (road.get("name") or "").startswith("arm")]
    assert len(arms) == 2
    connecting = [road for road in root.findall("road") if road.get("junction") != "-1"]
    assert len(connecting) >= 6


@pytest.mark.parametrize(("pavement", "surface"), [("asphalt", "asphalt"), ("concrete", "concrete")])
def test_every_lane_carries_the_pavement_as_its_material(make_case, pavement, surface):
    root = ET.fromstring(xodr_text(opendrive(make_case(road={"pavement": pavement}))))
    lanes = [lane for lane in root.iter("lane") if lane.get("id") != "0"]
    assert lanes and all(lane.find("material").get("surface") == surface for lane in lanes)
    assert all(0.5 < float(lane.find("material").get("friction")) <= 1.0 for lane in lanes)


def test_roadside_objects_are_written(tmp_path):
    case = load_case(SCENES / "10_road_damage" / "guard_rail" / "00_bend_highway_noon" / "05_level5.json")
    xodr, = write_interchange(case, tmp_path)
    objects = ET.parse(xodr).getroot().findall("road/objects/object")
    types = {obj.get("type") for obj in objects}
    assert "barrier" in types
    rails = [obj for obj in objects if "guard" in (obj.get("name") or "")]
    assert rails and all(obj.find("repeat") is not None for obj in rails)


def test_openscenario_names_every_entity(tmp_path):
    from scenariogeneration import xosc

    case = load_case(SCENES / "20_traffic" / "pedestrian" / "00_crossroad_urban_noon" / "03_level3.json")
    _, path = write_interchange(case, tmp_path, openscenario=True)
    expected = {EGO_NAME} | {p.name for p in participants(compile_scene(case))}
    assert len(expected) > 3
    parsed = xosc.ParseOpenScenario(str(path))
    names = {obj.name for obj in parsed.entities.scenario_objects}
    assert names == expected
    root = ET.parse(path).getroot()
    assert root.find("FileHeader").get("revMinor") == "0"
    assert root.find("RoadNetwork/LogicFile").get("filepath") == "road.xodr"
    sun = root.find(".//Environment/Weather/Sun")
    # Case azimuth is counter-clockwise from east; OpenSCENARIO's clockwise from north.
    assert float(sun.get("azimuth")) == pytest.approx(math.radians((90 - case.sun.azimuth) % 360))
    assert float(sun.get("elevation")) == pytest.approx(math.radians(case.sun.altitude))
    assert {p.get("entityRef") for p in root.findall(".//Private")} == expected


def test_export_command_writes_only_the_interchange_files(tmp_path, make_case):
    path = tmp_path / "case.json"
    save_case(make_case(road={"type": "bend"}), path)
    out = tmp_path / "out"
    assert cli.main(["export", str(path), "--out", str(out), "--opendrive"]) == 0
    assert sorted(p.name for p in out.iterdir()) == ["case.json", "road.xodr"]


def test_carla_script_explains_what_is_missing(tmp_path):
    script = Path(__file__).resolve().parents[2] / "scripts" / "carla_run.py"
    result = subprocess.run([sys.executable, str(script), str(tmp_path)], capture_output=True, text=True)
    assert result.returncode == 2 and "road.xodr is missing" in result.stderr


def test_core_imports_no_interchange_package_and_no_web_framework():
    code = ("import sys, lanevil_core, lanevil_core.cli, lanevil_core.drive, lanevil_core.interchange; "
            "bad = [m for m in ('scenariogeneration', 'fastapi', 'viser') if m in sys.modules]; assert not bad, bad")
    subprocess.run([sys.executable, "-c", code], check=True)
