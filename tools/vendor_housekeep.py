"""Vendor HACMan's household meshes into the package and ship their convex decompositions.

    python tools/vendor_housekeep.py --source DIR [--jobs 2]

``DIR`` holds ``meshes/*.obj``, ``split.json`` and ``README.md`` (the provenance note). The meshes, the split and the
note are copied to ``affordplan/objects/data/housekeep/``; each mesh is loaded exactly as ``load_object`` loads it
(repair, normalisation to a 5 cm largest half-extent) and its convex parts (CoACD, the project's settings) are written
to ``parts/NAME.npz`` with a fingerprint of the normalised mesh, so ``load_object("housekeep/NAME")`` never runs CoACD.
Release tooling: nothing at run time imports it.
"""

from __future__ import annotations

import argparse
import shutil
import sys
import time
import warnings
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np


def _parts(name: str, target: str) -> tuple[str, int, float]:
    from affordplan.objects import housekeep, model

    start = time.perf_counter()
    path = housekeep.data_dir() / "meshes" / f"{name}.obj"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        obj = model._from_mesh(name, model._read_mesh(path), housekeep.PARTS_SIZE, model.DEFAULT_DENSITY, name)
    arrays = {str(i): np.asarray(p.vertices, dtype=np.float64) for i, p in enumerate(obj.parts)}
    arrays["n_vertices"] = np.array(len(obj.mesh.vertices))
    arrays["extents"] = np.ptp(np.asarray(obj.mesh.vertices), axis=0)
    np.savez_compressed(Path(target) / f"{name}.npz", **arrays)
    return name, len(obj.parts), time.perf_counter() - start


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--source", type=Path, required=True, help="folder with meshes/, split.json and README.md")
    p.add_argument("--jobs", type=int, default=2, help="processes (default: 2)")
    p.add_argument("--only-missing", action="store_true", help="skip meshes whose parts are already written")
    args = p.parse_args(argv)
    from affordplan.objects import housekeep

    target = housekeep.data_dir()
    (target / "meshes").mkdir(parents=True, exist_ok=True)
    for mesh in sorted((args.source / "meshes").glob("*.obj")):
        shutil.copyfile(mesh, target / "meshes" / mesh.name)
    shutil.copyfile(args.source / "split.json", target / "split.json")
    shutil.copyfile(args.source / "README.md", target / "PROVENANCE.md")
    housekeep._hacman_split.cache_clear()
    parts = target / "parts"
    parts.mkdir(exist_ok=True)
    todo = [n for n in housekeep.names() if not (args.only_missing and (parts / f"{n}.npz").exists())]
    with ProcessPoolExecutor(args.jobs) as pool:
        for i, (name, n_parts, seconds) in enumerate(pool.map(_parts, todo, [str(parts)] * len(todo)), 1):
            print(f"[{i}/{len(todo)}] {name}: {n_parts} parts, {seconds:.1f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
