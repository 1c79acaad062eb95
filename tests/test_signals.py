"""Ctrl-C stops a long run: ``granrs.simulate``, ``granrs.sweep`` (its validation included)
and ``granrs run``, within 0.5 s; the API raises ``KeyboardInterrupt``, the command line
exits 130.

Each test starts a child Python on a run that takes minutes, waits until the child says it
is about to call in, lets the call get going, sends SIGINT and times how long the child takes
to catch it (the child prints the monotonic clock, which is system-wide, when it does). Before
the runs looked at a cancellation flag, none of these calls saw SIGINT until its work was
done: each test then timed out instead.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import pytest

import granrs
from granrs.scenefile import dumps

#: The acceptance bound: from SIGINT to the caller having KeyboardInterrupt in hand.
STOP_WITHIN = 0.5
#: How long the child runs its call before SIGINT (the call is well under way by then).
LEAD = 0.5
#: A free link that runs for minutes: 1e8 steps to t_end (more than a minute even at
#: 0.3 us a step).
LONG = granrs.cases.free_link(q_deg=30.0, v0=2.0).replace(t_end=2000.0, dt=2e-5, end="time")

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")

PREAMBLE = """
import sys, time
import numpy as np
import granrs
from granrs import _granrs

def caught():
    print("caught", time.monotonic(), flush=True)
"""


def _child_env() -> dict[str, str]:
    """This process's environment, with the granrs under test first on the path."""
    env = dict(os.environ)
    package_root = str(Path(granrs.__file__).resolve().parent.parent)
    env["PYTHONPATH"] = os.pathsep.join([package_root, env.get("PYTHONPATH", "")])
    return env


def _default_sigint() -> None:
    # A child of a shell's background job inherits SIGINT ignored, and Python then never
    # installs its handler: give the child the default disposition, as a terminal would.
    signal.signal(signal.SIGINT, signal.SIG_DFL)


class Child:
    """A child Python running `code`, its output lines read as they come."""

    def __init__(self, code: str, argv: tuple[str, ...] = ()) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, "-c", code, *argv],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=_child_env(),
            preexec_fn=_default_sigint,
        )
        self.lines: list[str] = []
        self.errors: list[str] = []
        self._cond = threading.Condition()
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()
        self._err_reader = threading.Thread(target=self._read_errors, daemon=True)
        self._err_reader.start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            with self._cond:
                self.lines.append(line.strip())
                self._cond.notify_all()

    def _read_errors(self) -> None:
        assert self.proc.stderr is not None
        for line in self.proc.stderr:
            self.errors.append(line)

    @property
    def stderr(self) -> str:
        return "".join(self.errors)

    def wait_for(self, word: str, timeout: float) -> str:
        """The first output line starting with `word` (fails after `timeout` s)."""
        deadline = time.monotonic() + timeout
        with self._cond:
            while True:
                for line in self.lines:
                    if line.startswith(word):
                        return line
                left = deadline - time.monotonic()
                if left <= 0 or (self.proc.poll() is not None and not self._reader.is_alive()):
                    break
                self._cond.wait(min(left, 0.1))
        self.kill()
        raise AssertionError(f"no {word!r} line in {timeout} s: {self.lines}\n{self.stderr}")

    def kill(self) -> None:
        """End the child (if it is still running) and read the rest of its output."""
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait()
        self._reader.join(timeout=10)
        self._err_reader.join(timeout=10)
        for pipe in (self.proc.stdout, self.proc.stderr):
            if pipe is not None:
                pipe.close()

    def interrupt_after_ready(self) -> float:
        """Wait for "ready", give the call `LEAD` s, send SIGINT; the latency to "caught"."""
        self.wait_for("ready", timeout=120)
        time.sleep(LEAD)
        assert self.proc.poll() is None, f"the child ended early: {self.lines}"
        sent = time.monotonic()
        self.proc.send_signal(signal.SIGINT)
        line = self.wait_for("caught", timeout=30)
        return float(line.split()[1]) - sent


def _run_child(body: str) -> Child:
    return Child(PREAMBLE + textwrap.dedent(body))


def _scene_code(scene: granrs.Scene) -> str:
    """Code that rebuilds `scene` in the child (from its TOML)."""
    return f"import granrs.scenefile\nscene = granrs.scenefile.loads({dumps(scene)!r})\n"


def _assert_stopped(child: Child, latency: float) -> None:
    print(f"caught {latency:.3f} s after SIGINT")
    child.proc.wait(timeout=30)
    child.kill()
    assert latency < STOP_WITHIN, f"caught {latency:.3f} s after SIGINT"
    assert child.proc.returncode == 0, (child.lines, child.stderr)


def test_ctrl_c_stops_simulate() -> None:
    """A minutes-long ``simulate`` raises KeyboardInterrupt within 0.5 s of SIGINT."""
    child = _run_child(
        _scene_code(LONG)
        + """
print("ready", flush=True)
try:
    granrs.simulate(scene)
except KeyboardInterrupt:
    caught()
    sys.exit(0)
print("finished", flush=True)
sys.exit(1)
"""
    )
    _assert_stopped(child, child.interrupt_after_ready())


def test_ctrl_c_stops_a_sweep_and_its_runs_in_flight() -> None:
    """A sweep whose runs each take minutes stops within 0.5 s (before, it waited for the
    runs in flight)."""
    child = _run_child(
        _scene_code(LONG)
        + """
print("ready", flush=True)
try:
    granrs.sweep(scene, v0=[1.0, 2.0, 3.0], threads=2, progress=False)
except KeyboardInterrupt:
    caught()
    sys.exit(0)
print("finished", flush=True)
sys.exit(1)
"""
    )
    _assert_stopped(child, child.interrupt_after_ready())


def test_ctrl_c_stops_a_sweeps_validation() -> None:
    """``granrs.sweep`` over ten million runs, interrupted while the core validates them
    (many seconds of work, before any run starts), stops within 0.5 s. The child says when
    the sweep calls the core's validation."""
    child = _run_child(
        _scene_code(granrs.cases.free_link(q_deg=0.0, v0=2.0))
        + """
import granrs.batch

class Announce:
    # The core module, saying when the sweep calls its validation.
    def __getattr__(self, name):
        attr = getattr(_granrs, name)
        if name != "validate_sweep":
            return attr
        def call(*args, **kwargs):
            print("ready", flush=True)
            return attr(*args, **kwargs)
        return call

granrs.batch._granrs = Announce()
try:
    granrs.sweep(
        scene, q_deg=np.linspace(-60, 60, 4000), v0=np.linspace(1, 3, 2500), progress=False
    )
except KeyboardInterrupt:
    caught()
    sys.exit(0)
print("finished", flush=True)
sys.exit(1)
"""
    )
    _assert_stopped(child, child.interrupt_after_ready())


def test_ctrl_c_stops_granrs_run_with_exit_130(tmp_path: Path) -> None:
    """``granrs run`` on a minutes-long scene: SIGINT stops it within 0.5 s (its "interrupted"
    line) and it exits 130."""
    path = tmp_path / "long.toml"
    path.write_text(dumps(LONG))
    code = textwrap.dedent(
        """
        import sys, time
        import granrs, granrs.api
        from granrs.cli import main
        print("ready", flush=True)
        code = main(["run", sys.argv[1]])
        print("caught", time.monotonic(), flush=True)
        sys.exit(code)
        """
    )
    child = Child(code, (str(path),))
    latency = child.interrupt_after_ready()
    print(f"stopped {latency:.3f} s after SIGINT")
    child.proc.wait(timeout=30)
    child.kill()
    assert child.proc.returncode == 130, (child.lines, child.stderr)
    assert "interrupted" in child.stderr, child.stderr
    assert latency < STOP_WITHIN, f"stopped {latency:.3f} s after SIGINT"
