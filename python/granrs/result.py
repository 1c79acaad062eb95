"""What a run returns: :class:`Result` (and :class:`ContactResult` per contact)."""

from __future__ import annotations

import html
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import _granrs
from .scene import Scene

__all__ = ["JOINT_NAMES", "LINK_NAMES", "SUMMARY_UNITS", "ContactResult", "Result"]

#: Units of the summary fields (the core's one table of output fields; ``status`` and a
#: contact's ``stopped`` have none, and a joint's fields are in ``Result.joints``).
SUMMARY_UNITS: dict[str, str] = {
    f["name"]: f["unit"]
    for f in _granrs.output_fields()
    if f["part"] != "joint" and f["name"] not in ("status", "stopped")
}

# Friendly names of the generalized coordinates of each body.
_COORDS = {
    "free_link": ("x", "y", "q"),
    "chain": ("x_pin", "y_pin", "q1", "q2"),
    "leg": ("x_ankle", "y_ankle", "q_foot", "q_shank", "q_thigh", "q_trunk"),
}
_RATES = {
    "free_link": ("vx", "vy", "omega"),
    "chain": ("vx_pin", "vy_pin", "omega1", "omega2"),
    "leg": ("vx_ankle", "vy_ankle", "omega_foot", "omega_shank", "omega_thigh", "omega_trunk"),
}
#: Names of each body's links (series ``link{i}.*``) and of the joint that carries each
#: link (series ``joint{i}.*``: the force and torque the link receives there).
LINK_NAMES = {
    "free_link": ("rod",),
    "chain": ("link1", "link2"),
    "leg": ("foot", "shank", "thigh", "trunk"),
}
JOINT_NAMES = {
    "free_link": ("root",),
    "chain": ("pin_on_link1", "pin"),
    "leg": ("root", "ankle", "knee", "hip"),
}


def _names(scene: Scene) -> dict[str, tuple[str, ...]]:
    """Names of a scene's coordinates, rates, links and joints: a built-in body's from the
    tables above; a linkage's from its links in the engine's order (coordinates
    ``x_root, y_root, q_<link>...``; the joint that carries each link, ``root`` for the root
    link)."""
    kind = scene.kind
    if kind != "linkage":
        return {
            "coords": _COORDS[kind],
            "rates": _RATES[kind],
            "links": LINK_NAMES[kind],
            "joints": JOINT_NAMES[kind],
        }
    body = scene.body
    order = body.order  # type: ignore[union-attr]
    carrier = {j.child: j.name for j in body.joints}  # type: ignore[union-attr]
    # A sinusoidal drive reads the time from a clock coordinate after the links'.
    clock = ("clock",) if any(j.amplitude_deg for j in body.joints) else ()  # type: ignore[union-attr]
    return {
        "coords": ("x_root", "y_root", *(f"q_{n}" for n in order), *clock),
        "rates": (
            "vx_root",
            "vy_root",
            *(f"omega_{n}" for n in order),
            *(f"{c}_rate" for c in clock),
        ),
        "links": order,
        "joints": tuple(carrier.get(n, "root") for n in order),
    }


@dataclass(frozen=True)
class ContactResult:
    """The results of one contact.

    Attributes:
        t_s: stopping time [s]: when the tip's vertical velocity reaches zero from below
            (NaN if it did not stop).
        depth: depth of the tip at the stop (or at the end without one) [m].
        stopped: whether the stop happened.
        summary: every scalar result of the contact (see ``SUMMARY_UNITS``).
    """

    t_s: float
    depth: float
    stopped: bool
    summary: dict[str, Any]


class Result:
    """The outcome of :func:`granrs.simulate`; :func:`granrs.animate` draws one recorded with
    ``record=("state", "forces")``.

    The run's numbers stay in the Rust core until they are read: ``status``, ``t_s`` and
    ``depth`` come straight from it, and the rest is converted on first access (so a loop
    that reads only the headline numbers pays for nothing else).

    Attributes:
        scene: the scene that was run.
        status: ``"stopped"``, ``"end_time"`` (ran to t_end as asked) or ``"not_stopped"``
            (t_end came before the stop the scene waits for).
        t_s: stopping time of contact 0 [s] (NaN if it did not stop).
        depth: depth of contact 0 at its stop [m].
        summary: contact 0's results plus the run's: t_s, depth, dq, omega_end, F_d_max,
            F_s_end, F_r_end, dKE, dPE, dE (thesis eqs. 3.22-3.26), steps, rhs_evals, ...;
            those of ``scene.outputs`` only, when the scene lists them (``status`` always).
        contacts: per contact (the chain's link 1 and link 2; the leg's foot).
        joints: per joint, by name (see ``JOINT_NAMES``): ``F_max`` [N], the largest force
            the joint passes to the link it carries, ``torque_max`` [N m] (a spring's, a
            locked or a driven joint's) and ``impulse_work`` [J] (the work of a
            table-driven joint's impulses). The chain's ``"pin"`` is the force link 1
            exerts on link 2.
        series: recorded time series (numpy arrays by name), or None. Multi-contact bodies
            keep the ``c0.``/``c1.`` prefixes; joint and link series are named
            ``<joint>.Fx/Fy/torque`` and ``<link>.KE/PE``.
        terms: the names of the force terms that acted, in the order of ``scene.forces``.
        impulses: the impulses of the table-driven joints at their tables' times, in time
            order: dicts with ``joint`` (its name), ``t`` [s], ``impulse`` (the angular
            impulse on the link it carries, N m s) and ``energy`` (the work it does, J; each
            joint's sum is its ``impulse_work`` in ``joints``).
        step_check: what the step's check measured (``Scene.step_check``), or None where no
            check ran (the run did not look too coarse, or the check is off): ``dt`` (the
            finer step), ``moves`` (each contact's relative move of ``t_s`` and ``depth`` at
            that step, by name: ``"t_s"``, ``"depth"``; several contacts ``"c0.t_s"``, ...),
            ``status`` (at ``scene.dt`` and at the finer step), ``largest`` (the largest
            move) and ``moved`` (more than 1 %, or the status changed: the run warned
            :class:`~granrs.StepSizeWarning`). The result's other numbers are the run's at
            ``scene.dt`` whether or not a check ran.
    """

    __slots__ = ("_core", "_d", "_raw", "scene", "step_check")

    def __init__(self, scene: Scene, core: Any) -> None:
        self.scene = scene
        self._core = core  # a granrs._granrs.RunOutcome, or the raw dict
        self._raw: dict[str, Any] | None = core if isinstance(core, dict) else None
        self._d: dict[str, Any] | None = None
        self.step_check: dict[str, Any] | None = None

    def __reduce__(self) -> tuple[Any, ...]:
        # Pickle the plain results, not the core's object (and what the step's check
        # measured, a slot's state).
        return (Result, (self.scene, self._raw_dict()), (None, {"step_check": self.step_check}))

    def _raw_dict(self) -> dict[str, Any]:
        if self._raw is None:
            self._raw = self._core.to_dict()
        return self._raw

    def _parts(self) -> dict[str, Any]:
        if self._d is None:
            raw = self._raw_dict()
            scene = self.scene
            # Every run's t_s and depth, whatever its outputs.
            contacts = [
                ContactResult(t_s=t_s, depth=depth, stopped=stopped, summary=c)
                for c, stopped, t_s, depth in zip(
                    raw["contacts"], raw["stopped"], raw["t_s"], raw["depth"], strict=True
                )
            ]
            # A body without contacts (a linkage in the air) has the run's entries only.
            summary = dict(raw["contacts"][0]) if raw["contacts"] else {}
            summary.update(raw["run"])
            names = _names(scene)["joints"]
            joints = (
                {}
                if scene.kind == "free_link"
                else {
                    names[i] if i < len(names) else f"joint{i}": j
                    for i, j in enumerate(raw["joints"])
                }
            )
            self._d = {
                "summary": summary,
                "contacts": contacts,
                "joints": joints,
                "series": _rename_series(scene, raw["series"], len(contacts)),
            }
        return self._d

    @property
    def status(self) -> str:
        return str(self._core["status"] if isinstance(self._core, dict) else self._core.status)

    @property
    def t_s(self) -> float:
        if isinstance(self._core, dict):
            return float(self._core["t_s"][0])
        return float(self._core.t_s)

    @property
    def depth(self) -> float:
        if isinstance(self._core, dict):
            return float(self._core["depth"][0])
        return float(self._core.depth)

    @property
    def summary(self) -> dict[str, Any]:
        return self._parts()["summary"]  # type: ignore[no-any-return]

    @property
    def contacts(self) -> list[ContactResult]:
        return self._parts()["contacts"]  # type: ignore[no-any-return]

    @property
    def joints(self) -> dict[str, dict[str, float]]:
        return self._parts()["joints"]  # type: ignore[no-any-return]

    @property
    def impulses(self) -> list[dict[str, Any]]:
        names = _names(self.scene)["joints"]
        return [
            {"joint": names[link], "t": t, "impulse": p, "energy": e}
            for link, t, p, e in self._raw_dict().get("impulses", ())
        ]

    @property
    def series(self) -> dict[str, np.ndarray] | None:
        return self._parts()["series"]  # type: ignore[no-any-return]

    @property
    def terms(self) -> tuple[str, ...]:
        """The names of the force terms that acted, in the order of ``scene.forces``."""
        return tuple(self._raw_dict()["terms"])

    @property
    def stopped(self) -> bool:
        """Whether the run ended on its stop condition."""
        return self.status == "stopped"

    def to_frame(self) -> Any:
        """The recorded series as a pandas DataFrame indexed by time."""
        import pandas as pd

        if self.series is None:
            raise ValueError("nothing was recorded: set Scene.record, e.g. record=('state',)")
        frame = pd.DataFrame(self.series)
        return frame.set_index("t")

    def _repr_html_(self) -> str:
        """Jupyter: the status and a compact table of each contact's results with units."""
        names = _names(self.scene)["links"]
        columns = (
            ("t_s", "t_s [ms]", 1e3),
            ("depth", "depth [mm]", 1e3),
            ("dq", "dq [deg]", 180.0 / math.pi),
            ("F_d_max", "F_d_max [N]", 1.0),
            ("F_r_end", "F_r_end [N]", 1.0),
            ("dE", "dE [J]", 1.0),
        )

        def cell(value: Any, factor: float) -> str:
            try:
                number = float(value) * factor
            except (TypeError, ValueError):
                return "-"
            return "-" if math.isnan(number) else f"{number:.4g}"

        head = "".join(f"<th>{html.escape(title)}</th>" for _, title, _ in columns)
        rows = []
        for i, c in enumerate(self.contacts):
            name = names[i] if i < len(names) else f"c{i}"
            cells = "".join(f"<td>{cell(c.summary.get(k), f)}</td>" for k, _, f in columns)
            stopped = "yes" if c.stopped else "no"
            rows.append(f"<tr><td>{html.escape(name)}</td><td>{stopped}</td>{cells}</tr>")
        summary = self.summary
        caption = (
            f"granrs {html.escape(self.scene.kind)}: {html.escape(self.status)}, "
            f"{summary.get('steps', '-')} steps, {summary.get('rhs_evals', '-')} rhs evaluations"
        )
        return (
            f"<table><caption>{caption}</caption>"
            f"<tr><th>contact</th><th>stopped</th>{head}</tr>{''.join(rows)}</table>"
        )

    def __repr__(self) -> str:
        t_s = "not stopped" if math.isnan(self.t_s) else f"{self.t_s * 1e3:.4f} ms"
        return (
            f"Result(status={self.status!r}, t_s={t_s}, depth={self.depth * 1e3:.4f} mm, "
            f"steps={self.summary.get('steps', '-')}, "
            f"rhs_evals={self.summary.get('rhs_evals', '-')})"
        )


def _rename_series(
    scene: Scene, raw: dict[str, np.ndarray] | None, n_contacts: int
) -> dict[str, np.ndarray] | None:
    if raw is None:
        return None
    named = _names(scene)
    coords, rates = named["coords"], named["rates"]
    out: dict[str, np.ndarray] = {}
    for name, values in raw.items():
        new = name
        if name.startswith("qd") and name[2:].isdigit() and int(name[2:]) < len(rates):
            new = rates[int(name[2:])]
        elif name.startswith("q") and name[1:].isdigit() and int(name[1:]) < len(coords):
            new = coords[int(name[1:])]
        elif n_contacts == 1 and name.startswith("c0."):
            new = name[3:]
        elif name.startswith("joint") and "." in name:
            idx, _, rest = name[5:].partition(".")
            joints = named["joints"]
            if idx.isdigit() and int(idx) < len(joints):
                new = f"{joints[int(idx)]}.{rest}"
        elif name.startswith("link") and "." in name:
            idx, _, rest = name[4:].partition(".")
            links = named["links"]
            if idx.isdigit() and int(idx) < len(links):
                new = f"{links[int(idx)]}.{rest}"
        out[new] = values
    if "KE" in out and "PE" in out:
        out["E"] = out["KE"] + out["PE"]
    return out
