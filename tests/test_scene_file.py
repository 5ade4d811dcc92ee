"""Scene files (affordplan.app.scene_file): the shipped examples, fields named when they are wrong, files on disk."""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path

import pytest

from affordplan.app.scene_file import DEMO_SCENE, demo_scene, load_scene, parse_scene
from affordplan.errors import InputError, MeshError

SCENES = Path(__file__).parents[1] / "examples" / "scenes"


def test_example_json_scene_is_the_demo_scene():
    scene = load_scene(SCENES / "mug_wall.json")
    assert scene == demo_scene()
    assert scene.name == "mug_wall" and scene.object == "mug"
    assert scene.start == {"resting_state": 0, "xy": (0.45, -0.05), "yaw": pytest.approx(math.radians(29.0))}
    assert scene.goal.resting_state == 1 and scene.goal.yaw == pytest.approx(math.pi / 2)
    assert [b.center for b in scene.obstacles] == [(0.6, -0.21), (0.6, 0.21)]


def test_yaml_scenes_parse_with_degrees_and_tolerances():
    corridor = load_scene(SCENES / "box_corridor.yaml")
    assert corridor.object == "lunch_box"
    assert corridor.goal.yaw == pytest.approx(math.pi) and corridor.goal.yaw_tol == pytest.approx(math.radians(15))
    assert corridor.start["yaw"] == 0.0 and len(corridor.obstacles) == 2
    assert not corridor.goal.yaw_symmetric  # the labelled box's two ends differ
    die = load_scene(SCENES / "die_two_blocks.yaml")
    assert die.goal.resting_state == 2 and die.goal.yaw == pytest.approx(math.radians(30))
    assert not die.goal.yaw_symmetric and load_scene(SCENES / "mug_wall.json").goal.yaw_symmetric  # the default
    # a scene survives a round trip through its plain-data form
    assert parse_scene(json.loads(json.dumps(die.as_dict()))) == die


def _mutated(path: tuple, value):
    data = copy.deepcopy(DEMO_SCENE)
    d = data
    for key in path[:-1]:
        d = d[key]
    if value is _DELETE:
        del d[path[-1]]
    else:
        d[path[-1]] = value
    return data


_DELETE = object()


@pytest.mark.parametrize("path, value, error, words", [
    (("goal", "xy"), [0.69], InputError, "goal.xy must be a list of 2 numbers"),
    (("goal", "xy"), [0.69, "a"], InputError, "goal.xy[1] must be a finite number"),
    (("goal", "xy_tol"), 0.0, InputError, "goal.xy_tol must be positive"),
    (("goal", "yaw"), 1.0, InputError, "give yaw (radians) or yaw_deg (degrees), not both"),
    (("goal", "resting_state"), -1, InputError, "goal.resting_state must be a resting-state index"),
    (("goal", "colour"), "red", InputError, "goal: unknown field(s) ['colour']"),
    (("goal", "yaw_symmetric"), "no", InputError, "goal.yaw_symmetric must be true or false"),
    (("start", "xy"), _DELETE, InputError, "start: missing field 'xy'"),
    (("start", "resting_state"), 1.5, InputError, "start.resting_state must be a resting-state index"),
    (("obstacles",), {"center": [0.6, 0.0]}, InputError, "obstacles must be a list"),
    (("obstacles", 1, "size"), [0.02, -0.2, 0.1], InputError, "obstacles[1].size must be positive"),
    (("obstacles", 0, "centre"), [0.6, 0.0], InputError, "obstacles[0]: unknown field(s) ['centre']"),
    (("goal",), _DELETE, InputError, "missing field 'goal'"),
    (("object",), 3, InputError, "object must be a catalogue name or a mesh path"),
    (("obstacle",), [], InputError, "unknown field(s) ['obstacle']"),
])
def test_bad_scene_fields_are_named(path, value, error, words):
    with pytest.raises(error) as info:
        parse_scene(_mutated(path, value), source="s.json")
    assert str(info.value).startswith("s.json: ") and words in str(info.value)


def test_resting_states_are_checked_against_the_object():
    scene = parse_scene(_mutated(("goal", "resting_state"), 7), source="s.json")
    with pytest.raises(InputError, match=r"s.json: goal.resting_state: mug has 3 resting states"):
        scene.load_object()
    with pytest.raises(MeshError, match="s.json: object: unknown object 'teapot'"):
        parse_scene(_mutated(("object",), "teapot"), source="s.json").load_object()


def test_scene_files_on_disk(tmp_path):
    with pytest.raises(InputError, match="does not exist"):
        load_scene(tmp_path / "missing.json")
    bad = tmp_path / "bad.json"
    bad.write_text("{\"object\": \"mug\",")
    with pytest.raises(InputError, match="bad.json: not valid JSON"):
        load_scene(bad)
    yml = tmp_path / "bad.yaml"
    yml.write_text("object: [mug\n")
    with pytest.raises(InputError, match="bad.yaml: not valid YAML"):
        load_scene(yml)
    txt = tmp_path / "scene.txt"
    txt.write_text("{}")
    with pytest.raises(InputError, match="must end in .json, .yaml or .yml"):
        load_scene(txt)
    # a relative mesh path is resolved against the scene file's folder; the name defaults to the stem
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "part.stl").write_text("solid part\nendsolid part\n")
    data = _mutated(("object",), "meshes/part.stl")
    del data["name"]
    (tmp_path / "part_scene.json").write_text(json.dumps(data))
    scene = load_scene(tmp_path / "part_scene.json")
    assert Path(scene.object) == tmp_path / "meshes" / "part.stl" and scene.name == "part_scene"

