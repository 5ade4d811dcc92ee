"""Generate ``docs/api.md`` from the docstrings (standard library only: ``inspect``).

    python docs/gen_api.py            # rewrite docs/api.md
    python docs/gen_api.py --check    # exit 1 when docs/api.md is out of date (for CI)

For each module in :data:`MODULES`: its docstring, then each public class and function defined in
it (its ``__all__`` when it has one, else the names without a leading underscore), with the
signature and the docstring; for classes, their public methods and properties. Names a module only
re-exports are listed with a pointer to where they are documented.
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import os
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "api.md"

# (section title, modules), in reading order: the public surface first, then the internals it rests on.
MODULES: list[tuple[str, list[str]]] = [
    ("Public surface", ["affordplan", "affordplan.errors", "affordplan.goal", "affordplan.world",
                        "affordplan.objects.model", "affordplan.objects.resting", "affordplan.sim.simulator",
                        "primitives", "primitives.skills", "primitives.strokes", "primitives.rewards",
                        "primitives.params", "planner.api", "planner.plan", "planner.execute"]),
    ("Command line, scenes, pictures and video", ["affordplan.app.cli", "affordplan.app.scene_file",
                                                  "affordplan.app.demo", "affordplan.app.video",
                                                  "affordplan.app.render", "affordplan.app.viewer", "planner.plot"]),
    ("Simulation internals", ["affordplan.sim.scene", "affordplan.sim.guards", "affordplan.sim.arm",
                              "affordplan.sim.pushers", "affordplan.geometry"]),
    ("Learning at run time", ["primitives.observation", "primitives.networks", "primitives.success_model",
                              "primitives.ensemble", "primitives.frames", "primitives.affordances"]),
    ("Training", ["primitives.training.env", "primitives.training.replay", "primitives.training.train",
                  "primitives.training.evaluate", "primitives.training.scripted", "primitives.training.success",
                  "primitives.training.checkpoint"]),
    ("Research and release tooling", ["primitives.research.ceiling", "primitives.research.frame_ceiling",
                                      "primitives.research.sensitivity", "primitives.research.ship",
                                      "primitives.research.curves"]),
    ("Planning internals", ["planner.graph", "planner.footprint", "planner.motion", "planner.chain",
                            "planner.predict", "planner.places", "planner.ratings", "planner.memory",
                            "planner.odds"]),
    ("Benchmarks", ["affordplan.app.bench.primitive", "affordplan.app.bench.plan", "affordplan.app.bench.compare"]),
]


SECTIONS = ("Args:", "Arguments:", "Attributes:", "Returns:", "Raises:", "Yields:")


def _markdown(doc: str) -> str:
    """Google-style sections (``Args:`` and indented ``name: text`` items) as Markdown lists; ``::`` as ``:``."""
    out: list[str] = []
    section = False
    for line in doc.splitlines():
        if line.strip() in SECTIONS:
            section = True
            out += [f"**{line.strip()[:-1]}**", ""]
            continue
        if section:
            if not line.strip():
                section = False
                out.append("")
                continue
            if not line.startswith("    "):
                section = False
            elif not line.startswith("     "):  # an item: 4 spaces, then "name: text"
                name, sep, text = line.strip().partition(": ")
                out.append(f"- `{name}`: {text}" if sep and len(name) < 40 else f"- {line.strip()}")
                continue
            else:  # its continuation
                out.append("  " + line.strip())
                continue
        out.append(line[:-2] + ":" if line.endswith("::") else line)
    return "\n".join(out)


def _doc(obj) -> str:
    return _markdown(inspect.getdoc(obj) or "")


class _Short:
    """Stands in for a long default value: ``Protocol(...)``."""

    def __init__(self, text: str):
        self.text = text

    def __repr__(self) -> str:
        return self.text


def _signature(name: str, obj) -> str:
    """``name(arg: type = default, ...) -> type``, without ``self``, with long defaults shortened."""
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return f"{name}(...)"
    params = []
    for p in sig.parameters.values():
        if p.name == "self":
            continue
        if p.default is not inspect.Parameter.empty and len(repr(p.default)) > 40:
            p = p.replace(default=_Short(f"{type(p.default).__name__}(...)"))
        params.append(p)
    text = str(sig.replace(parameters=params))
    text = re.sub(r"(: |-> )'([^']*)'", r"\1\2", text)  # string annotations (from __future__) unquoted
    return f"{name}{text}"


def _public_names(module) -> list[str]:
    names = getattr(module, "__all__", None)
    if names is None:
        names = [n for n, v in vars(module).items()
                 if not n.startswith("_") and (inspect.isclass(v) or inspect.isfunction(v))
                 and getattr(v, "__module__", None) == module.__name__]
    return list(names)


def _class_members(cls) -> list[tuple[str, object]]:
    members = []
    for name, value in cls.__dict__.items():
        if name.startswith("_") and name != "__call__":
            continue
        if isinstance(value, property) or inspect.isfunction(value):
            members.append((name, value))
        elif isinstance(value, (classmethod, staticmethod)):
            members.append((name, value.__func__))
    return members


def _indent_doc(text: str) -> list[str]:
    return [text, ""] if text else []


def _bullet(head: str, doc: str) -> str:
    """A list item: ``head: first line``, further docstring lines indented to stay in the item."""
    if not doc:
        return f"- {head}"
    first, *rest = doc.splitlines()
    return "\n".join([f"- {head}: {first}"] + [f"  {line}" if line else "" for line in rest])


def document_module(name: str) -> list[str]:
    """Markdown lines for one module."""
    try:
        module = importlib.import_module(name)
    except Exception as exc:  # a reference with holes is not written (0.24.0.dev0 shipped one with 83)
        raise SystemExit(f"error: cannot import {name} ({type(exc).__name__}: {exc}); run this with the "
                         f"project installed (the README's set-up), from the repository root") from exc
    lines = [f"### `{name}`", ""] + _indent_doc(_doc(module))
    for attr in _public_names(module):
        value = getattr(module, attr, None)
        if value is None:
            continue
        home = getattr(value, "__module__", None)
        if inspect.ismodule(value):
            lines += [f"- `{attr}`: the module `{value.__name__}`", ""]
            continue
        if home is not None and home != name and (inspect.isclass(value) or inspect.isfunction(value)):
            lines += [f"- `{attr}`: see `{home}.{value.__qualname__}`", ""]
            continue
        if inspect.isclass(value):
            lines += [f"#### class `{_signature(attr, value)}`", ""] + _indent_doc(_doc(value))
            for member, obj in _class_members(value):
                if isinstance(obj, property):
                    lines += [_bullet(f"property `{member}`", _doc(obj))]
                else:
                    lines += [_bullet(f"`{_signature(member, obj)}`", _doc(obj))]
            lines += [""]
        elif inspect.isfunction(value):
            lines += [f"#### `{_signature(attr, value)}`", ""] + _indent_doc(_doc(value))
        else:
            text = repr(value)
            lines += [f"- `{attr}` = `{text if len(text) < 100 else text[:97] + '...'}`", ""]
    return lines


PACKAGES = ("affordplan", "primitives", "planner")


def unlisted_modules() -> list[str]:
    """Modules of :data:`PACKAGES` that :data:`MODULES` does not name (documented under "Other modules")."""
    listed = {name for _, names in MODULES for name in names}
    found = []
    for package in PACKAGES:
        path = ROOT / package
        for file in sorted(path.rglob("*.py")):
            parts = file.relative_to(ROOT).with_suffix("").parts
            if parts[-1] == "__init__":
                parts = parts[:-1]
            if any(p.startswith("_") for p in parts) or "weights" in parts:
                continue
            name = ".".join(parts)
            if name not in listed:
                found.append(name)
    return found


def generate() -> str:
    lines = ["# API reference", "",
             "Generated from the docstrings by `python docs/gen_api.py`; do not edit by hand. Units are SI "
             "(metres, radians, seconds); poses are 4x4 homogeneous transforms named `T_frame_object`; the world "
             "frame has z up with the table top at z = 0 and the arm's base at the origin.", ""]
    sections = MODULES + ([("Other modules", extra)] if (extra := unlisted_modules()) else [])
    lines += ["Contents:", ""]
    for title, names in sections:
        lines += [f"- {title}: " + ", ".join(f"`{n}`" for n in names)]
    lines += [""]
    for title, names in sections:
        lines += [f"## {title}", ""]
        for name in names:
            lines += document_module(name)
    text = "\n".join(lines).rstrip() + "\n"
    text = re.sub(r"(\n- `[^\n]*`: (?:see|the module) `[^\n]*`)\n\n(?=- `[^\n]*`: (?:see|the module))", r"\1\n", text)
    text = re.sub(r"(\n- `[^\n]*`: (?:see|the module) `[^\n]*`)\n\n(?=- `[^\n]*`: (?:see|the module))", r"\1\n", text)
    return text.replace(str(ROOT) + os.sep, "")  # no machine-specific paths in defaults


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        description="Generate docs/api.md from the docstrings.",
        epilog="examples:\n  python docs/gen_api.py\n  python docs/gen_api.py --check",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--check", action="store_true", help="exit 1 when docs/api.md is out of date")
    parser.add_argument("--out", default=str(OUT), help="where to write (default: docs/api.md)")
    args = parser.parse_args(argv)
    sys.path.insert(0, str(ROOT))
    os.environ.setdefault("MUJOCO_GL", "egl")
    text = generate()
    out = Path(args.out)
    if args.check:
        current = out.read_text(encoding="utf-8") if out.exists() else ""
        if current != text:
            print(f"{out} is out of date: run python docs/gen_api.py", file=sys.stderr)
            return 1
        print(f"{out} is up to date")
        return 0
    out.write_text(text, encoding="utf-8")
    print(f"wrote {out} ({len(text.splitlines())} lines)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
