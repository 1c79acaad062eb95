"""The ``granrs`` command line.

Usage::

    granrs --version
    granrs run SCENE.toml [--set FIELD=VALUE ...] [--series OUT.csv|OUT.parquet] [--json]
    granrs animate SCENE.toml [--out OUT.gif|OUT.mp4|OUT.html] [--frame-dt S] [--speed X]
                   [--fps N] [--dpi DPI] [--quiet] [--set FIELD=VALUE ...]
    granrs scene new [--body BODY] [--out FILE]
    granrs reproduce [--out DIR] [--dt DT] [--chapter KEY ...] [--quiet]
    granrs bench accuracy [--out DIR] [--quick] [--repeats N] [--quiet]
    granrs calibrate [--cases BODY] [--measurements thesis:NAME|FILE.csv] [--params P,...]
                     [--per-angle] [--base NAME] [--fit ROWS] [--predict ROWS] [--json]
                     [--out FILE.csv]
    granrs compare [--laws L,...] [--measurements SPEC ...] [--folds COLUMN|auto|none]
                   [--starts N] [--dt DT] [--json] [--out FILE.json] [--quiet]

Each subcommand is one ``_add_<name>`` function that declares its arguments and one
``_cmd_<name>`` function that runs it and returns the exit code; :data:`_COMMANDS` lists
them.

Exit codes: 0 on success; 2 for invalid input (a usage error, a scene file that cannot be
read, or any :class:`~granrs.errors.GranrsError` but a simulation failure: one line on
stderr naming the field and the file and line, no traceback); 1 when the simulation fails
(:class:`~granrs.errors.SimulationError`) or an output file cannot be written; 130 on Ctrl-C.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import math
import numbers
import os
import sys
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from . import __version__
from ._files import check_target, replacing, write_text
from .errors import (
    CoefficientsWarning,
    GranrsError,
    InvalidParameterError,
    InvalidSceneError,
    SimulationError,
    StepSizeWarning,
)
from .space import Result as SpaceResult
from .space import Scene as SpaceScene

__all__ = ["main"]

PROG = "granrs"
#: Exit code of invalid input (argparse's usage errors use the same).
EXIT_INVALID = 2
#: Exit code of an operating-system error (e.g. the output directory is not writable).
EXIT_OS_ERROR = 1
#: Exit code of a failed simulation (a non-finite state).
EXIT_SIMULATION = 1
#: Exit code after Ctrl-C.
EXIT_INTERRUPTED = 130


def _add_reproduce(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Declare ``granrs reproduce``."""
    from .report import CHAPTERS

    parser = sub.add_parser(
        "reproduce",
        help="run the thesis's cases and write the reproduction report",
        description=(
            "Run the thesis's cases, compare them with its tables and write DIR/README.md "
            "(Markdown) with its PNG figures in DIR/figures/. Nothing is written if a run "
            "fails."
        ),
    )
    parser.add_argument(
        "--out",
        metavar="DIR",
        default="granrs-report",
        help="output directory (default: ./granrs-report)",
    )
    parser.add_argument(
        "--dt",
        type=float,
        default=1e-4,
        metavar="DT",
        help="integration step in seconds (default: 1e-4, the thesis's 10 kHz)",
    )
    parser.add_argument(
        "--chapter",
        dest="chapters",
        action="append",
        choices=list(CHAPTERS),
        metavar="KEY",
        help=f"chapter to run, repeatable (available: {', '.join(CHAPTERS)}; default: all)",
    )
    parser.add_argument("--quiet", action="store_true", help="no progress output")
    parser.set_defaults(handler=_cmd_reproduce)


def _cmd_reproduce(args: argparse.Namespace) -> int:
    """Run ``granrs reproduce``."""
    from .report import CHAPTERS, reproduce

    chapters = tuple(args.chapters) if args.chapters else tuple(CHAPTERS)
    path = reproduce(args.out, chapters=chapters, dt=args.dt, progress=not args.quiet)
    if not args.quiet:
        print(f"report written to {path}")
    return 0


def _add_bench(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Declare ``granrs bench``."""
    parser = sub.add_parser(
        "bench",
        help="run a benchmark (accuracy: error against time of each integrator setting)",
        description=(
            "Run a benchmark. 'accuracy' compares RK4 (each sign model, a sweep of dt) and "
            "dopri5 (a sweep of rtol) with a fine reference on three free-link scenes and "
            "writes DIR/accuracy.csv, DIR/accuracy.png and DIR/accuracy.md."
        ),
    )
    parser.add_argument("name", choices=["accuracy"], help="benchmark to run")
    parser.add_argument(
        "--out",
        metavar="DIR",
        default="granrs-bench",
        help="output directory (default: ./granrs-bench)",
    )
    parser.add_argument(
        "--quick", action="store_true", help="shorter sweeps and a coarser reference"
    )
    parser.add_argument(
        "--repeats", type=int, default=3, metavar="N", help="timing repeats (default: 3)"
    )
    parser.add_argument("--quiet", action="store_true", help="no progress output")
    parser.set_defaults(handler=_cmd_bench)


def _cmd_bench(args: argparse.Namespace) -> int:
    """Run ``granrs bench``."""
    from .bench import work_precision

    if args.repeats < 1:
        raise InvalidParameterError(
            f"--repeats must be a whole number >= 1; got {args.repeats}", field="repeats"
        )
    work_precision(args.out, quick=args.quick, repeats=args.repeats, progress=not args.quiet)
    if not args.quiet:
        print(f"benchmark written to {args.out}")
    return 0


def _add_calibrate(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Declare ``granrs calibrate``."""
    parser = sub.add_parser(
        "calibrate",
        help="fit the force coefficients (or the leg's joints) to measured depth and t_s",
        description=(
            "Fit parameters of the force law by weighted least squares to measured depths "
            "and stopping times (granrs.calibrate), print the fitted values with standard "
            "errors and ~95% intervals and each row's residuals in units of the measured sd; "
            "optionally predict other rows out of sample."
        ),
    )
    parser.add_argument(
        "--cases",
        choices=["free_link", "chain", "leg"],
        default=None,
        help="the body (default: the thesis table's, or free_link for a CSV)",
    )
    parser.add_argument(
        "--measurements",
        default="thesis:table_3_1",
        metavar="SPEC",
        help=(
            "thesis:table_3_1 (default), thesis:table_4_chain, thesis:table_5_1_means, "
            "thesis:table_5_1, or a CSV file with the same columns"
        ),
    )
    parser.add_argument(
        "--params",
        default="eta_h,eta_d,eta_v,lam",
        metavar="P,...",
        help=(
            "comma-separated parameters: any term's as TERM.PARAM (static_v.eta_v, rft.zeta, "
            "poncelet.k), a factor on one as scale.TERM.PARAM, a free-link angle node as "
            "TERM.PARAM@45; the body's unknowns mass, pin_mass, joints.k, joints.c; the "
            "thesis's short names eta_h, eta_d, eta_v, lam also work"
        ),
    )
    parser.add_argument(
        "--per-angle", action="store_true", help="free link: one value per measured angle"
    )
    parser.add_argument(
        "--base", default=None, help="base coefficients: table_3_4 (default) or table_3_2"
    )
    parser.add_argument(
        "--fit",
        metavar="COLUMN=V,...",
        default=None,
        help="fit only these rows, e.g. q_deg=0,45,75 or v0_case=1,2",
    )
    parser.add_argument(
        "--predict",
        metavar="COLUMN=V,...",
        default=None,
        help="predict these rows with the fitted values (out of sample), e.g. q_deg=60",
    )
    parser.add_argument("--starts", type=int, default=1, metavar="N", help="starts (default 1)")
    parser.add_argument("--dt", type=float, default=1e-4, metavar="DT", help="step [s]")
    parser.add_argument("--json", action="store_true", help="print the result as JSON")
    parser.add_argument(
        "--out", metavar="FILE.csv", default=None, help="write the residuals per row to CSV"
    )
    parser.add_argument(
        "--card",
        metavar="FILE.toml",
        default=None,
        help=(
            "write the fit as a medium card (granrs.media), named after the file: each "
            "fitted term's parameter with its source, sd and ~95%% interval"
        ),
    )
    parser.add_argument(
        "--quiet", action="store_true", help="no progress bar (shown on a terminal)"
    )
    parser.set_defaults(handler=_cmd_calibrate)


def _row_filter(text: str, option: str) -> tuple[str, list[float]]:
    """``COLUMN=V,...`` -> (column, values)."""
    column, sep, values = text.partition("=")
    try:
        if not sep or not column.strip():
            raise ValueError
        numbers_ = [float(v) for v in values.split(",") if v.strip()]
        if not numbers_:
            raise ValueError
    except ValueError:
        raise InvalidParameterError(
            f"{option} {text!r}: expected COLUMN=V,... (e.g. q_deg=0,45,75)",
            field=option.lstrip("-"),
        ) from None
    return column.strip(), numbers_


def _cmd_calibrate(args: argparse.Namespace) -> int:
    """Run ``granrs calibrate``."""
    from .calibrate import Measurements, calibrate

    if args.out:
        check_target(args.out, "out", "the residuals to")
    if args.card:
        from pathlib import Path

        from .media import MediumCard

        check_target(args.card, "card", "the medium card to")
        MediumCard(Path(args.card).stem)  # the card's name: a bad one is refused here
    measurements = Measurements.load(args.measurements, args.cases)
    cases = args.cases or measurements.body
    fit_rows = measurements
    if args.fit:
        column, values = _row_filter(args.fit, "--fit")
        fit_rows = measurements.subset(**{column: values})
    test_rows = None
    if args.predict:
        column, values = _row_filter(args.predict, "--predict")
        test_rows = measurements.subset(**{column: values})
    if args.starts < 1:
        raise InvalidParameterError(f"--starts must be >= 1; got {args.starts}", field="starts")
    params = [p.strip() for p in args.params.split(",") if p.strip()]
    kwargs: dict[str, Any] = {
        "per_angle": args.per_angle,
        "starts": args.starts,
        "dt": args.dt,
        "progress": False if args.quiet else None,
    }
    if args.base:
        kwargs["base"] = args.base
    result = calibrate(cases, fit_rows, params, **kwargs)
    frame = result.residuals.assign(set="fit")
    predicted = None
    if test_rows is not None and len(test_rows):
        predicted = result.predict(test_rows).assign(set="predicted")
        frame = _concat([frame, predicted])
    if args.out:
        with replacing(args.out) as tmp:
            frame.to_csv(tmp, index=False)
    if args.card:
        result.card(Path(args.card).stem).save(args.card)
    if args.json:
        out = result.to_dict()
        if predicted is not None:
            out["predicted"] = predicted.to_dict("records")
        print(json.dumps(_plain(out), indent=2, allow_nan=False))
        return 0
    print(result.summary())
    columns = [c for c in _CALIBRATE_COLUMNS if c in frame.columns]
    header = list(columns)
    rows = [[_number(v) for v in row] for row in frame[columns].itertuples(index=False)]
    print()
    print("\n".join(_table(header, rows)))
    if predicted is not None:
        from .calibrate import within

        print(
            f"predicted rows: depth within 1 sd {within(predicted, 'depth', 1)}, t_s within "
            f"2 sd {within(predicted, 't_s', 2)} of {len(predicted)}"
        )
    return 0


def _add_compare(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Declare ``granrs compare``."""
    parser = sub.add_parser(
        "compare",
        help="compare force laws on the experiments, cross-validated (granrs.compare)",
        description=(
            "Fit every force law to the measurements and check it out of sample by "
            "leave-one-group-out cross-validation (granrs.compare); print one line per "
            "dataset and law: parameters, in-sample chi2/dof, AIC, BIC, and the "
            "out-of-sample counts within 1 and 2 sd."
        ),
    )
    parser.add_argument(
        "--laws",
        default=None,
        metavar="L,...",
        help="comma-separated law names (default: every law of granrs.compare.LAWS)",
    )
    parser.add_argument(
        "--measurements",
        action="append",
        default=None,
        metavar="SPEC",
        help=(
            "thesis:table_3_1, thesis:table_4_chain, thesis:table_5_1_means, "
            "thesis:table_5_1 (repeat for several; default: the first three)"
        ),
    )
    parser.add_argument(
        "--folds",
        default="auto",
        metavar="COLUMN",
        help="the column whose groups are left out one at a time: auto (default), none, "
        "or a column name",
    )
    parser.add_argument("--starts", type=int, default=1, metavar="N", help="starts (default 1)")
    parser.add_argument("--dt", type=float, default=1e-4, metavar="DT", help="step [s]")
    parser.add_argument("--json", action="store_true", help="print {dataset: {law: {...}}}")
    parser.add_argument(
        "--out", metavar="FILE.json", default=None, help="write {dataset: {law: {...}}} here"
    )
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.set_defaults(handler=_cmd_compare)


#: The columns ``granrs compare`` prints.
_COMPARE_COLUMNS: tuple[str, ...] = (
    "dataset",
    "law",
    "rank",
    "n_params",
    "chi2_dof",
    "aic",
    "bic",
    "depth_within_1sd",
    "ts_within_1sd",
    "ts_within_2sd",
    "failed_out_of_sample",
    "n_rows",
)


def _cmd_compare(args: argparse.Namespace) -> int:
    """Run ``granrs compare``."""
    from .calibrate import Measurements
    from .compare import compare, to_json

    if args.out:
        check_target(args.out, "out", "the comparison to")
    laws = None
    if args.laws is not None:
        laws = [name.strip() for name in args.laws.split(",") if name.strip()]
    measurements = None
    if args.measurements:
        measurements = {}
        for spec in args.measurements:
            m = Measurements.load(spec)
            name = m.body if m.body not in measurements else spec.removeprefix("thesis:")
            measurements[name] = m
    folds = None if args.folds == "none" else args.folds
    frame = compare(
        laws,
        measurements,
        folds=folds,
        dt=args.dt,
        starts=args.starts,
        progress=False if args.quiet else None,
    )
    data = to_json(frame)
    text = json.dumps(data, indent=2, allow_nan=False)
    if args.out:
        write_text(args.out, text + "\n")
    if args.json:
        print(text)
        return 0
    rows, notes = [], []
    for rec in frame.to_dict("records"):
        if not rec["available"]:
            rows.append([rec["dataset"], rec["law"], *["-"] * (len(_COMPARE_COLUMNS) - 2)])
            notes.append(f"{rec['dataset']} {rec['law']}: not run: {rec['reason']}")
            continue
        rows.append([_number(rec[c]) for c in _COMPARE_COLUMNS])
        if rec["failed_in_sample"] or rec["failed_out_of_sample"]:
            notes.append(
                f"{rec['dataset']} {rec['law']}: runs failed on {rec['failed_in_sample']} of "
                f"{rec['n_rows']} rows in sample and {rec['failed_out_of_sample']} out of "
                "sample (no prediction: chi2, AIC and BIC undefined where a row failed); "
                "ranked after the laws whose rows all ran; a smaller --dt may resolve them"
            )
    header = ["failed" if c == "failed_out_of_sample" else c for c in _COMPARE_COLUMNS]
    print("\n".join(_table(header, rows)))
    if folds is None:
        print("(no cross-validation: every number in sample; rank by chi2)")
    else:
        print("(counts out of sample; chi2/dof, AIC, BIC in sample; rank by out-of-sample chi2)")
    for note in notes:
        print(note)
    return 0


#: The residual columns ``granrs calibrate`` prints.
_CALIBRATE_COLUMNS: tuple[str, ...] = (
    "set",
    "height_case",
    "link",
    "v0_case",
    "q_deg",
    "v0_mean",
    "depth_mean",
    "depth_sim",
    "depth_z",
    "t_s_mean",
    "t_s_sim",
    "t_s_z",
)


def _concat(frames: list[Any]) -> Any:
    """``pandas.concat`` of residual frames (pandas imported only when calibrating)."""
    import pandas as pd

    return pd.concat(frames, ignore_index=True)


#: What ``--series`` records when the scene records nothing.
SERIES_RECORD: tuple[str, ...] = ("state", "forces", "energy")
#: The output formats of ``--series``, by file extension.
SERIES_FORMATS: tuple[str, ...] = (".csv", ".parquet")


#: Units of the recorded series the core names itself (per contact, per joint, energies);
#: coordinates and rates take theirs from the body's names (``granrs.result``), a force
#: term's columns are forces (its ``columns`` in ``granrs.forces``).
_SERIES_UNITS: dict[str, str] = {
    "t": "s",
    "work_sand": "J",
    "tip_x": "m",
    "tip_y": "m",
    "depth": "m",
    "v_tip_x": "m/s",
    "v_tip_y": "m/s",
    "v_E_x": "m/s",
    "v_E_y": "m/s",
    "mode_x": "-",
    "mode_y": "-",
    "Fx": "N",
    "Fy": "N",
    "torque": "N m",
    "KE": "J",
    "PE": "J",
    "E": "J",
    "joint_loss": "J",
}


def series_units(result: Any) -> dict[str, str]:
    """The unit of each recorded series of ``result`` (``Result.series``'s names): SI, angles
    in rad (a name whose unit is not known here maps to ``""``)."""
    from . import _granrs
    from .result import _names

    names = _names(result.scene)
    units: dict[str, str] = {}
    for coords, position, angle in (
        (names["coords"], "m", "rad"),
        (names["rates"], "m/s", "rad/s"),
    ):
        for i, name in enumerate(coords):
            units[name] = position if i < 2 else angle
    units.update({"clock": "s", "clock_rate": "-"})
    for info in _granrs.term_infos():
        units.update({column: "N" for column in info["columns"]})
    out = {}
    for name in result.series:
        field = name.rsplit(".", 1)[-1] if "." in name else name
        out[name] = units.get(name) or _SERIES_UNITS.get(field) or units.get(field, "")
    return out


def _add_scene_file(parser: argparse.ArgumentParser) -> None:
    """The arguments of a command that runs a scene file: the file and its ``--set``s."""
    parser.add_argument("scene", metavar="SCENE.toml", help="the scene file")
    parser.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="FIELD=VALUE",
        help=(
            "override a field, repeatable; VALUE is TOML (q_deg=30, 'record=[\"state\"]', "
            "'knee={k=300.0, c=5.0}'); TERM.PARAM sets a force term's parameter "
            "(static_v.eta_v=300); a bare word is a string (body=chain); a body in space's "
            "fields likewise ('velocity=[0, 0, -2]', rft3d.zeta=2e6, body.shape.radius=0.01)"
        ),
    )


def _read_scene(path: str, overrides: dict[str, Any]) -> Any:
    """The scene in the file ``path`` with ``overrides`` applied; an unreadable file is an
    :class:`InvalidSceneError` naming it."""
    from . import scenefile

    try:
        return scenefile.load(path, overrides)
    except OSError as exc:
        reason = exc.strerror or str(exc)
        raise InvalidSceneError(f"cannot read scene file {path}: {reason}") from None


def _add_run(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Declare ``granrs run``."""
    parser = sub.add_parser(
        "run",
        help="run one scene file and print its summary",
        description=(
            "Run the scene in a TOML scene file (see granrs.scenefile; 'granrs scene new' "
            "writes one) and print its summary: the run's status and statistics, then each "
            "contact's results with units."
        ),
    )
    _add_scene_file(parser)
    parser.add_argument(
        "--series",
        metavar="OUT",
        help=(
            "write the recorded time series to OUT.csv or OUT.parquet (parquet needs "
            "pyarrow), one column per series named with its SI unit ('q [rad]', "
            "'depth [m]'); a scene that records nothing records state, forces and energy"
        ),
    )
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")
    parser.set_defaults(handler=_cmd_run)


def _series_format(path: str) -> str:
    """The extension of a ``--series`` file, checked (and pyarrow's presence for parquet)."""
    suffix = Path(path).suffix.lower()
    if suffix not in SERIES_FORMATS:
        raise InvalidSceneError(
            f"--series {path}: unknown extension {suffix or '(none)'!r}; "
            f"use {' or '.join(SERIES_FORMATS)}",
            field="series",
        )
    if suffix == ".parquet" and importlib.util.find_spec("pyarrow") is None:
        raise InvalidSceneError(
            f"--series {path}: writing parquet needs pyarrow: pip install pyarrow (or write .csv)",
            field="series",
        )
    check_target(path, "series", "the series to")
    return suffix


def _plain(value: Any) -> Any:
    """A JSON-ready value: numpy scalars to Python, NaN and infinities to None."""
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return value
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, numbers.Real):
        number = float(value)
        return number if math.isfinite(number) else None
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    return str(value)


def _contact_names(result: Any) -> list[str]:
    from .result import _names

    names = _names(result.scene)["links"]
    return [names[i] if i < len(names) else f"c{i}" for i in range(len(result.contacts))]


def summary_dict(result: Any, source: str | None = None) -> dict[str, Any]:
    """The run's summary as plain data (what ``granrs run --json`` prints): the scene file,
    body, where the coefficients come from, status, the run's statistics, each contact's
    results by name, each joint's largest force and torque, and the units. NaN (e.g. ``t_s``
    without a stop) is None."""
    from .result import SUMMARY_UNITS

    # The core's run-level entries of Result.summary (the rest are contact 0's).
    run = dict(result._raw_dict()["run"])
    contacts = {
        name: {"stopped": c.stopped, **c.summary}
        for name, c in zip(_contact_names(result), result.contacts, strict=True)
    }
    units = dict(SUMMARY_UNITS)
    units.update({"t_final": "s", "energy_start": "J", "energy_end": "J"})
    return _plain(
        {
            "scene": source,
            "body": result.scene.kind,
            "coefficients_source": result.scene.coefficients_source,
            "status": result.status,
            "t_s": result.t_s,
            "depth": result.depth,
            "run": run,
            "contacts": contacts,
            "joints": result.joints,
            "units": units,
        }
    )


def _number(value: Any) -> str:
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        number = float(value)
        return "-" if math.isnan(number) else f"{number:.6g}"
    return str(value)


def _table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> list[str]:
    """Rows of text columns, the first left-aligned and the others right-aligned."""
    widths = [max(len(row[i]) for row in [header, *rows]) for i in range(len(header))]

    def line(row: Sequence[str]) -> str:
        cells = [row[0].ljust(widths[0])]
        cells += [cell.rjust(width) for cell, width in zip(row[1:], widths[1:], strict=True)]
        return "  ".join(cells).rstrip()

    return [line(header), line(["-" * w for w in widths]), *(line(row) for row in rows)]


#: A joint's force (torque) below this fraction of the run's largest force (torque) is
#: round-off of the solve, not a load: ``granrs run`` prints it as 0.
ROUNDOFF_RTOL = 1e-9
#: The contact quantities that are forces [N] (the scale of :data:`ROUNDOFF_RTOL`).
_FORCE_KEYS: tuple[str, ...] = ("F_d_max", "F_s_end", "F_r_end")


def _joint_rows(result: Any) -> tuple[list[list[str]], bool]:
    """The joint table's rows, with forces and torques below :data:`ROUNDOFF_RTOL` of the
    run's largest printed as 0, and whether any was."""
    joints = result.joints

    def largest(values: Any) -> float:
        finite = [abs(float(v)) for v in values if math.isfinite(float(v))]
        return max(finite, default=0.0)

    force_scale = largest(
        [j.get("F_max", math.nan) for j in joints.values()]
        + [c.summary.get(k, math.nan) for c in result.contacts for k in _FORCE_KEYS]
    )
    torque_scale = largest([j.get("torque_max", math.nan) for j in joints.values()])
    zeroed = False

    def cell(value: float, scale: float) -> str:
        nonlocal zeroed
        if math.isfinite(value) and value != 0.0 and abs(value) < ROUNDOFF_RTOL * scale:
            zeroed = True
            return "0"
        return _number(value)

    rows = [
        [
            name,
            cell(float(j.get("F_max", math.nan)), force_scale),
            cell(float(j.get("torque_max", math.nan)), torque_scale),
        ]
        for name, j in joints.items()
    ]
    return rows, zeroed


def summary_text(result: Any, source: str | None = None) -> str:
    """The run's summary as a readable table (what ``granrs run`` prints): the status, the
    energies, where the coefficients come from, each contact's results (a scene without
    contacts says so) and each joint's largest force and torque."""
    from .result import SUMMARY_UNITS

    summary = result.summary

    def s(key: str) -> str:
        # A field the scene's outputs leave out: "-".
        return _number(summary.get(key, math.nan))

    title = f"{source}: " if source else ""
    lines = [
        f"{title}{result.scene.kind}, status {result.status} at t = {s('t_final')} s "
        f"({s('steps')} steps, {s('rhs_evals')} rhs evaluations, {s('events')} events)",
        f"energy: {s('energy_start')} J at the start, {s('energy_end')} J at the end",
    ]
    if result.contacts:
        lines += [f"coefficients: {result.scene.coefficients_source}", ""]
        names = _contact_names(result)
        keys = [k for k in result.contacts[0].summary if k in SUMMARY_UNITS]
        rows = [["stopped", "-", *(_number(c.stopped) for c in result.contacts)]]
        rows += [
            [
                key,
                SUMMARY_UNITS[key],
                *(_number(c.summary.get(key, math.nan)) for c in result.contacts),
            ]
            for key in keys
        ]
        lines += _table(["quantity", "unit", *names], rows)
        if result.status != "stopped" and any(c.stopped for c in result.contacts):
            # A contact's stop is its tip's vertical velocity reaching zero from below; the
            # run went on (a driven body, a run to t_end), so say what "stopped" means here.
            lines += [
                'note: "stopped" = the tip\'s downward velocity reached zero at t_s; the run went',
                f"on (status {result.status}), so the body need not be at rest there.",
            ]
    else:
        lines.append("no contacts: the sand never acts on this body")
    if result.joints:
        lines.append("")
        joint_rows, zeroed = _joint_rows(result)
        lines += _table(["joint", "F_max [N]", "torque_max [N m]"], joint_rows)
        if zeroed:
            lines.append(
                f"(0: below {ROUNDOFF_RTOL:g} of the run's largest force or torque, round-off)"
            )
    return "\n".join(lines)


def _cmd_run(args: argparse.Namespace) -> int:
    """Run ``granrs run``."""
    from . import scenefile
    from .api import simulate

    overrides = dict(scenefile.parse_override(item) for item in args.overrides)
    suffix = _series_format(args.series) if args.series else None
    scene = _read_scene(args.scene, overrides)
    if suffix and not scene.record:
        in_space = isinstance(scene.record, bool)
        scene = scene.replace(record=True if in_space else SERIES_RECORD)
        what = "every series column" if in_space else ", ".join(SERIES_RECORD)
        print(f"{PROG}: note: the scene records nothing; --series records {what}", file=sys.stderr)
    result = simulate(scene)
    in_space = isinstance(result, SpaceResult)
    if args.series:
        frame = _space_frame(result) if in_space else _planar_frame(result)
        with replacing(args.series) as tmp:
            if suffix == ".parquet":
                frame.to_parquet(tmp)
            else:
                frame.to_csv(tmp)
        print(
            f"{PROG}: series written to {args.series} ({len(frame)} rows, "
            f"{len(frame.columns) + 1} columns)",
            file=sys.stderr,
        )
    if args.json:
        as_dict = space_summary_dict if in_space else summary_dict
        print(json.dumps(as_dict(result, args.scene), indent=2, allow_nan=False))
    else:
        print((space_summary_text if in_space else summary_text)(result, args.scene))
    return 0


def _planar_frame(result: Any) -> Any:
    """A planar run's recorded series as a table, each column's unit in its name."""
    frame = result.to_frame()
    units = series_units(result)
    frame = frame.rename(columns=lambda name: f"{name} [{units[name]}]")
    frame.index.name = f"t [{units['t']}]"
    return frame


def _space_frame(result: Any) -> Any:
    """A body in space's recorded series as a table, each column's unit in its name."""
    import pandas as pd

    from .space import SERIES_COLUMNS

    series = result.series or {}
    frame = pd.DataFrame({k: v for k, v in series.items() if k != "t"})
    frame.index = pd.Index(series.get("t", []), name="t [s]")
    return frame.rename(columns=lambda n: f"{n} [{SERIES_COLUMNS.get(n, ('', ''))[0]}]")


def space_summary_dict(result: Any, source: str | None = None) -> dict[str, Any]:
    """A body in space's summary as plain data (``granrs run --json``): the scene file, the
    status, every summary field (NaN is None) and their units."""
    from .space import SUMMARY_FIELDS

    return {
        "scene": source,
        "body": "space",
        "status": result.status,
        "summary": {
            k: (None if isinstance(v, float) and math.isnan(v) else v)
            for k, v in result.summary.items()
        },
        "units": {k: unit for k, (unit, _) in SUMMARY_FIELDS.items()},
    }


def space_summary_text(result: Any, source: str | None = None) -> str:
    """A body in space's summary as a readable table (``granrs run``): the status, then
    every summary field with its unit and description."""
    from .space import SUMMARY_FIELDS

    title = f"{source}: " if source else ""
    shape = type(result.scene.body.shape).__name__.lower()
    lines = [f"{title}a {shape} in space, status {result.status}", ""]
    rows = [
        [name, _number(result.summary[name]), unit, text]
        for name, (unit, text) in SUMMARY_FIELDS.items()
        if name in result.summary
    ]
    lines += _table(["field", "value", "unit", ""], rows)
    return "\n".join(lines)


#: What ``granrs animate`` records (besides what the scene records already).
ANIMATE_RECORD: tuple[str, ...] = ("state", "forces")


def _add_animate(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Declare ``granrs animate``."""
    from .animation import DEFAULT_FPS, DEFAULT_FRAMES, DEFAULT_SPEED

    parser = sub.add_parser(
        "animate",
        help="run one scene file and write an animation of the impact (GIF, MP4 or HTML)",
        description=(
            "Run the scene in a TOML scene file, recording its state and forces, and write an "
            "animation of the impact. A planar scene: the body to scale, the sand, the "
            "immersed part, each contact's force split by term, the clock and the depth. A "
            "body in space (space = true): its surface in 3D at each recorded pose over the "
            "sand's surface, the sand's force as an arrow from its centre of mass, and the "
            "clock. Frame k shows t = k * frame_dt; speed = frame_dt * fps (give any two, or "
            "one). The output path is checked before the run."
        ),
    )
    _add_scene_file(parser)
    parser.add_argument(
        "--out",
        metavar="OUT",
        default="impact.gif",
        help=(
            "output file: .gif (Pillow), .mp4 (needs ffmpeg) or .html (a JavaScript player); "
            "default: ./impact.gif"
        ),
    )
    parser.add_argument(
        "--frame-dt",
        type=float,
        default=None,
        metavar="S",
        help="simulated seconds per frame (default: speed / fps)",
    )
    parser.add_argument(
        "--speed",
        type=float,
        default=None,
        metavar="X",
        help=f"simulated seconds per second of movie (default: {DEFAULT_SPEED:g}, "
        f"i.e. 50x slow motion, or faster so that the movie has at most {DEFAULT_FRAMES} "
        "frames)",
    )
    parser.add_argument(
        "--fps",
        type=float,
        default=None,
        metavar="N",
        help=f"frames per second of the movie (default: {DEFAULT_FPS:g})",
    )
    parser.add_argument(
        "--dpi", type=float, default=100.0, metavar="DPI", help="resolution (default: 100)"
    )
    parser.add_argument(
        "--quiet", action="store_true", help="no progress bar (shown on a terminal)"
    )
    parser.set_defaults(handler=_cmd_animate)


def _cmd_animate(args: argparse.Namespace) -> int:
    """Run ``granrs animate``."""
    from . import scenefile
    from ._animation import animate
    from .animation import check_output, playback
    from .api import simulate

    overrides = dict(scenefile.parse_override(item) for item in args.overrides)
    # Every argument is checked before the run: playback, the output path.
    playback(args.frame_dt, args.speed, args.fps)
    out = check_output(args.out)
    scene = _read_scene(args.scene, overrides)
    if isinstance(scene, SpaceScene):
        # A body in space records every series column (its pose and the sand's force) or none.
        scene = scene.replace(record=True)
    else:
        scene = scene.replace(record=tuple(dict.fromkeys((*scene.record, *ANIMATE_RECORD))))
    result = simulate(scene)
    # The defaults left out resolve against the run's length (at most DEFAULT_FRAMES frames).
    anim = animate(result, args.frame_dt, args.speed, args.fps, dpi=args.dpi)
    anim.write(out, progress=False if args.quiet else None)
    print(
        f"{PROG}: animation written to {out} ({anim.n_frames} frames, "
        f"{anim.frame_dt * 1e3:.4g} ms per frame, {anim.fps:.4g} fps, speed {anim.speed:.4g})",
        file=sys.stderr,
    )
    return 0


def _add_scene(sub: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    """Declare ``granrs scene``."""
    from .scene import BODIES

    parser = sub.add_parser(
        "scene",
        help="write a scene file template ('scene new')",
        description="Scene files: 'new' writes a commented scene file to start from.",
    )
    actions = parser.add_subparsers(dest="action", metavar="ACTION", required=True)
    new = actions.add_parser(
        "new",
        help="write a commented scene file (the thesis's scene for the body)",
        description=(
            "Write a scene file with every field of the body and a note on each: the "
            "thesis's free link (q = 0, v0 = 2.214 m/s), chain case 1, or the leg at "
            "3.28 m/s. Prints to stdout unless --out is given."
        ),
    )
    new.add_argument(
        "--body", choices=list(BODIES), default="free_link", help="the body (default: free_link)"
    )
    new.add_argument("--out", metavar="FILE", help="write to FILE instead of stdout")
    new.add_argument("--force", action="store_true", help="overwrite FILE if it exists")
    parser.set_defaults(handler=_cmd_scene)


def _cmd_scene(args: argparse.Namespace) -> int:
    """Run ``granrs scene new``."""
    from . import cases

    text = cases.template(args.body)
    if args.out is None:
        sys.stdout.write(text)
        return 0
    if os.path.exists(args.out) and not args.force:
        raise InvalidSceneError(f"{args.out} exists; pass --force to overwrite it", field="out")
    check_target(args.out, "out", "the scene file to")
    write_text(args.out, text)
    print(f"scene file written to {args.out}", file=sys.stderr)
    return 0


#: The subcommands, in help order: each adds its parser and sets ``handler``.
_COMMANDS: tuple[Callable[[argparse._SubParsersAction[argparse.ArgumentParser]], None], ...] = (
    _add_run,
    _add_animate,
    _add_scene,
    _add_reproduce,
    _add_bench,
    _add_calibrate,
    _add_compare,
)


def build_parser() -> argparse.ArgumentParser:
    """The ``granrs`` argument parser with every subcommand."""
    parser = argparse.ArgumentParser(
        prog=PROG,
        description="granrs: rods, linkages and feet sinking into sand.",
    )
    parser.add_argument("--version", action="version", version=f"{PROG} {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for add in _COMMANDS:
        add(sub)
    return parser


def _one_line(exc: BaseException) -> str:
    """The exception's message on one line, naming the offending field if it has one."""
    message = " ".join(str(exc).split()) or type(exc).__name__
    field = getattr(exc, "field", None)
    if field and field not in message:
        message += f" (field: {field})"
    return message


def _show_warning(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    file: Any = None,
    line: str | None = None,
) -> None:
    """A warning as one line on stderr (``granrs: warning: ...``), not Python's two."""
    print(f"{PROG}: warning: {' '.join(str(message).split())}", file=sys.stderr)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``granrs`` command line with ``argv`` (default: ``sys.argv[1:]``).

    Returns the exit code instead of exiting (also for ``--help``, ``--version`` and usage
    errors), so that it can be called from Python and tests.
    """
    try:
        # Building the parser imports the report's chapters (and pandas): a Ctrl-C there
        # stops the command as one during its work does.
        parser = build_parser()
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, usage errors
        return exc.code if isinstance(exc.code, int) else EXIT_INVALID
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    try:
        with warnings.catch_warnings():
            # granrs's own warnings are part of the command's output: one line each.
            for category in (CoefficientsWarning, StepSizeWarning):
                warnings.simplefilter("default", category)
            warnings.showwarning = _show_warning
            return int(args.handler(args))
    except SimulationError as exc:
        print(f"{PROG}: simulation failed: {_one_line(exc)}", file=sys.stderr)
        return EXIT_SIMULATION
    except GranrsError as exc:
        print(f"{PROG}: error: {_one_line(exc)}", file=sys.stderr)
        return EXIT_INVALID
    except OSError as exc:
        print(f"{PROG}: error: {_one_line(exc)}", file=sys.stderr)
        return EXIT_OS_ERROR
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
