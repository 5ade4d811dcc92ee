"""Kill a training run with SIGKILL at random moments, resume it each time, and measure what was lost.

    python -m primitives.research.killtest push --kills 5 --out /tmp/killtest
    python -m primitives.research.killtest spin --kills 3 --steps 400 --checkpoint-seconds 2 --workers 1 --out /tmp/kt

What it does: starts ``python -m primitives.train PRIMITIVE ... --checkpoint-minutes C`` (a small
config: few points, a small replay) in a process group of its own, waits a random time after the
run starts stepping (uniform in [0.5 s, 3 C]), sends SIGKILL to the learner, and resumes with
``--resume``; ``--kills`` times, then lets the last run finish. For each kill it reports:

- the step of the checkpoint left on disk (``checkpoint.pt``, read back) and the step the resumed
  run started from (the first line of its progress bar): they must agree;
- the last step the progress bar printed before the kill (tqdm prints every 2 s, so this is a
  lower bound; ``lost_steps`` adds the steps at the observed rate since that print);
- ``lost_s``, the training seconds since the last checkpoint was written (or since this run began
  stepping, when it wrote none): at most one checkpoint interval plus one loop iteration
  (``SLACK_S``) when checkpoints are written on time;
- stale temporary files (a kill during a checkpoint write leaves one; the checkpoint itself is
  replaced atomically, never torn) and orphaned worker processes (``--workers`` > 0: workers
  that outlived their learner; they are then killed).

Finally it truncates a copy of the final checkpoint and checks that ``--resume`` from it exits with
a one-line error naming the file (exit status 2), not a traceback. Exit status 0 when every check held.
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from affordplan.log import cli_logging
from affordplan.robot import SKILLS as PRIMITIVES

logger = logging.getLogger(__name__)

SLACK_S = 2.0  # one learner loop iteration and the checkpoint write, on a loaded 2-core machine
_PROGRESS = re.compile(r"(\d+)/(\d+) \[")


@dataclass
class Kill:
    """One SIGKILL and what it cost (steps are primitives executed; times in seconds)."""

    index: int
    after_s: float  # when, after the run began stepping
    last_seen_step: int  # the progress bar's last count before the kill (a lower bound)
    lost_steps: int  # estimate: steps done since the checkpoint, up to the kill
    lost_s: float  # training seconds since the last checkpoint (or the run's start of stepping)
    checkpoint_step: int  # step in checkpoint.pt after the kill (0: none yet)
    resumed_from: int | None = None  # first count of the resumed run's progress bar
    stale_tmp_files: int = 0
    orphans: int = 0  # processes of the run still alive 2 s after the learner was killed
    orphan_commands: list[str] = field(default_factory=list)
    signal: str = "KILL"
    exit_ok: bool = True  # INT / TERM: the run saved and exited with status 130 by itself

    @property
    def ok(self) -> bool:
        return self.resumed_from == self.checkpoint_step and self.orphans == 0 and self.exit_ok


@dataclass
class KillTestResult:
    primitive: str
    steps: int
    interval_s: float
    kills: list[Kill] = field(default_factory=list)
    completed: bool = False
    final_steps: int = 0
    corrupt_checkpoint_error: str = ""  # what --resume from a truncated checkpoint printed
    corrupt_checkpoint_ok: bool | None = None  # None: not checked
    wall_s: float = 0.0
    duplicated_log_rows: int = 0  # rows of the final log.csv whose step is not above the row before

    @property
    def max_lost_s(self) -> float:
        return max((k.lost_s for k in self.kills), default=0.0)

    @property
    def ok(self) -> bool:
        return (self.completed and self.final_steps == self.steps and all(k.ok for k in self.kills)
                and self.duplicated_log_rows == 0
                and self.max_lost_s <= self.interval_s + SLACK_S
                and self.corrupt_checkpoint_ok is not False)

    def as_dict(self) -> dict:
        d = asdict(self)
        d.update(ok=self.ok, max_lost_s=self.max_lost_s)
        return d

    def report(self) -> str:
        lines = [f"killtest {self.primitive}: {len(self.kills)} kills, {self.steps} steps, checkpoint every "
                 f"{self.interval_s:.1f} s, {self.wall_s:.0f} s in all",
                 "  kill  signal  after_s  last_seen  ckpt_step  resumed_from  lost_steps  lost_s  tmp  orphans"]
        for k in self.kills:
            mark = "" if k.exit_ok else "!"
            lines.append(f"  {k.index:4d}  {k.signal:>6s}{mark}  {k.after_s:7.1f}  {k.last_seen_step:9d}  "
                         f"{k.checkpoint_step:9d}  "
                         f"{str(k.resumed_from):>12s}  {k.lost_steps:10d}  {k.lost_s:6.1f}  {k.stale_tmp_files:3d}  "
                         f"{k.orphans:7d}")
        lines += [
            f"  lost at most {self.max_lost_s:.1f} s of training per kill (bound: interval {self.interval_s:.1f} s "
            f"+ {SLACK_S:.0f} s slack)",
            f"  final run completed: {self.completed} ({self.final_steps}/{self.steps} steps); log rows logged twice: "
            f"{self.duplicated_log_rows}",
            f"  --resume from a truncated checkpoint: {self.corrupt_checkpoint_error or '(not run)'}",
        ]
        orphaned = sorted({c for k in self.kills for c in k.orphan_commands})
        lines += [f"  orphaned after a kill (then killed): {c}" for c in orphaned]
        lines.append("  OK" if self.ok else "  FAILED")
        return "\n".join(lines)


class _Run:
    """One training process; a thread reads its progress bar from stderr."""

    def __init__(self, cmd: list[str], env: dict):
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env,
                                     start_new_session=True)
        self.progress: list[tuple[float, int]] = []  # (time, step) of every progress print
        self.stderr_tail: list[str] = []
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        buf = b""
        while True:
            chunk = self.proc.stderr.read1(4096) if hasattr(self.proc.stderr, "read1") else self.proc.stderr.read(1)
            if not chunk:
                break
            buf += chunk
            parts = re.split(rb"[\r\n]", buf)
            buf = parts.pop()
            for raw in parts:
                self._line(raw.decode(errors="replace"))
        if buf:
            self._line(buf.decode(errors="replace"))

    def _line(self, line: str) -> None:
        m = _PROGRESS.search(line)
        if m:
            self.progress.append((time.time(), int(m.group(1))))
        elif line.strip():
            self.stderr_tail = (self.stderr_tail + [line.strip()])[-20:]

    def wait_stepping(self, timeout: float) -> float | None:
        """Time of the first progress print (the run has started stepping), or ``None``."""
        end = time.time() + timeout
        while time.time() < end and self.proc.poll() is None:
            if self.progress:
                return self.progress[0][0]
            time.sleep(0.05)
        return self.progress[0][0] if self.progress else None

    def descendants(self) -> list[int]:
        """Process ids of every descendant (Linux /proc), for the orphan check."""
        found, todo = [], [self.proc.pid]
        while todo:
            pid = todo.pop()
            try:
                tasks = os.listdir(f"/proc/{pid}/task")
            except OSError:
                continue
            for tid in tasks:
                try:
                    with open(f"/proc/{pid}/task/{tid}/children") as f:
                        kids = [int(c) for c in f.read().split()]
                except OSError:
                    kids = []
                found += kids
                todo += kids
        return found

    def kill_group(self) -> None:
        """SIGKILL whatever is left of this run's process group (it was started as its own session)."""
        try:
            os.killpg(self.proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split()[2] != "Z"
    except OSError:
        return False


def _command(pid: int) -> str:
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as f:
            return f.read().replace(b"\0", b" ").decode(errors="replace").strip()[:160]
    except OSError:
        return "?"


def _checkpoint_step(path: Path) -> tuple[int, float]:
    """``(global_step, modification time)`` of a checkpoint; ``(0, 0.0)`` when there is none."""
    from primitives.training import checkpoint as ckpt

    if not path.exists():
        return 0, 0.0
    return int(ckpt.load(path)["state"]["global_step"]), path.stat().st_mtime


def train_command(primitive: str, out: Path, steps: int, interval_s: float, workers: int, seed: int,
                  resume: bool) -> list[str]:
    """The ``python -m primitives.train`` command line of the small killtest config."""
    cmd = [sys.executable, "-m", "primitives.train", primitive, "--steps", str(steps), "--workers", str(workers),
           "--out", str(out), "--seed", str(seed), "--checkpoint-minutes", f"{interval_s / 60:.6f}",
           "--n-points", "64", "--replay-size", "2000", "--learning-starts", "50", "--batch-size", "16",
           "--max-minutes", "60"]
    return cmd + (["--resume"] if resume else [])


def killtest(primitive: str = "push", kills: int = 5, out: str | os.PathLike = "killtest", steps: int = 4000,
             interval_s: float = 3.0, workers: int = 0, seed: int = 0, timeout: float = 600.0,
             overwrite: bool = False, window: tuple[float, float] | None = None, check_truncated: bool = True,
             log: Callable[[str], None] | None = None, signals: tuple[str, ...] = ("KILL",)) -> KillTestResult:
    """Run the kill-and-resume test (see the module docstring); ``out`` is created and must not exist
    unless ``overwrite``.

    ``window``: seconds after a run begins stepping within which its kill falls (uniformly; default
    ``(0.5, 3 * interval_s)``). ``check_truncated``: also check ``--resume`` from a truncated checkpoint.
    ``signals``: what stops each run, in turn (``KILL``, ``INT``: Ctrl-C, ``TERM``); a run stopped by INT or TERM
    must save a checkpoint and exit by itself (status 130). ``log``: where each stop's and the final run's line goes
    (default: this module's logger, at INFO).
    """
    log = log or logger.info
    low, high = window or (0.5, 3.0 * interval_s)
    root = Path(out)
    if root.exists():
        if not overwrite:
            raise FileExistsError(f"{root} exists; pass --overwrite or choose another --out")
        shutil.rmtree(root)
    run_dir = root / "run"
    rng = np.random.default_rng(seed)
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    result = KillTestResult(primitive, steps, interval_s)
    t0 = time.time()
    pending: Kill | None = None
    for i in range(kills + 1):
        run = _Run(train_command(primitive, run_dir, steps, interval_s, workers, seed, resume=i > 0), env)
        started = run.wait_stepping(timeout=120.0)
        if pending is not None:  # the previous kill: where did this run start from?
            pending.resumed_from = run.progress[0][1] if run.progress else None
            pending = None
        if started is None:
            run.kill_group()
            raise RuntimeError("the training run never started stepping:\n" + "\n".join(run.stderr_tail))
        if i == kills:  # the last run: let it finish
            try:
                run.proc.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                run.kill_group()
            run._reader.join(timeout=5)
            summary = run.proc.stdout.read().decode(errors="replace")
            result.completed = run.proc.returncode == 0
            try:
                result.final_steps = int(json.loads(summary)["steps"])
            except (ValueError, KeyError):
                result.final_steps = _checkpoint_step(run_dir / "checkpoint.pt")[0]
            log(f"final run: exit status {run.proc.returncode}, {result.final_steps} steps")
            break
        after = float(rng.uniform(low, high))
        while time.time() < started + after and run.proc.poll() is None:
            time.sleep(0.01)
        if run.proc.poll() is not None:  # finished before its kill: nothing to kill, the test is too short
            raise RuntimeError(f"the run finished before kill {i + 1}; raise --steps")
        children = run.descendants()
        name = signals[i % len(signals)]
        t_kill = time.time()
        os.kill(run.proc.pid, getattr(signal, f"SIG{name}"))
        try:
            run.proc.wait(timeout=60.0)
        except subprocess.TimeoutExpired:  # INT / TERM ignored: a failure the report shows (exit status None)
            run.kill_group()
            run.proc.wait()
        polite_ok = name == "KILL" or run.proc.returncode == 130
        if not polite_ok:
            log(f"stop {i + 1} ({name}): exit status {run.proc.returncode}; stderr ends:\n  "
                + "\n  ".join(run.stderr_tail[-8:]))
        time.sleep(2.0 if children else 0.2)  # give orphaned workers time to notice, if they can
        orphans = [pid for pid in children if _alive(pid)]
        orphan_commands = [_command(pid) for pid in orphans]
        run.kill_group()
        run._reader.join(timeout=5)
        seen_t, seen_step = run.progress[-1]
        if seen_step >= steps:
            raise RuntimeError(f"the run had finished its {steps} steps before kill {i + 1}; raise --steps")
        rate = (seen_step - run.progress[0][1]) / max(seen_t - run.progress[0][0], 1e-9) if len(run.progress) > 1 else 0
        ckpt_step, ckpt_mtime = _checkpoint_step(run_dir / "checkpoint.pt")
        since = max(0.0, t_kill - max(ckpt_mtime, started))
        at_kill = seen_step + int(round(rate * (t_kill - seen_t)))
        stale = len(list(run_dir.glob("checkpoint.pt*.tmp")))
        pending = Kill(index=i + 1, after_s=t_kill - started, last_seen_step=seen_step,
                       lost_steps=max(0, at_kill - ckpt_step), lost_s=since, checkpoint_step=ckpt_step,
                       stale_tmp_files=stale, orphans=len(orphans), orphan_commands=orphan_commands, signal=name,
                       exit_ok=polite_ok)
        result.kills.append(pending)
        log(f"kill {i + 1}: {pending.after_s:.1f} s in, last seen step {seen_step}, checkpoint at step {ckpt_step} "
            f"({since:.1f} s before the kill), {len(orphans)} orphaned processes")
    result.duplicated_log_rows = _duplicated_rows(run_dir / "log.csv")
    if check_truncated:
        result.corrupt_checkpoint_error, result.corrupt_checkpoint_ok = _check_truncated(
            primitive, root, run_dir, steps, interval_s, workers, seed, env)
    result.wall_s = time.time() - t0
    return result


def _duplicated_rows(path: Path) -> int:
    """Rows of a training log whose step is not above the previous row's (a resumed run logging steps again)."""
    if not path.exists():
        return 0
    with open(path) as f:
        steps = [int(line.split(",", 1)[0]) for line in f.read().splitlines()[1:] if line[:1].isdigit()]
    return int(sum(b <= a for a, b in zip(steps, steps[1:])))


def _check_truncated(primitive, root: Path, run_dir: Path, steps, interval_s, workers, seed, env) -> tuple[str, bool]:
    """``--resume`` from a half-length copy of the checkpoint: a one-line error and exit status 2?"""
    broken = root / "truncated"
    broken.mkdir(parents=True, exist_ok=True)
    data = (run_dir / "checkpoint.pt").read_bytes()
    (broken / "checkpoint.pt").write_bytes(data[: len(data) // 2])
    proc = subprocess.run(train_command(primitive, broken, steps, interval_s, workers, seed, resume=True),
                          capture_output=True, text=True, env=env, timeout=300)
    lines = [line for line in proc.stderr.strip().splitlines() if line.strip()]
    message = lines[-1] if lines else ""
    ok = proc.returncode == 2 and "Traceback" not in proc.stderr and "checkpoint" in message
    return message, ok


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m primitives.research.killtest",
        description="SIGKILL a training run at random moments, resume it with --resume each time, and check that "
                    "it continues from its last checkpoint, loses at most one checkpoint interval, and finishes.",
        epilog="examples:\n"
               "  python -m primitives.research.killtest push --kills 5 --out /tmp/killtest\n"
               "  python -m primitives.research.killtest spin --kills 3 --workers 1 --out /tmp/kt --overwrite --json",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("primitive", choices=PRIMITIVES)
    p.add_argument("--kills", type=int, default=5, help="stops before the final run (default: %(default)s)")
    p.add_argument("--signals", nargs="+", choices=("KILL", "INT", "TERM"), default=["KILL"],
                   help="the signal of each stop, in turn (default: %(default)s)")
    p.add_argument("--out", required=True, help="folder for the run (created; must not exist)")
    p.add_argument("--steps", type=int, default=4000, help="primitives in the whole run (default: %(default)s)")
    p.add_argument("--checkpoint-seconds", type=float, default=3.0,
                   help="checkpoint interval (default: %(default)s)")
    p.add_argument("--workers", type=int, default=0, help="rollout processes of the run (default: %(default)s)")
    p.add_argument("--seed", type=int, default=0, help="seeds the kill moments and the run (default: %(default)s)")
    p.add_argument("--timeout", type=float, default=600.0, help="seconds the final run may take")
    p.add_argument("--overwrite", action="store_true", help="delete OUT first if it exists")
    p.add_argument("--json", action="store_true", help="print JSON instead of a report")
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    cli_logging()
    quiet = (lambda message: None) if args.json else logger.info
    result = killtest(args.primitive, args.kills, args.out, args.steps, args.checkpoint_seconds, args.workers,
                      args.seed, args.timeout, args.overwrite, log=quiet, signals=tuple(args.signals))
    print(json.dumps(result.as_dict(), indent=2) if args.json else result.report())
    return 0 if result.ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
