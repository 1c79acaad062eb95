"""Sweeps share one bounded pool: ``threads`` above the machine's cores runs on every core
with a warning, and sweeping at many thread counts in turn leaves no more threads than cores.

Before, every thread count kept a pool of its own: ``threads=1000`` left 1,002 OS threads,
and thread counts 1 to 40 in turn left 822 alive, with no word about the cores.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pandas as pd
import pytest

import granrs
from granrs import _granrs, cases

BASE = cases.free_link(q_deg=0.0, v0=2.0)
AXES = {"q_deg": [-20.0, 0.0, 35.0], "v0": [1.0, 2.5]}


def _cores() -> int:
    """What this process may run on."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def test_max_threads_is_the_cores() -> None:
    """The pool's size is what the process may run on (its CPU affinity)."""
    assert _granrs.max_threads() == _cores()


def test_threads_above_the_cores_run_on_every_core_with_a_warning() -> None:
    """``threads`` past the cores: a RuntimeWarning naming both counts, and the rows of a
    one-thread sweep."""
    cores = _cores()
    one = granrs.sweep(BASE, threads=1, progress=False, **AXES)
    with pytest.warns(RuntimeWarning, match=rf"threads={cores + 7} .* {cores} cores"):
        many = granrs.sweep(BASE, threads=cores + 7, progress=False, **AXES)
    pd.testing.assert_frame_equal(one, many)


def test_threads_up_to_the_cores_say_nothing(recwarn: pytest.WarningsRecorder) -> None:
    granrs.sweep(BASE, threads=_cores(), progress=False, **AXES)
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]


@pytest.mark.skipif(
    not Path("/proc/self/task").is_dir() or not hasattr(os, "sched_getaffinity"),
    reason="needs /proc and sched_getaffinity",
)
def test_forty_thread_counts_in_turn_leave_no_more_threads_than_cores() -> None:
    """In a fresh process: sweeps at threads = 1..40 (and one at 1000), then the validation
    at each, leave at most one thread per core beyond those the process had after import."""
    code = textwrap.dedent(
        """
        import os, warnings
        import granrs
        # A sweep's frame needs pandas, which `import granrs` no longer loads: pandas (its
        # pyarrow) starts threads of its own when imported, counted here with the others.
        import pandas
        from granrs import _granrs, cases

        def tasks():
            return len(os.listdir("/proc/self/task"))

        base = cases.free_link(q_deg=0.0, v0=2.0)
        before = tasks()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            for n in [*range(1, 41), 1000]:
                granrs.sweep(base, threads=n, progress=False, v0=[1.0, 2.0, 3.0])
                _granrs.validate_sweep(base=base._plain(), axes=[("v0", [1.0, 2.0])], threads=n)
        print(before, tasks(), len(os.sched_getaffinity(0)))
        """
    )
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(
        [str(Path(granrs.__file__).resolve().parent.parent), env.get("PYTHONPATH", "")]
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300
    )
    assert out.returncode == 0, out.stderr
    before, after, cores = map(int, out.stdout.split())
    assert after - before <= cores, f"{after - before} threads started for {cores} cores"
