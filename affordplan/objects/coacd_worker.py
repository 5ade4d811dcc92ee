"""Runs CoACD in a child process: ``python coacd_worker.py IN.npz OUT.npz SETTINGS_JSON``.

Run by path (not ``-m``), so the child imports numpy and coacd only. :mod:`.decompose` starts it
with a time limit: a decomposition that runs away, or a crash inside CoACD's C++ code, costs the
child process, never the caller's.
"""

import json
import sys

import numpy as np


def main(argv: list[str]) -> int:
    source, target, settings = argv
    import coacd

    coacd.set_log_level("error")
    with np.load(source) as data:
        mesh = coacd.Mesh(np.asarray(data["vertices"], dtype=float), np.asarray(data["faces"], dtype=np.int64))
    parts = coacd.run_coacd(mesh, **json.loads(settings))
    arrays = {}
    for i, (v, f) in enumerate(parts):
        arrays[f"v{i}"] = np.asarray(v, dtype=float)
        arrays[f"f{i}"] = np.asarray(f, dtype=np.int64)
    np.savez(target, **arrays)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
