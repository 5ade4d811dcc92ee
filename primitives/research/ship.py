"""Ship a candidate set of one skill's files as the package's weights, keeping the old ones and the provenance.

    python -m primitives.research.ship push --from candidates/push_60_bf16 --keep push_0.16 --release 0.18.0
    python -m primitives.research.ship push --from DIR --keep NAME --dry-run     # print what would move, change nothing

A **candidate set** is a folder laid out like ``primitives/weights/`` (what ``--weights-dir`` runs): ``{skill}.pt``
(the policy) and ``{skill}_success.pt`` (its goal-frame success model), optionally ``{skill}_frames.json`` (the
frame search's calibration) and ``{skill}_success_searched.pt`` (the searched success model), and any other file
of the skill (``{skill}_config.json``, ``{skill}_log.csv``, ``{skill}.eval_*.json``, ``*.train.json``). A skill's
files are those named ``{skill}.*`` or ``{skill}_*``.

Shipping does, in this order, and changes nothing until every check has passed:

1. **Check** that the set loads as a skill (:func:`primitives.load_skill` with ``weights_dir``) and that its
   fitted files were fitted with *its* files: each run path their ``info`` names (``policy``, ``model``,
   ``frames``) must, where it exists on this machine, be byte for byte (sha256) the set's file of that role.
   A path that is absent here is reported, not refused; ``"shipped"`` (a set that was shipped before) passes.
2. **Keep** the skill's shipped files: move them to ``candidates/KEEP/`` in the repository root, outside the packages
   (refused if that folder exists), so that ``--weights-dir candidates/KEEP`` still runs them.
3. **Copy** the set's files in. In the fitted files (both success models, the frames file) each of ``policy``,
   ``model`` and ``frames`` that names a path becomes ``"shipped"``; the path moves to ``trained_with``; and a
   ``note`` records the release and the sha256 of the shipped files it was fitted with. The weights themselves
   are not touched.

This is what releases 0.17 (roll), 0.18 (push) and 0.19 (spin) did by hand. The record of commands and figures
(``weights/RECORD.md``) is still written by hand; the command prints what to put in it.

**Ratings for another sensor** (``--sensor cameras``): the set holds some of the shipped policy's three ratings
refitted to that sensor's clouds, and no policy; they ship into ``weights/{sensor}/``
(:func:`primitives.weights_file.rating_path`), which is refused for the sensor the policy was trained on (its own
ratings serve it). Their ``policy`` must be the shipped one, and a ``model`` or ``frames`` they name the set's own
or the one that serves the sensor now. Only the files the set replaces are kept; the subfolder's others stay.

    python -m primitives.research.ship roll --sensor cameras --from candidates/roll_cam --keep roll_cam_0.24

**A policy for another sensor** (``--sensor cameras`` with a set that holds a policy): a policy chosen for that
sensor's clouds with its own ratings (:func:`primitives.weights_file.policy_path`), checked as a set without
``--sensor`` is; it ships into ``weights/{sensor}/``, and every file of the skill there is kept first (ratings
fitted to another policy must not stay beside it). To give a sensor the policy shipped now, while another takes
its place for the other sensors: ship a set of that policy with its ratings for the sensor (``--sensor``), then the
new policy with its own (without).
"""

from __future__ import annotations

import argparse
import hashlib
import os
import shutil
import tempfile
from dataclasses import dataclass, field, replace
from pathlib import Path

from affordplan.errors import AffordplanError, InputError, WeightsError
from affordplan.log import cli_logging, one_line_errors
from affordplan.sim.sensor import SENSORS, check_sensor
from primitives import weights_file
from primitives.frames import FrameSearch
from primitives.training.env import PRIMITIVES
from primitives.weights_file import SHIPPED_DIR as WEIGHTS_DIR
from primitives.weights_file import policy_sensor, rating_path

RATING_OF = {"model": "success", "frames": "frames", "searched": "searched"}  # role: weights_file.RATINGS name

REPO_ROOT = Path(__file__).resolve().parents[2]
ROLES = ("policy", "model", "frames")  # the info keys of a fitted file that name the files it was fitted with
SHIPPED = "shipped"


def role_files(skill: str) -> dict[str, str]:
    """The file name of each role in a weights folder: ``policy``, ``model`` (the goal-frame success model),
    ``frames``; and ``searched``, the searched success model (fitted, but named by no other file's info)."""
    return {"policy": f"{skill}.pt", **{role: weights_file.rating_name(skill, r) for role, r in RATING_OF.items()}}


def skill_files(folder: Path, skill: str) -> list[Path]:
    """The files of ``skill`` directly in ``folder`` (``{skill}.*`` and ``{skill}_*``), sorted by name."""
    return sorted(p for p in folder.iterdir()
                  if p.is_file() and (p.name.startswith(f"{skill}.") or p.name.startswith(f"{skill}_")))


def sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def read_info(path: Path) -> dict:
    """The ``info`` of a fitted file: a success model (``.pt``) or a frames file (``.json``, read by
    :meth:`FrameSearch.load`, which raises :class:`InputError` for an unreadable one)."""
    if path.suffix == ".json":
        return dict(FrameSearch.load(path).info)
    try:
        content = weights_file.read(path)
    except WeightsError as exc:
        raise InputError(f"{path} cannot be read ({exc})") from exc
    payload = content.get("payload", content) if isinstance(content, dict) else {}
    return dict(payload.get("info", {})) if isinstance(payload, dict) else {}


@dataclass
class ShipPlan:
    """What :func:`plan_ship` found: the files to keep and to copy, and the provenance checks."""

    skill: str
    source: Path
    weights_dir: Path
    keep_dir: Path
    to_keep: list[Path]
    to_copy: list[Path]
    digests: dict[str, str]  # sha256 of the set's file of each role it holds (policy, model, frames)
    checked: list[str] = field(default_factory=list)  # "model: policy runs/x/policy.pt = push.pt (sha256 ab12...)"
    unchecked: list[str] = field(default_factory=list)  # run paths absent from this machine
    sensor: str | None = None  # ratings for this sensor's clouds, shipped into weights_dir/sensor/

    @property
    def target(self) -> Path:
        """The folder the set's files are copied into."""
        return self.weights_dir if self.sensor is None else self.weights_dir / self.sensor

    def describe(self) -> str:
        lines = [f"ship {self.skill} from {self.source} into {self.target}",
                 f"keep {len(self.to_keep)} shipped file(s) in {self.keep_dir}:"]
        lines += [f"  {p.name}" for p in self.to_keep]
        lines += [f"copy {len(self.to_copy)} file(s):"] + [f"  {p.name}" for p in self.to_copy]
        lines += ["provenance, byte for byte:"] + [f"  {c}" for c in self.checked]
        lines += [f"  not checked (absent here): {u}" for u in self.unchecked]
        return "\n".join(lines)


def plan_ship(skill: str, source: str | Path, keep: str, weights_dir: str | Path | None = None,
              base: str | Path = ".", sensor: str | None = None) -> ShipPlan:
    """Check a candidate set (module docstring, step 1) and say what shipping it would move; change nothing.

    ``base``: the folder that relative run paths in the files' ``info`` are taken from (the repository root,
    where the training commands ran); the files now shipped are kept in ``base/candidates/KEEP``.
    ``sensor``: the set holds ratings of the shipped policy refitted to this sensor's clouds (module docstring).
    Raises :class:`InputError` for a set that cannot ship.
    """
    from primitives.skills import load_skill

    if sensor is not None:
        check_sensor(sensor)
    if skill not in PRIMITIVES:
        raise InputError(f"unknown skill {skill!r}; expected one of {PRIMITIVES}")
    source = Path(source)
    weights_dir = Path(weights_dir) if weights_dir is not None else WEIGHTS_DIR
    if not source.is_dir():
        raise InputError(f"candidate set {str(source)!r} is not a folder")
    if source.resolve() == weights_dir.resolve():
        raise InputError("the candidate set is the weights folder itself")
    if not keep or Path(keep).name != keep or keep in (".", ".."):
        raise InputError(f"--keep must be a plain folder name under candidates/, got {keep!r}")
    keep_dir = Path(base) / "candidates" / keep
    if keep_dir.exists():
        raise InputError(f"{keep_dir} exists already; choose another --keep name")
    names = role_files(skill)
    with_policy = sensor is not None and (source / names["policy"]).exists()  # a policy for that sensor's clouds
    if sensor is None or with_policy:
        for role in ("policy", "model"):
            if not (source / names[role]).exists():
                raise InputError(f"the candidate set has no {names[role]} (its {role})")
        try:
            load_skill(skill, weights_dir=source)
        except AffordplanError as exc:
            raise InputError(f"the candidate set does not load as the {skill} skill: {exc}") from exc
        serving = {role: source / names[role] for role in ROLES if (source / names[role]).exists()}
        target = weights_dir if sensor is None else weights_dir / sensor
        to_keep = skill_files(target, skill) if target.is_dir() else []
    else:
        serving = _ratings_serving(skill, source, weights_dir, sensor)
        to_keep = [p for p in skill_files(weights_dir / sensor, skill) if (source / p.name).exists()] \
            if (weights_dir / sensor).is_dir() else []
    digests = {role: sha256(path) for role, path in serving.items()}
    plan = ShipPlan(skill, source, weights_dir, keep_dir, to_keep, skill_files(source, skill), digests, sensor=sensor)
    for fitted in ("model", "frames", "searched"):
        path = source / names[fitted]
        if not path.exists():
            continue
        info = read_info(path)
        for role in ROLES:
            named = info.get(role)
            if named is None or role == fitted or named == SHIPPED:
                continue
            own = serving.get(role, source / names[role])
            if role not in digests:
                raise InputError(f"{path.name} was fitted with a {role} ({named}) the set does not hold ({own.name})")
            run_file = Path(named) if Path(named).is_absolute() else Path(base) / named
            if not run_file.exists():
                plan.unchecked.append(f"{path.name}: {role} {named}")
                continue
            digest = sha256(run_file)
            whose = "the set's" if own.parent == source else "the shipped"
            if digest != digests[role]:
                raise InputError(f"{path.name} was fitted with {named}, which is not {whose} {own.name} "
                                 f"(sha256 {digest[:12]} against {digests[role][:12]})")
            plan.checked.append(f"{path.name}: {role} {named} = {own.name} (sha256 {digest[:12]})")
    return plan


def _ratings_serving(skill: str, source: Path, weights_dir: Path, sensor: str) -> dict[str, Path]:
    """For a set of ``sensor`` ratings (module docstring): check it, and return the file that will serve each role
    once it ships (the set's own, else the shipped policy and the ratings serving ``sensor`` now)."""
    from primitives.skills import load_skill

    names = role_files(skill)
    policy = weights_dir / names["policy"]
    if (source / names["policy"]).exists():
        raise InputError(f"a set of {sensor} ratings holds no policy; {source / names['policy']} is one "
                         f"(ship a policy with its own ratings without --sensor)")
    if not policy.is_file():
        raise InputError(f"{weights_dir} has no {names['policy']} for the {sensor} ratings to rate")
    own = policy_sensor(skill, weights_dir)
    if own == sensor:
        raise InputError(f"the shipped {names['policy']} was trained on {sensor} clouds: the ratings beside it serve "
                         f"them, and {weights_dir / sensor} would never be read; ship them without --sensor")
    held = [role for role in RATING_OF if (source / names[role]).exists()]
    if not held:
        raise InputError(f"the candidate set holds none of {[names[r] for r in RATING_OF]}")
    with tempfile.TemporaryDirectory() as tmp:  # the weights folder as it would be, for the load check
        overlay = Path(tmp)
        shutil.copy2(policy, overlay / policy.name)
        for role in RATING_OF:
            now = rating_path(skill, RATING_OF[role], sensor, weights_dir, trained_on=own)
            if now.exists():
                shutil.copy2(now, overlay / names[role])
        (overlay / sensor).mkdir()
        for role in held:
            shutil.copy2(source / names[role], overlay / sensor / names[role])
        try:
            skill_ = load_skill(skill, weights_dir=overlay)
        except AffordplanError as exc:
            raise InputError(f"the {sensor} ratings do not load with the shipped {skill} policy: {exc}") from exc
        if sensor not in skill_.rated_sensors:
            raise InputError(f"the {sensor} ratings are not read for the shipped {skill} policy")
    serving = {"policy": policy}
    for role in ("model", "frames"):
        path = source / names[role] if role in held else rating_path(skill, RATING_OF[role], sensor, weights_dir,
                                                                      trained_on=own)
        if path.exists():
            serving[role] = path
    return serving


def portable(value, root: Path | None = None):
    """``value`` with every mention of the repository's absolute path ``root`` (default: this checkout's) dropped from
    its strings (in dicts and lists too), so that a shipped file names its runs as ``runs/...``, not by where this
    checkout lies."""
    root = REPO_ROOT if root is None else root
    if isinstance(value, str):
        return value.replace(f"{root}{os.sep}", "").replace(str(root), ".")
    if isinstance(value, dict):
        return {k: portable(v, root) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return type(value)(portable(v, root) for v in value)
    return value


def relabel(path: Path, release: str, digests: dict[str, str]) -> None:
    """Rewrite the ``info`` of a fitted file as shipped (module docstring, step 3), its paths made
    :func:`portable`; its model is untouched."""
    def update(info: dict) -> dict:
        info = portable(info)
        trained_with = {role: info[role] for role in ROLES if role in info and info[role] != SHIPPED}
        if not trained_with:
            return info
        for role in trained_with:
            info[role] = SHIPPED
        info["trained_with"] = {**info.get("trained_with", {}), **trained_with}
        fitted_with = ", ".join(f"{role} sha256 {digests[role][:12]}" for role in trained_with if role in digests)
        info["note"] = f"trained with the files shipped in {release}: {fitted_with}"
        return info

    if path.suffix == ".json":
        search = FrameSearch.load(path)
        replace(search, info=update(dict(search.info))).save(path)
    else:
        content = weights_file.read(path)
        content["payload"]["info"] = update(dict(content["payload"].get("info", {})))
        weights_file.save(path, content["payload"], content["meta"])


def ship(plan: ShipPlan, release: str) -> None:
    """Carry out a :func:`plan_ship` (module docstring, steps 2-3)."""
    names = role_files(plan.skill)
    plan.keep_dir.mkdir(parents=True)
    for path in plan.to_keep:
        shutil.move(str(path), plan.keep_dir / path.name)
    plan.target.mkdir(exist_ok=True)
    for path in plan.to_copy:
        shutil.copy2(path, plan.target / path.name)
    for fitted in ("model", "frames", "searched"):
        path = plan.target / names[fitted]
        if path.exists() and (plan.source / names[fitted]).exists():
            relabel(path, release, plan.digests)


@one_line_errors("python -m primitives.research.ship")
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m primitives.research.ship", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("skill", choices=PRIMITIVES)
    parser.add_argument("--from", dest="source", required=True, help="the candidate set (a folder like weights/)")
    parser.add_argument("--keep", required=True,
                        help="folder name under candidates/ (in the repository root) for the files now shipped")
    parser.add_argument("--release", default=None, help="the release the note names (default: the package version)")
    parser.add_argument("--weights-dir", default=None, help="the weights folder to ship into (default: the package's)")
    parser.add_argument("--sensor", choices=SENSORS, default=None,
                        help="ship into weights/SENSOR/: the set holds ratings of the shipped policy refitted to this "
                             "sensor's clouds, or a policy for them with its own ratings (default: the set is the "
                             "policy for every other sensor, with its own ratings)")
    parser.add_argument("--dry-run", action="store_true", help="check and print what would move; change nothing")
    args = parser.parse_args(argv)
    cli_logging()
    plan = plan_ship(args.skill, args.source, args.keep, args.weights_dir, sensor=args.sensor)
    print(plan.describe())
    if args.dry_run:
        print("dry run: nothing changed")
        return 0
    if args.release is None:
        import affordplan

        args.release = affordplan.__version__
    ship(plan, args.release)
    print(f"shipped; the previous files are in {plan.keep_dir}. Record the command and figures in weights/RECORD.md.")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
