"""The weights file format: tensors and plain metadata, loaded without running any code.

Every file affordplan writes (a policy, a success model, a training checkpoint) is a ``torch.save`` of::

    {"meta": {"format": "affordplan-weights", "format_version": 1, "skill": "push", "kind": "policy",
              "sensor": "cameras", "n_points": 256, "version": "0.24.0", ...},
     "payload": {...tensors, numbers, strings, lists and dicts...}}

and is read back with ``torch.load(..., weights_only=True)``: torch's restricted unpickler, which builds tensors and
plain containers only, so a file made to run code when unpickled is refused, never executed. NumPy arrays in a payload
are stored as tensors (:func:`to_storable`). A file is checked against what the caller asks for (skill, kind), by its
metadata, before any of its tensors reach a model, so a roll file given as push weights is refused with both names.

Files written before this format (a bare policy ``state_dict``, or ``{"model": ..., "info": ...}``) carry no
metadata; :func:`load` refuses them, and ``python -m primitives.weights_file stamp FILE --skill S --kind K`` adds it
(after loading the file safely).
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import tempfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import torch

from affordplan.errors import InputError, WeightsError
from affordplan.log import cli_logging
from primitives.params import SKILLS

FORMAT = "affordplan-weights"
FORMAT_VERSION = 1
KINDS = ("policy", "success", "checkpoint", "ranker")
# for messages
_WHAT = {"policy": "weights", "success": "success model", "checkpoint": "checkpoint", "ranker": "option ranker"}
SHIPPED_DIR = Path(__file__).parent / "weights"  # the shipped weights: the one place that knows where they live


RATINGS = ("success", "frames", "searched")  # a policy's ratings: goal-frame model, frame calibration, searched model


def rating_name(skill: str, rating: str) -> str:
    """The file name of one of ``skill``'s :data:`RATINGS`."""
    names = {"success": f"{skill}_success.pt", "frames": f"{skill}_frames.json",
             "searched": f"{skill}_success_searched.pt"}
    if rating not in names:
        raise InputError(f"unknown rating {rating!r}; one of {RATINGS}")
    return names[rating]


def sensor_policy(skill: str, sensor: str | None, weights_dir: str | os.PathLike | None = None) -> Path | None:
    """``{weights_dir}/{sensor}/{skill}.pt`` where that folder holds a policy of its own (one chosen for ``sensor``'s
    clouds, its ratings beside it), else ``None`` (also for ``sensor=None``). ``weights_dir``: by default the
    shipped weights."""
    base = Path(weights_dir) if weights_dir is not None else SHIPPED_DIR
    if sensor is not None and (path := base / sensor / f"{skill}.pt").is_file():
        return path
    return None


def policy_path(skill: str, sensor: str | None = None, weights_dir: str | os.PathLike | None = None) -> Path:
    """The policy that acts on ``sensor``'s clouds: :func:`sensor_policy` where there is one, else
    ``{weights_dir}/{skill}.pt`` (whether or not it exists). ``weights_dir``: by default the shipped weights."""
    base = Path(weights_dir) if weights_dir is not None else SHIPPED_DIR
    return sensor_policy(skill, sensor, base) or base / f"{skill}.pt"


def rating_path(skill: str, rating: str, sensor: str | None = None, weights_dir: str | os.PathLike | None = None,
                *, trained_on: str | None = None) -> Path:
    """The file of ``skill``'s ``rating`` (:data:`RATINGS`) for ``sensor``'s clouds.

    A policy's ratings beside it (``{weights_dir}/{skill}_success.pt``, ``_frames.json``, ``_success_searched.pt``)
    fit the sensor it was trained on. ``{weights_dir}/{sensor}/`` may hold any of them refitted to another sensor's
    clouds: that file where it exists and the policy was trained on another sensor, else the one beside the policy
    (whether or not it exists). Where ``{weights_dir}/{sensor}/`` holds a policy of its own (:func:`policy_path`),
    its ratings are the ones in that folder (whether or not they exist): the others were fitted to another policy.
    ``weights_dir``: by default the shipped weights. ``trained_on``: the policy's sensor where the caller has it (a
    loaded policy's ``sensor``); otherwise it is read from the policy's file when needed.
    """
    base = Path(weights_dir) if weights_dir is not None else SHIPPED_DIR
    name = rating_name(skill, rating)
    if sensor_policy(skill, sensor, base) is not None:
        return base / sensor / name
    if sensor is not None and (base / sensor / name).exists():
        own = trained_on if trained_on is not None else policy_sensor(skill, base)
        if own != sensor:
            return base / sensor / name
    return base / name


def rated_for(skill: str, sensor: str, weights_dir: str | os.PathLike | None = None, *,
              trained_on: str | None = None) -> bool:
    """Whether any of ``skill``'s ratings was refitted to ``sensor``'s clouds, or a policy of its own chosen for them
    (:func:`rating_path`; ``trained_on`` as there)."""
    base = Path(weights_dir) if weights_dir is not None else SHIPPED_DIR
    if sensor_policy(skill, sensor, base) is not None:
        return True
    if not any((base / sensor / rating_name(skill, rating)).exists() for rating in RATINGS):
        return False
    own = trained_on if trained_on is not None else policy_sensor(skill, base)
    return any(rating_path(skill, rating, sensor, base, trained_on=own).parent != base for rating in RATINGS)


def policy_sensor(skill: str, weights_dir: str | os.PathLike | None = None) -> str | None:
    """The sensor whose clouds the policy ``{weights_dir}/{skill}.pt`` was trained on (its metadata; ``"surface"``
    for files stamped without one), or ``None`` where the folder holds no readable policy of ``skill``."""
    path = (Path(weights_dir) if weights_dir is not None else SHIPPED_DIR) / f"{skill}.pt"
    if not path.is_file():
        return None
    try:
        _, meta = load(path, kind="policy", skill=skill)
    except WeightsError:
        return None
    return str(meta.get("sensor", "surface"))


def to_storable(value: Any) -> Any:
    """``value`` with every NumPy array and scalar turned into a tensor or a Python number (recursively)."""
    if isinstance(value, np.ndarray):
        return torch.from_numpy(np.ascontiguousarray(value))
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, Mapping):
        return {k: to_storable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return type(value)(to_storable(v) for v in value)
    return value


def make_meta(skill: str, kind: str, **extra: Any) -> dict:
    """The metadata of a file of ``kind`` for ``skill``; ``extra`` (plain values) is kept alongside."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        release = version("affordplan")
    except PackageNotFoundError:  # run from a source tree that was never installed
        release = "unknown"
    return dict(format=FORMAT, format_version=FORMAT_VERSION, skill=skill, kind=kind, version=release,
                **to_storable(extra))


def save(path: str | os.PathLike, payload: Mapping, meta: Mapping) -> None:
    """Write ``{"meta": meta, "payload": payload}`` atomically: to a temporary file in the same folder, fsynced, then
    renamed over ``path``; temporary files a killed earlier write left behind are removed."""
    if meta.get("format") != FORMAT or meta.get("kind") not in KINDS:
        raise WeightsError(f"not affordplan weights metadata: {dict(meta)!r:.200}")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    for stale in path.parent.glob(f"{path.name}*.tmp"):
        stale.unlink(missing_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name, suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as f:
            torch.save(dict(meta=dict(meta), payload=to_storable(dict(payload))), f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def read(path: str | os.PathLike, what: str = "weights") -> Any:
    """Whatever ``path`` holds, through torch's restricted unpickler (tensors and plain containers only).

    Raises:
        WeightsError: no such file, a folder, a damaged or truncated file, or one that would run code to load.
    """
    path = Path(path)
    if not path.exists():
        raise WeightsError(f"no {what} at {path}")
    if path.is_dir():
        raise WeightsError(f"{path} is a folder, not a {what} file")
    try:
        return torch.load(path, map_location="cpu", weights_only=True)
    except Exception as exc:  # torch raises several types; UnpicklingError for anything beyond tensors
        text = str(exc).strip().splitlines()
        first = text[0][:200] if text else type(exc).__name__
        if "Unsupported global" in str(exc) or "GLOBAL" in str(exc):  # an object torch would have to construct
            found = re.search(r"GLOBAL ([\w.]+)", str(exc))
            what = f" ({found.group(1)})" if found else ""
            raise WeightsError(f"{path} is not a safe weights file: it holds objects other than tensors and plain "
                               f"values{what}, which loading could run as code, so it was not loaded") from None
        raise WeightsError(f"{what} {path} is damaged or truncated ({type(exc).__name__}: {first})") from exc


def load(path: str | os.PathLike, *, kind: str, skill: str | None = None) -> tuple[dict, dict]:
    """``(payload, meta)`` of the affordplan weights file ``path``, checked to be a ``kind`` file for ``skill``.

    Raises:
        WeightsError: see :func:`read`; no affordplan metadata; another kind, skill or format version.
    """
    content = read(path, _WHAT.get(kind, kind))
    meta = content.get("meta") if isinstance(content, dict) else None
    if not isinstance(meta, dict) or meta.get("format") != FORMAT or not isinstance(content.get("payload"), dict):
        raise WeightsError(f"{path} carries no affordplan weights metadata (written by an older release or another "
                           f"program); if it is yours, add it with: python -m primitives.weights_file stamp {path} "
                           f"--skill SKILL --kind {kind}")
    if meta.get("format_version") != FORMAT_VERSION:
        raise WeightsError(f"{path} is format version {meta.get('format_version')!r:.40}; this release reads "
                           f"{FORMAT_VERSION}")
    if meta.get("kind") != kind:
        raise WeightsError(f"{path} holds a {str(meta.get('kind'))[:40]} file, not a {kind}")
    if skill is not None and meta.get("skill") != skill:
        raise WeightsError(f"{path} is for the {str(meta.get('skill'))[:40]} skill, not {skill}")
    return content["payload"], meta


def stamp(path: str | os.PathLike, *, skill: str, kind: str, sensor: str = "surface") -> None:
    """Rewrite an older (metadata-less) file in this format, after loading it safely: a policy's bare
    ``state_dict`` becomes ``{"model": state_dict}``; a success model's ``{"model", "info"}`` is kept."""
    if skill not in SKILLS or kind not in ("policy", "success"):
        raise WeightsError(f"stamp takes a skill in {SKILLS} and a kind 'policy' or 'success'")
    content = read(path)
    if isinstance(content, dict) and content.get("meta", {}).get("format") == FORMAT:
        raise WeightsError(f"{path} already carries affordplan metadata")
    if kind == "policy":
        payload = dict(model=content.get("model", content) if isinstance(content, dict) else content)
    else:
        if not isinstance(content, dict) or "model" not in content:
            raise WeightsError(f"{path} is not a success model (no 'model' entry)")
        payload = dict(content)
    save(path, payload, make_meta(skill, kind, sensor=sensor))


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m primitives.weights_file",
                                description="Inspect affordplan weights files, or stamp an older one with metadata.")
    sub = p.add_subparsers(dest="command", required=True)
    show = sub.add_parser("show", help="print a file's metadata")
    show.add_argument("path", type=Path)
    st = sub.add_parser("stamp", help="add metadata to a file written before the format had it")
    st.add_argument("path", type=Path)
    st.add_argument("--skill", required=True, choices=SKILLS)
    st.add_argument("--kind", required=True, choices=("policy", "success"))
    st.add_argument("--sensor", default="surface", choices=("surface", "cameras"),
                    help="the clouds it was trained on (default: %(default)s, what every release before 0.24 used)")
    args = p.parse_args(argv)
    cli_logging()
    try:
        if args.command == "show":
            content = read(args.path)
            meta = content.get("meta") if isinstance(content, dict) else None
            print(meta if meta else "no affordplan metadata")
        else:
            stamp(args.path, skill=args.skill, kind=args.kind, sensor=args.sensor)
    except WeightsError as exc:
        print(f"{p.prog}: error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
