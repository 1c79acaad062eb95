"""``import granrs`` loads none of the large libraries that a run does not need (pandas and
the pyarrow it brings, matplotlib, scipy, ...): each is imported where it is first used (a
sweep's DataFrame, a plot, a calibration), and every public name still resolves. Each check
runs in a fresh interpreter, since the test session has imported them all."""

from __future__ import annotations

import json
import subprocess
import sys

#: Libraries granrs uses but a run does not need: none is loaded by ``import granrs``.
HEAVY = (
    "pandas",
    "pyarrow",
    "matplotlib",
    "scipy",
    "emcee",
    "dask",
    "distributed",
    "tqdm",
    "mujoco",
    "gymnasium",
    "trimesh",
)


def _loaded(code: str) -> set[str]:
    """The top-level packages loaded after ``code`` runs in a fresh interpreter."""
    report = (
        "import sys, json; print(json.dumps(sorted({m.partition('.')[0] for m in sys.modules})))"
    )
    out = subprocess.run(
        [sys.executable, "-c", f"{code}\n{report}"], check=True, capture_output=True, text=True
    )
    return set(json.loads(out.stdout.splitlines()[-1]))


def test_import_granrs_loads_no_large_library() -> None:
    assert _loaded("import granrs") & set(HEAVY) == set()


def test_a_simulation_loads_none_either() -> None:
    code = (
        "import granrs\n"
        "r = granrs.simulate(granrs.cases.free_link(q_deg=45, v0=2.27))\n"
        "assert r.status == 'stopped' and r.summary['depth'] > 0"
    )
    assert _loaded(code) & set(HEAVY) == set()


def test_every_public_name_resolves_and_a_sweep_gives_a_dataframe() -> None:
    code = (
        "import granrs\n"
        "missing = [n for n in granrs.__all__ if getattr(granrs, n, None) is None]\n"
        "assert not missing, missing\n"
        "import pandas as pd\n"
        "df = granrs.sweep(granrs.cases.free_link(q_deg=0, v0=2.0), v0=[1.0, 2.0])\n"
        "assert isinstance(df, pd.DataFrame) and len(df) == 2"
    )
    assert {"pandas", "matplotlib"} <= _loaded(code)
