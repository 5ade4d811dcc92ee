"""Scene files: an object, its start, a goal and box obstacles, in JSON or YAML.

A scene file is what ``affordplan plan SCENE`` reads (``affordplan demo`` runs the embedded
:data:`DEMO_SCENE`). All lengths are metres in the world frame (z up, table top at z = 0, the arm's
base at the origin, objects in x in [0.3, 0.75], |y| <= 0.3); angles are radians, or degrees in a
field whose name ends in ``_deg`` (give one or the other, not both)::

    {
      "name": "mug_wall",                                   # optional, names the outputs
      "description": "the mug on its side behind a wall",   # optional
      "object": "mug",                                      # catalogue name or mesh path
      "size": 0.05,                                         # optional: largest half-extent, metres
      "start": {"resting_state": 0, "xy": [0.45, -0.05], "yaw": 0.5},
      "goal": {"xy": [0.69, 0.0], "resting_state": 1, "yaw_deg": 90,
               "xy_tol": 0.03, "yaw_tol_deg": 15,            # yaw, resting_state, tolerances optional
               "yaw_symmetric": true},                        # optional: false when markings break symmetry
      "obstacles": [{"center": [0.6, -0.21], "size": [0.02, 0.2, 0.1], "yaw": 0.0}]
    }

A relative mesh path is resolved against the scene file's folder. Resting states are indices into
``load_object(object).resting_states`` (``affordplan render OBJECT`` shows them). Every mistake raises
an :class:`affordplan.errors.AffordplanError` whose message names the file and the field.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from affordplan.errors import AffordplanError, InputError
from affordplan.goal import Goal
from affordplan.objects.model import MESH_SUFFIXES, ObjectModel, load_object
from affordplan.world import Box

TOP_LEVEL = ("name", "description", "object", "size", "start", "goal", "obstacles")
START_FIELDS = ("resting_state", "xy", "yaw", "yaw_deg")
GOAL_FIELDS = ("xy", "yaw", "yaw_deg", "resting_state", "xy_tol", "yaw_tol", "yaw_tol_deg", "yaw_symmetric")
MAX_FILE_BYTES = 1_000_000  # a scene is a few hundred bytes; this bounds reading and parsing
MAX_DEPTH = 8  # nesting of mappings and lists; a scene needs 3

# The README's main job: the mug lies on its side behind a wall with a 22 cm gap; the plan flips it
# upright (resting state 1, opening up), pushes it through the gap and turns it to 90 deg.
DEMO_SCENE: dict[str, Any] = {
    "name": "mug_wall",
    "description": "The mug lies on its side behind a wall with a gap: flip it upright, push it through the gap "
                   "and turn it to face +y.",
    "object": "mug",
    "start": {"resting_state": 0, "xy": [0.45, -0.05], "yaw_deg": 29.0},
    "goal": {"xy": [0.69, 0.0], "resting_state": 1, "yaw_deg": 90.0},
    "obstacles": [
        {"center": [0.6, -0.21], "size": [0.02, 0.2, 0.1]},
        {"center": [0.6, 0.21], "size": [0.02, 0.2, 0.1]},
    ],
}


@dataclass(frozen=True)
class Scene:
    """A parsed scene file.

    Attributes:
        object: catalogue name or mesh path (absolute, or as given when it is a catalogue name).
        start: ``{"resting_state": i, "xy": (x, y), "yaw": rad}`` as :func:`affordplan.plan` takes it.
        goal: the :class:`affordplan.Goal`.
        obstacles: boxes standing on the table.
        size: largest half-extent of the object after normalisation, metres.
        name: a short name (the file's stem by default).
        description: free text.
        source: where it was read from (for messages).
    """

    object: str
    start: dict
    goal: Goal
    obstacles: tuple[Box, ...] = ()
    size: float = 0.05
    name: str = "scene"
    description: str = ""
    source: str = field(default="<scene>", compare=False)

    def load_object(self) -> ObjectModel:
        """Load the object and check that the start's and the goal's resting states exist for it."""
        try:
            obj = load_object(self.object, size=self.size)
        except AffordplanError as exc:
            raise type(exc)(f"{self.source}: object: {exc}") from exc
        n = len(obj.resting_states)
        for where, state in (("start.resting_state", self.start["resting_state"]),
                             ("goal.resting_state", self.goal.resting_state)):
            if state is not None and not 0 <= state < n:
                raise InputError(f"{self.source}: {where}: {obj.name} has {n} resting states (0..{n - 1}), "
                                 f"got {state} (see `affordplan render {self.object}`)")
        return obj

    def as_dict(self) -> dict:
        """The scene as plain data (radians), in the file format."""
        g = self.goal
        goal = {"xy": list(g.xy), "resting_state": g.resting_state, "yaw": g.yaw, "xy_tol": g.xy_tol,
                "yaw_tol": g.yaw_tol, "yaw_symmetric": g.yaw_symmetric}
        return {
            "name": self.name, "description": self.description, "object": self.object, "size": self.size,
            "start": {"resting_state": self.start["resting_state"], "xy": list(self.start["xy"]),
                      "yaw": self.start["yaw"]},
            "goal": {k: v for k, v in goal.items() if v is not None},
            "obstacles": [{"center": list(b.center), "size": list(b.size), "yaw": b.yaw} for b in self.obstacles],
        }


def demo_scene() -> Scene:
    """The scene ``affordplan demo`` runs (:data:`DEMO_SCENE`)."""
    return parse_scene(DEMO_SCENE, source="<demo scene>")


def load_scene(path: str | os.PathLike) -> Scene:
    """Read a scene from a ``.json``, ``.yaml`` or ``.yml`` file (YAML needs PyYAML)."""
    path = Path(path)
    if path.is_dir():
        raise InputError(f"scene file {_short(str(path))} is a folder; give a .json or .yaml file")
    if not path.is_file():
        raise InputError(f"scene file {_short(str(path))} does not exist")
    suffix = path.suffix.lower()
    if suffix not in (".json", ".yaml", ".yml"):
        raise InputError(f"{path}: a scene file must end in .json, .yaml or .yml")
    if path.stat().st_size > MAX_FILE_BYTES:
        raise InputError(f"{path}: a scene file is at most {MAX_FILE_BYTES // 1000} kB; this one is "
                         f"{path.stat().st_size // 1000} kB")
    try:
        text = path.read_bytes().decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(f"{path}: not UTF-8 text (byte {exc.start}); save the scene file as UTF-8") from None
    data = _parse_yaml(text, path) if suffix in (".yaml", ".yml") else _parse_json(text, path)
    return parse_scene(data, source=str(path), base_dir=path.parent, default_name=path.stem)


def _check_structure(text: str, path: Path) -> None:
    """Refuse YAML that could expand beyond what it shows: aliases (``*a``, each one a copy of a whole anchored
    value: nine nested levels of them make gigabytes from 400 bytes) and nesting deeper than ``MAX_DEPTH``."""
    import yaml

    depth = 0
    try:
        for event in yaml.parse(text, Loader=yaml.SafeLoader):
            if isinstance(event, yaml.AliasEvent):
                raise InputError(f"{path}: YAML aliases (*{_short(event.anchor, 20)}) are not allowed in scene files; "
                                 "write the values out")
            if isinstance(event, (yaml.MappingStartEvent, yaml.SequenceStartEvent)):
                depth += 1
                if depth > MAX_DEPTH:
                    raise InputError(f"{path}: nested deeper than {MAX_DEPTH} levels; a scene is at most {MAX_DEPTH}")
            elif isinstance(event, (yaml.MappingEndEvent, yaml.SequenceEndEvent)):
                depth -= 1
    except yaml.YAMLError as exc:
        raise InputError(f"{path}: not valid YAML: {str(exc)[:300]}") from None


def _parse_yaml(text: str, path: Path) -> Any:
    import yaml

    _check_structure(text, path)
    try:
        return yaml.safe_load(text)
    except (yaml.YAMLError, ValueError, OverflowError) as exc:
        raise InputError(f"{path}: not valid YAML: {str(exc)[:300]}") from None


def _parse_json(text: str, path: Path) -> Any:
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"{path}: not valid JSON: {str(exc)[:300]}") from None
    except (RecursionError, ValueError) as exc:  # deep nesting; a number of more than 4300 digits
        raise InputError(f"{path}: JSON too deeply nested or with an over-long number ({type(exc).__name__})") \
            from None


def _short(value: Any, limit: int = 60) -> str:
    """A description of ``value`` of at most ``limit`` characters: never format an unbounded value into a message.
    Containers are described by type and length, not expanded (a YAML alias bomb is gigabytes of repr)."""
    if isinstance(value, (list, tuple, dict, set)):
        return f"a {type(value).__name__} of {len(value)} items"
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) >= 10**30:
        return f"an integer of {len(str(abs(value)))} digits"
    text = repr(value)
    return text if len(text) <= limit else text[:limit - 3] + "..."


def parse_scene(data: Any, source: str = "<scene>", base_dir: str | os.PathLike | None = None,
                default_name: str = "scene") -> Scene:
    """Check and convert scene data (a mapping as read from JSON / YAML) into a :class:`Scene`."""
    top = _mapping(data, source, "the scene")
    _known(top, TOP_LEVEL, source, "")
    for key in ("object", "start", "goal"):
        if key not in top:
            raise InputError(f"{source}: missing field '{key}'")
    name = _text(top.get("name", default_name), source, "name")
    description = _text(top.get("description", ""), source, "description")
    obj = _object_source(top["object"], source, base_dir)
    size = _number(top.get("size", 0.05), source, "size", positive=True)
    start = _start(top["start"], source)
    goal = _goal(top["goal"], source)
    obstacles_raw = top.get("obstacles", [])
    if not isinstance(obstacles_raw, list):
        raise InputError(f"{source}: obstacles must be a list of boxes, got {type(obstacles_raw).__name__}")
    obstacles = tuple(_box(b, source, f"obstacles[{i}]") for i, b in enumerate(obstacles_raw))
    return Scene(object=obj, start=start, goal=goal, obstacles=obstacles, size=size, name=name,
                 description=description, source=source)


# ----------------------------------------------------------------------------------- fields
def _mapping(value: Any, source: str, what: str) -> Mapping:
    if not isinstance(value, Mapping):
        raise InputError(f"{source}: {what} must be a mapping of fields, got {type(value).__name__}")
    return value


def _known(d: Mapping, allowed: tuple[str, ...], source: str, prefix: str) -> None:
    unknown = sorted(str(k) for k in d if k not in allowed)
    if unknown:
        where = f"{prefix}: " if prefix else ""
        raise InputError(f"{source}: {where}unknown field(s) {str(unknown)[:200]}; expected some of "
                         f"{list(allowed)}")


def _text(value: Any, source: str, name: str) -> str:
    if not isinstance(value, str):
        raise InputError(f"{source}: {name} must be a string, got {_short(value)}")
    return value


def _number(value: Any, source: str, name: str, positive: bool = False) -> float:
    finite = not isinstance(value, bool) and isinstance(value, (int, float))
    try:
        finite = finite and math.isfinite(float(value))
    except OverflowError:  # an integer beyond a float's range
        finite = False
    if not finite:
        raise InputError(f"{source}: {name} must be a finite number, got {_short(value)}")
    if positive and value <= 0:
        raise InputError(f"{source}: {name} must be positive, got {_short(value)}")
    return float(value)


def _numbers(value: Any, n: int, source: str, name: str, unit: str) -> tuple[float, ...]:
    if not isinstance(value, (list, tuple)) or len(value) != n:
        raise InputError(f"{source}: {name} must be a list of {n} numbers ({unit}), got {_short(value)}")
    return tuple(_number(v, source, f"{name}[{i}]") for i, v in enumerate(value))


def _index(value: Any, source: str, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise InputError(f"{source}: {name} must be a resting-state index (an integer >= 0), got {_short(value)}")
    return int(value)


def _angle(d: Mapping, key: str, source: str, prefix: str, default: float | None) -> float | None:
    """``d[key]`` in radians or ``d[key + "_deg"]`` in degrees (not both); ``default`` when neither."""
    if key in d and f"{key}_deg" in d:
        raise InputError(f"{source}: {prefix}: give {key} (radians) or {key}_deg (degrees), not both")
    if f"{key}_deg" in d:
        return math.radians(_number(d[f"{key}_deg"], source, f"{prefix}.{key}_deg"))
    if key in d:
        return _number(d[key], source, f"{prefix}.{key}")
    return default


def _object_source(value: Any, source: str, base_dir) -> str:
    if not isinstance(value, str) or not value.strip():
        raise InputError(f"{source}: object must be a catalogue name or a mesh path, got {_short(value)}")
    if base_dir is not None and Path(value).suffix.lower() in MESH_SUFFIXES and not Path(value).is_absolute():
        candidate = Path(base_dir) / value
        if candidate.exists():
            return str(candidate)
    return value


def _start(value: Any, source: str) -> dict:
    d = _mapping(value, source, "start")
    _known(d, START_FIELDS, source, "start")
    if "xy" not in d:
        raise InputError(f"{source}: start: missing field 'xy' (metres)")
    return {
        "resting_state": _index(d.get("resting_state", 0), source, "start.resting_state"),
        "xy": _numbers(d["xy"], 2, source, "start.xy", "metres"),
        "yaw": _angle(d, "yaw", source, "start", 0.0),
    }


def _goal(value: Any, source: str) -> Goal:
    d = _mapping(value, source, "goal")
    _known(d, GOAL_FIELDS, source, "goal")
    if "xy" not in d:
        raise InputError(f"{source}: goal: missing field 'xy' (metres)")
    if "yaw_tol" in d and "yaw_tol_deg" in d:
        raise InputError(f"{source}: goal: give yaw_tol (radians) or yaw_tol_deg (degrees), not both")
    kwargs: dict[str, Any] = {"xy": _numbers(d["xy"], 2, source, "goal.xy", "metres"),
                              "yaw": _angle(d, "yaw", source, "goal", None)}
    if d.get("resting_state") is not None:
        kwargs["resting_state"] = _index(d["resting_state"], source, "goal.resting_state")
    if "xy_tol" in d:
        kwargs["xy_tol"] = _number(d["xy_tol"], source, "goal.xy_tol", positive=True)
    tol = _angle(d, "yaw_tol", source, "goal", None)
    if tol is not None:
        kwargs["yaw_tol"] = _number(tol, source, "goal.yaw_tol", positive=True)
    if "yaw_symmetric" in d:
        if not isinstance(d["yaw_symmetric"], bool):
            raise InputError(f"{source}: goal.yaw_symmetric must be true or false, got {_short(d['yaw_symmetric'])}")
        kwargs["yaw_symmetric"] = d["yaw_symmetric"]
    try:
        return Goal(**kwargs)
    except AffordplanError as exc:
        raise type(exc)(f"{source}: goal: {exc}") from exc


def _box(value: Any, source: str, name: str) -> Box:
    d = _mapping(value, source, name)
    try:
        return Box.from_dict(d, name)  # the core's rules, shared with affordplan.plan(obstacles=[dict, ...])
    except InputError as exc:
        raise InputError(f"{source}: {exc}") from None


__all__ = ["DEMO_SCENE", "Scene", "demo_scene", "load_scene", "parse_scene"]
