"""Which force law fits the experiments: a cross-validated comparison of laws.

:func:`granrs.compare` fits each law to each set of measurements (:func:`granrs.calibrate`), and
checks every law out of sample by leave-one-group-out cross-validation: each group of rows
(Table 3.1: one impact angle; the chain: one case; the leg: one drop height, or one
subject) is predicted by the law fitted to the other groups. It returns a
:class:`pandas.DataFrame` with one row per dataset and law.

A law is data (:class:`~granrs.compare.Law`): the terms that act, and the parameters to
fit with their starting values and bounds. :data:`~granrs.compare.LAWS` holds the named
laws, :data:`~granrs.compare.PIECES` named pieces that are no law alone (a drag that never
stops a body) but add to one: ``"thesis_refit+axial_drag"`` names their sum. A law whose
term the core does not have (yet) is reported as unavailable, with the reason, instead of
failing.

The numbers, per dataset and law (columns of the frame, and keys of
:func:`~granrs.compare.to_json`):

* ``n_params``: the parameters fitted (the law's and the body's unknowns);
* ``n_rows``: measurement rows; ``n_residuals``: 2 per row (depth, t_s);
* ``chi2``, ``dof``, ``chi2_dof``: in sample (the fit to every row), chi2 the sum of the
  squared residuals over the fit's sd (:meth:`granrs.Measurements.sd_fit`);
* ``aic`` = chi2 + 2 k and ``bic`` = chi2 + k ln(n) (k parameters, n residuals): the
  Gaussian log-likelihood with the measured sd taken as known, up to a constant shared by
  every law of a dataset, so that differences between laws are meaningful;
* ``depth_within_1sd``, ``ts_within_1sd``, ``ts_within_2sd``: out of sample, the rows whose
  predicted value is within 1 (2) measured sd of the measured mean (the measured sd alone,
  as :func:`granrs.calibrate.within` counts);
* ``oos_chi2``: out of sample, the sum of the squared residuals over the fit's sd: the
  score the laws are ranked by (``rank``, 1 the best);
* ``stop_order`` (chain): in how many cases the two links stop in the measured order, out
  of sample, and which link stops first per case, measured and predicted;
* ``rows``: per row, the measured mean and sd and the out-of-sample prediction of depth and
  t_s, with z = (prediction - mean) / sd, the group it was held out with, and ``failed``
  (its run failed: its prediction and z are NaN);
* ``folds``: per fold (``"all"`` the in-sample fit, then each held-out group), the fitted
  values with their ~95 % intervals, chi2 and dof, the parameters that ended on a bound,
  the z of depth and t_s of the rows it was fitted to (in sample) and how many of those
  rows failed at the fitted values (``failed``);
* ``failed_in_sample``, ``failed_out_of_sample``: the rows whose run failed (no
  prediction: e.g. a step too coarse for the law), in the fit to every row and out of
  sample. A failed row has no residual, so a statistic over it is undefined: ``chi2``,
  ``chi2_dof``, ``aic`` and ``bic`` are NaN when a row failed in sample, ``oos_chi2`` when
  one failed out of sample, and a law with a row failed out of sample is ranked after
  every law whose rows all ran (by its number of failed rows), never as a better fit;
* ``available``, ``reason``: whether the law could run, and why not;
* ``simulations``, ``seconds``: what the comparison cost;
* ``result``: the :class:`~granrs.CalibrationResult` of the fit to every row (None when
  the law fits nothing or did not run), e.g. to write it as a medium card
  (:meth:`~granrs.CalibrationResult.card`); not in :func:`~granrs.compare.to_json`.

A law with nothing to fit (``thesis_published``) is evaluated once: its out-of-sample
predictions are its in-sample ones.
"""

from __future__ import annotations

import difflib
import itertools
import math
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from . import forces as _forces
from .batch import _threads as _check_threads
from .bodies import CONTACT_SHAPES
from .calibrate import Measurements, calibrate, evaluate
from .calibrate.fit import _residual_frame
from .calibrate.model import _parse_param, base_coefficients
from .errors import GranrsError, InvalidParameterError, SimulationError, UnknownNameError
from .scene import Scene

if TYPE_CHECKING:
    import pandas as pd

__all__ = [
    "BODY_UNKNOWNS",
    "DATASETS",
    "JSON_KEYS",
    "LAWS",
    "PIECES",
    "Dataset",
    "FitParam",
    "Law",
    "compare",
    "scenes",
    "sums",
    "synthetic",
    "to_json",
]

#: A fitted parameter's start and bounds in natural units: (start, low, high).
FitParam = tuple[float, float, float]


@dataclass(frozen=True)
class Law:
    """A force law to compare: the terms that act, and what to fit.

    Attributes:
        name: its name in the comparison (``"thesis_refit"``).
        summary: one line: what it is.
        thesis: whether the law starts from the thesis's terms with its published
            coefficients for the row (Table 3.4, 4.4 or sec. 5.3.2); ``terms`` are then
            added to them.
        terms: the terms (beyond the thesis's, if ``thesis``) as ``(name, {param:
            value})``; a fitted parameter's value is its start. The terms that act on the
            body (the registry's body terms: ``gravity``, ``joint_springs``) are added when
            missing.
        fit: the parameters to fit on every dataset: ``{name: (start, low, high)}``, names
            as :func:`granrs.calibrate` takes them (``scale.static_v.eta_v``,
            ``poncelet.c``, ...).
        fit_body: per body, parameters fitted on that body only (they replace those of
            ``fit`` of the same name; ``None`` as the value drops one).
        fixed_body: per body, parameters held at a value on that body (``{body:
            {"poncelet.c": 0.0}}``): for a parameter with no default that is not fitted.
        body_unknowns: whether the body's unknowns
            (:data:`~granrs.compare.BODY_UNKNOWNS`) are fitted too; if not, the body's
            published setting is used (:attr:`~granrs.compare.Dataset.published`).
    """

    name: str
    summary: str
    thesis: bool = False
    terms: tuple[tuple[str, Mapping[str, float]], ...] = ()
    fit: Mapping[str, FitParam] = field(default_factory=dict)
    fit_body: Mapping[str, Mapping[str, FitParam | None]] = field(default_factory=dict)
    fixed_body: Mapping[str, Mapping[str, float]] = field(default_factory=dict)
    body_unknowns: bool = True

    def __add__(self, other: Law) -> Law:
        """The sum of two laws: both laws' terms (a term that both list is refused), the
        parameters either fits (``other``'s win on a name both fit), and the thesis's terms
        if either starts from them; the body's unknowns fitted only if both fit them."""
        if not isinstance(other, Law):
            return NotImplemented
        clash = sorted({t for t, _ in self.terms} & {t for t, _ in other.terms})
        if clash:
            raise InvalidParameterError(
                f"laws {self.name!r} and {other.name!r} both list the term {clash[0]!r}",
                field="laws",
            )

        def merged(a: Mapping[str, Mapping[str, Any]], b: Mapping[str, Mapping[str, Any]]) -> Any:
            return {k: {**a.get(k, {}), **b.get(k, {})} for k in {*a, *b}}

        return Law(
            f"{self.name}+{other.name}",
            f"{self.summary}; plus {other.summary}",
            thesis=self.thesis or other.thesis,
            terms=(*self.terms, *other.terms),
            fit={**self.fit, **other.fit},
            fit_body=merged(self.fit_body, other.fit_body),
            fixed_body=merged(self.fixed_body, other.fixed_body),
            body_unknowns=self.body_unknowns and other.body_unknowns,
        )

    def params_for(self, body: str) -> dict[str, FitParam]:
        """The law's own parameters fitted on ``body`` (without the body's unknowns)."""
        out: dict[str, FitParam | None] = {**self.fit, **self.fit_body.get(body, {})}
        return {k: v for k, v in out.items() if v is not None}

    def needs(self) -> tuple[str, ...]:
        """Every term the law lists (the body's included)."""
        names = _forces.THESIS_TERMS if self.thesis else ()
        return (*names, *(t for t, _ in self.terms))

    def terms_for(self, body: str) -> Callable[[Mapping[str, Any]], tuple[_forces.Term, ...]]:
        """The law's terms for one measurement row of ``body``, at the start values."""
        extra = []
        fixed = self.fixed_body.get(body, {})
        for name, params in self.terms:
            starts = {
                k.split(".", 1)[1]: v[0]
                for k, v in self.params_for(body).items()
                if k.startswith(name + ".") and "@" not in k
            }
            held = {k.split(".", 1)[1]: v for k, v in fixed.items() if k.startswith(name + ".")}
            extra.append(_forces.term(name, **{**params, **held, **starts}))
        listed = {t.name for t in extra}
        head, tail = (tuple(n for n in names if _acts_on(n, body)) for names in _body_terms())

        def law(row: Mapping[str, Any]) -> tuple[_forces.Term, ...]:
            if self.thesis:
                base = _forces.thesis(base_coefficients(body, row))
                base = tuple(t for t in base if t.name not in tail)
            else:
                base = tuple(_forces.term(n) for n in head if n not in listed)
            after = tuple(_forces.term(n) for n in tail if n not in listed)
            return (*base, *extra, *after)

        return law


def _acts_on(term: str, body: str) -> bool:
    """Whether ``term`` acts on ``body``: on a planar contact's shape, or (a body in space)
    on a shape that is not one."""
    shapes = set(_forces.info(term).shapes)
    planar = shapes & set(CONTACT_SHAPES)
    return bool(shapes - planar) if body == "space" else bool(planar)


def _body_terms() -> tuple[tuple[str, ...], tuple[str, ...]]:
    """The terms that act on the body (the registry's ``acts == "body"``: its weight, its
    joints) that a law gets when it does not list them: those the thesis's law lists before
    its contact terms, and the others, after the law's own terms."""
    body = [n for n in _forces.TERMS if _forces.info(n).acts == "body"]
    thesis = _forces.THESIS_TERMS
    first = next(i for i, n in enumerate(thesis) if _forces.info(n).acts == "contact")
    head = tuple(n for n in thesis[:first] if n in body)
    return head, tuple(n for n in body if n not in head)


#: The thesis's law refit: scale factors on its published coefficients for the row, which
#: keep their shape in angle (free link), link and case (chain) and speed (leg).
_THESIS_SCALES: dict[str, FitParam] = {
    "scale.static_h.eta_h": (1.0, 0.02, 50.0),
    "scale.drag.eta_d": (1.0, 0.02, 50.0),
    "scale.static_v.eta_v": (1.0, 0.02, 50.0),
    "scale.static_v.lam": (1.0, 0.02, 50.0),
}
#: The leg has 4 residuals (2 heights x depth, t_s) and each fold 2: its laws fit one
#: parameter of their own (the static vertical scale for the thesis's law), besides the
#: joints' stiffness.
_LEG_THESIS: dict[str, FitParam | None] = {
    "scale.static_h.eta_h": None,
    "scale.drag.eta_d": None,
    "scale.static_v.lam": None,
}

#: The laws compared by default, by name.
LAWS: dict[str, Law] = {
    law.name: law
    for law in (
        Law(
            "thesis_published",
            "the thesis's law with its published coefficients (Table 3.4 nearest row, Table "
            "4.4, sec. 5.3.2); nothing fitted",
            thesis=True,
            body_unknowns=False,
        ),
        Law(
            "thesis_refit",
            "the thesis's law, its four coefficients scaled from the published ones and fitted",
            thesis=True,
            fit=_THESIS_SCALES,
            fit_body={"leg": _LEG_THESIS},
        ),
        Law(
            "thesis+poncelet",
            "the thesis's law refit, plus poncelet (c rho_g A |v| v + k d) at the tip",
            thesis=True,
            terms=(("poncelet", {"k": 0.0}),),
            fit={**_THESIS_SCALES, "poncelet.c": (1.0, 1e-3, 1e3)},
            fit_body={"leg": {**_LEG_THESIS, "scale.static_v.eta_v": None}},
        ),
        Law(
            "rft",
            "resistive force theory (Li, Zhang & Goldman 2013), zeta fitted",
            terms=(("rft", {}),),
            fit={"rft.zeta": (1e6, 1e3, 1e9)},
        ),
        Law(
            "rft+rft_inertial",
            "rft plus its inertial (rate-dependent) term, zeta and the inertial coefficient fitted",
            terms=(("rft", {}), ("rft_inertial", {})),
            fit={"rft.zeta": (1e6, 1e3, 1e9), "rft_inertial.lam": (1.0, 1e-3, 1e3)},
            fit_body={"leg": {"rft_inertial.lam": None}},
        ),
        Law(
            "poncelet",
            "poncelet alone (Katsuragi & Durian 2007): c and k fitted",
            terms=(("poncelet", {}),),
            fit={"poncelet.c": (1.0, 1e-3, 1e3), "poncelet.k": (300.0, 1.0, 1e7)},
            # The leg: one parameter of the law (see _LEG_THESIS): the depth friction, from
            # the order of the body weight over the measured depth; no inertial drag.
            fit_body={"leg": {"poncelet.c": None, "poncelet.k": (1e4, 1.0, 1e7)}},
            fixed_body={"leg": {"poncelet.c": 0.0}},
        ),
    )
}

#: Named pieces of laws, compared only in a sum (``"thesis_refit+axial_drag"``, or
#: ``LAWS["thesis_refit"] + PIECES["axial_drag"]``): alone they stop nothing.
PIECES: dict[str, Law] = {
    law.name: law
    for law in (
        Law(
            "axial_drag",
            "a quadratic drag along the rod's axis on its end face, eta_a rho_g (pi d_c^2 / 4) "
            "|v_a| v_a at E, eta_a fitted",
            terms=(("axial_drag", {}),),
            fit={"axial_drag.eta_a": (5.0, 1e-3, 1e3)},
        ),
    )
}

#: The body's unknowns fitted with every law that fits (``Law.body_unknowns``), by body.
#: The leg's joint stiffness, within a physiological range (see
#: :data:`~granrs.compare.DATASETS`). The chain's link mass is not in the thesis, but it
#: cannot be fitted beside a law's force scale: every term of these laws is linear in its
#: coefficient (eta_h, eta_d, eta_v, c, k, zeta), and gravity is linear in the mass, so a
#: mass m' with those coefficients times m'/m gives the same motion (a = g + F/m). The
#: chain keeps its solid-steel mass, and each law's coefficients are per that mass;
#: :func:`granrs.calibrate` fits the mass itself (``"mass"``) where the law is held fixed.
BODY_UNKNOWNS: dict[str, dict[str, FitParam]] = {
    "free_link": {},
    "chain": {},
    "leg": {"joints.k": (300.0, 100.0, 1000.0)},
    "space": {},
}


@dataclass(frozen=True)
class Dataset:
    """A dataset of the comparison: the thesis's measurements and how to cut them.

    Attributes:
        measurements: the thesis's measurements' name (:meth:`granrs.Measurements.thesis`).
        group: the column whose values are the cross-validation's groups.
        published: Scene settings of the thesis's model for what is not fitted
            (``joints``: the leg's; other keys: Scene fields).
        fixed: settings of every fitting law for what is not fitted.
        note: how the groups were chosen, and what is assumed.
    """

    measurements: str
    group: str
    published: Mapping[str, Any] = field(default_factory=dict)
    fixed: Mapping[str, Any] = field(default_factory=dict)
    note: str = ""


#: The thesis's datasets by name, in report order.
DATASETS: dict[str, Dataset] = {
    "free_link": Dataset(
        "table_3_1",
        "q_deg",
        note="Table 3.1, 12 rows: leave one impact angle out (4 folds of 3 rows).",
    ),
    "chain": Dataset(
        "table_4_chain",
        "v0_case",
        note="Tables 4.1-4.2, 3 cases x 2 links: leave one case out (3 folds of 2 rows). "
        "The link mass is not in the thesis: every law runs with solid steel (0.0341 kg). It "
        "cannot be fitted beside a law's coefficients (a mass m' with the sand's force "
        "scaled by m'/m moves the same), so each law's coefficients are per that mass.",
    ),
    "leg": Dataset(
        "table_5_1_means",
        "height_case",
        published={"joints": "locked"},
        fixed={"joints": {"c": 5.0}},
        note="Table 5.1 averaged per drop height (the mean of the 5 subjects' means, sd "
        "across subjects): 2 rows, so leave one height out (2 folds of 1 row, each fit on 2 "
        "residuals: one parameter of the law and the joints' stiffness). The thesis's model "
        "has locked joints; the fitting laws put one spring-damper on ankle, knee and hip, "
        "k fitted within 100-1000 N m/rad and c = 5 N m s/rad. The range is an assumption "
        "built on the knee's quasi-stiffness in walking (Shamaei, Sawicki & Dollar, PLoS ONE "
        "8 (2013) e59993): a published regression of the knee's flexion quasi-stiffness in "
        "the weight acceptance of walking (PMC4914409, Table II) gives about 3 N m/deg, "
        "~170 N m/rad, for a 75 kg adult; a landing, with the muscles braced, is taken to be "
        "stiffer, up to about 6 times that. No landing stiffness of these subjects was "
        "measured.",
    ),
}

#: Out-of-sample columns of each row.
_ROW_COLUMNS = ("depth_pred", "depth_z", "t_s_pred", "t_s_z")


def _law_list(laws: Any) -> list[Law]:
    if laws is None:
        return list(LAWS.values())
    if isinstance(laws, (str, Law)):
        laws = [laws]
    out = []
    for item in laws:
        if isinstance(item, Law):
            out.append(item)
        elif isinstance(item, str) and item in LAWS:
            out.append(LAWS[item])
        elif isinstance(item, str) and (law := _named_sum(item)) is not None:
            out.append(law)
        else:
            names = [*LAWS, *PIECES]
            hint = difflib.get_close_matches(str(item), names, n=1)
            more = f"; did you mean {hint[0]!r}?" if hint else ""
            raise UnknownNameError(
                f"unknown law {item!r}{more} (laws: {', '.join(LAWS)}; pieces to add to "
                f"them with '+': {', '.join(PIECES)}; or a granrs.compare.Law)",
                field="laws",
            )
    if not out:
        raise InvalidParameterError(
            f"no law to compare: laws is empty (give names of {', '.join(LAWS)}, or "
            "granrs.compare.Law objects)",
            field="laws",
        )
    names = [law.name for law in out]
    for n in names:
        if names.count(n) > 1:
            raise InvalidParameterError(f"law {n!r} is given twice", field="laws")
    return out


def _named_sum(name: str) -> Law | None:
    """The sum a name like ``"thesis_refit+axial_drag"`` spells: names of :data:`LAWS` and
    :data:`PIECES` joined with ``+`` (a named law's own ``+`` kept: the longest name first),
    at least one of them a law; ``None`` if it spells none."""
    known = {**PIECES, **LAWS}
    parts = name.split("+")
    found: list[Law] = []
    i = 0
    while i < len(parts):
        j = next((j for j in range(len(parts), i, -1) if "+".join(parts[i:j]) in known), None)
        if j is None:
            return None
        found.append(known["+".join(parts[i:j])])
        i = j
    if len(found) < 2 or not any(law.name in LAWS for law in found):
        return None
    # Two parts listing the same term: the sum's own error, naming them.
    total = found[0]
    for law in found[1:]:
        total = total + law
    return total


def _datasets(measurements: Any) -> dict[str, Measurements]:
    if measurements is None:
        return {name: Measurements.thesis(d.measurements) for name, d in DATASETS.items()}
    if isinstance(measurements, Measurements):
        return {measurements.body: measurements}
    if isinstance(measurements, str):
        m = Measurements.load(measurements)
        return {m.body: m}
    if isinstance(measurements, Mapping):
        out = {}
        for name, m in measurements.items():
            if isinstance(m, str):
                m = Measurements.load(m)
            if not isinstance(m, Measurements):
                raise InvalidParameterError(
                    f"measurements[{name!r}] must be a granrs.Measurements or a thesis name; "
                    f"got {type(m).__name__}",
                    field="measurements",
                )
            out[str(name)] = m
        if not out:
            raise InvalidParameterError("no measurements to compare", field="measurements")
        return out
    raise InvalidParameterError(
        "measurements must be a granrs.Measurements, a thesis name, a mapping of dataset "
        f"name to either, or None (the thesis's three); got {type(measurements).__name__}",
        field="measurements",
    )


def _group_column(name: str, m: Measurements, folds: Any) -> str | None:
    if isinstance(folds, Mapping):
        folds = folds.get(name, "auto")
    if folds is None or folds == "none":
        return None
    if folds == "auto":
        default = {
            "free_link": "q_deg",
            "chain": "v0_case",
            "leg": "height_case" if "subject" not in m.rows.columns else "subject",
        }.get(m.body)
        return default if default in m.rows.columns else None
    if not isinstance(folds, str) or folds not in m.rows.columns:
        hint = difflib.get_close_matches(str(folds), list(m.rows.columns), n=1)
        more = f"; did you mean {hint[0]!r}?" if hint else ""
        raise UnknownNameError(
            f"folds: the {name} measurements have no column {folds!r}{more}", field="folds"
        )
    return folds


def _unavailable(law: Law, body: str) -> str:
    """Why ``law`` cannot run on ``body`` (empty if it can, as far as names go)."""
    for name in law.needs():
        if name not in _forces.TERMS:
            return f"the term {name!r} is not in this build of granrs"
        if not _acts_on(name, body):
            where = "a body in space" if body == "space" else f"the planar {body}"
            return f"the term {name!r} does not act on {where}"
    for name, _ in law.terms:
        given = {p.name for p in _forces.info(name).params}
        for k in dict(law.terms)[name]:
            if k not in given:
                return f"the term {name!r} has no parameter {k!r}"
    for p in law.params_for(body):
        try:
            _parse_param(p, body)
        except GranrsError as error:
            return str(error)
    return ""


@dataclass
class _Job:
    """One law on one dataset: what to fit and how."""

    law: Law
    body: str
    #: What calibrate takes as its cases: the body's name, or (space) the function of
    #: the row that makes its scene.
    cases: Any
    params: dict[str, FitParam]
    overrides: dict[str, Any]
    joints: dict[str, float] | None


def _scene_fn(cases: Any, name: str, m: Measurements) -> Any:
    """The function that makes a row's scene for the dataset ``name`` if its measurements
    are of bodies in space (``cases``: one function, or a mapping of dataset name to one);
    None for the thesis's bodies."""
    if m.body != "space":
        return None
    fn = cases.get(name) if isinstance(cases, Mapping) else cases
    if not callable(fn):
        raise InvalidParameterError(
            f"the {name} measurements are of bodies in space: cases= must give the function "
            "of a measurement row that returns its granrs.space.Scene",
            field="cases",
        )
    return fn


def _job(law: Law, name: str, m: Measurements, scene_of: Any = None) -> _Job:
    body = m.body
    params = dict(law.params_for(body))
    settings = DATASETS[name] if name in DATASETS else Dataset("", "")
    if law.params_for(body) and law.body_unknowns:
        params.update(BODY_UNKNOWNS[body])
        extra = dict(settings.fixed)
    else:
        extra = dict(settings.published)
    joints = extra.pop("joints", None)
    overrides: dict[str, Any] = dict(extra)
    if isinstance(joints, str):
        overrides.update({j: joints for j in ("ankle", "knee", "hip")})
        joints = None
    return _Job(law, body, scene_of if body == "space" else body, params, overrides, joints)


def _fit(job: _Job, m: Measurements, dt: float, threads: int | None, starts: int) -> Any:
    names = list(job.params)
    return calibrate(
        job.cases,
        m,
        names,
        bounds={k: (v[1], v[2]) for k, v in job.params.items()},
        start={k: v[0] for k, v in job.params.items()},
        forces=job.law.terms_for(job.body),
        joints=job.joints,
        dt=dt,
        threads=threads,
        starts=starts,
        **job.overrides,
    )


def _predict(
    job: _Job, m: Measurements, dt: float, threads: int | None, fit: Any = None
) -> pd.DataFrame:
    if fit is not None:
        return fit.predict(m)
    return evaluate(
        job.cases,
        m,
        forces=job.law.terms_for(job.body),
        joints=job.joints,
        dt=dt,
        threads=threads,
        **job.overrides,
    )


def _fold_record(held_out: Any, fit: Any) -> dict[str, Any]:
    res = fit.residuals
    failed = _failed(res)
    return {
        "held_out": held_out,
        "values": dict(fit.values),
        "intervals": {k: list(v) for k, v in fit.intervals.items()},
        "std_errors": dict(fit.std_errors),
        # The fit's chi2 counts a failed run as a large residual: no chi2 where one failed.
        "chi2": fit.chi2 if failed == 0 else math.nan,
        "dof": fit.dof,
        "at_bound": list(fit.at_bound),
        "failed": failed,
        # In sample: the z of the rows this fold was fitted to, in their order.
        "depth_z": [float(z) for z in res["depth_z"]],
        "t_s_z": [float(z) for z in res["t_s_z"]],
    }


def _plain(value: Any) -> Any:
    if isinstance(value, (np.floating, np.integer)):
        return value.item()
    if isinstance(value, np.bool_):
        return bool(value)
    return value


def _rows(m: Measurements, pred: pd.DataFrame, group: str | None) -> list[dict[str, Any]]:
    out = []
    keys = [c for c in pred.columns if not c.startswith(("depth_", "t_s_"))]
    for i in range(len(m)):
        src = m.rows.iloc[i]
        p = pred.iloc[i]
        row = {k: _plain(p[k]) for k in keys if k != "unresolved"}
        row["held_out_with"] = _plain(src[group]) if group else None
        for q in ("depth", "t_s"):
            row[f"{q}_mean"] = float(src[f"{q}_mean"])
            row[f"{q}_sd"] = float(src[f"{q}_sd"])
            row[f"{q}_pred"] = float(p[f"{q}_sim"])
            row[f"{q}_z"] = float(p[f"{q}_z"])
            row[f"{q}_zfit"] = float(p[f"{q}_zfit"])
        row["failed"] = not (math.isfinite(row["depth_pred"]) and math.isfinite(row["t_s_pred"]))
        out.append(row)
    return out


def _failed(frame: pd.DataFrame) -> int:
    """The rows of a residual frame whose run failed: no simulated depth or t_s (a failed
    run's are NaN; a run that did not stop has its end time as t_s, a number)."""
    ran = np.isfinite(frame["depth_sim"].to_numpy(dtype=float)) & np.isfinite(
        frame["t_s_sim"].to_numpy(dtype=float)
    )
    return int(np.count_nonzero(~ran))


def _chi2(frame: pd.DataFrame) -> float:
    """The sum of the squared residuals over the fit's sd, NaN if a row failed (a failed
    run has no residual: skipping it would make the law look better than it is)."""
    depth = frame["depth_zfit"].to_numpy(dtype=float)
    t_s = frame["t_s_zfit"].to_numpy(dtype=float)
    if not (np.all(np.isfinite(depth)) and np.all(np.isfinite(t_s))):
        return math.nan
    return float(sum(d**2 + t**2 for d, t in zip(depth.tolist(), t_s.tolist(), strict=True)))


def _count(rows: Sequence[Mapping[str, Any]], q: str, k: float) -> int:
    return int(sum(1 for r in rows if abs(r[f"{q}_z"]) <= k + 1e-12))


def _stop_order(rows: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """The chain: in how many cases the links stop in the measured order (out of sample)."""
    cases: dict[Any, dict[int, Mapping[str, Any]]] = {}
    for r in rows:
        cases.setdefault(r["v0_case"], {})[int(r["link"])] = r
    per_case = {}
    for case, links in cases.items():
        if set(links) != {1, 2}:
            continue
        measured = links[1]["t_s_mean"] - links[2]["t_s_mean"]
        predicted = links[1]["t_s_pred"] - links[2]["t_s_pred"]
        first_m = 1 if measured < 0 else 2 if measured > 0 else 0
        first_p = 1 if predicted < 0 else 2 if predicted > 0 else 0
        per_case[str(_plain(case))] = {"measured_first": first_m, "predicted_first": first_p}
    ok = sum(1 for v in per_case.values() if v["measured_first"] == v["predicted_first"])
    return {"in_order": ok, "cases": len(per_case), "per_case": per_case}


def _entry(
    name: str,
    job: _Job,
    m: Measurements,
    group: str | None,
    dt: float,
    threads: int | None,
    starts: int,
    tick: Callable[[str], None],
) -> dict[str, Any]:
    """Fit, cross-validate and summarise one law on one dataset."""
    import pandas as pd

    t0 = time.perf_counter()
    k = len(job.params)
    n_res = 2 * len(m)
    sims = 0
    folds: list[dict[str, Any]] = []
    full = None
    if k == 0:
        pred = _predict(job, m, dt, threads)
        sims += len(m)
        failed_in = _failed(pred)
        chi2 = _chi2(pred)
        oos = pred
        tick(f"{name}: {job.law.name}")
    else:
        full = _fit(job, m, dt, threads, starts)
        sims += full.simulations
        failed_in = _failed(full.residuals)
        # The fit's own chi2 (failed runs enter its steps as large residuals) where every
        # row ran at the optimum; undefined otherwise.
        chi2 = full.chi2 if failed_in == 0 else math.nan
        folds.append(_fold_record("all", full))
        tick(f"{name}: {job.law.name}, all rows")
        if group is None:
            oos = full.residuals
        else:
            parts = []
            index = []
            for g in pd.unique(m.rows[group]):
                mask = (m.rows[group] == g).to_numpy()
                train, test = m.subset(~mask), m.subset(mask)
                if 2 * len(train) < k:
                    raise InvalidParameterError(
                        f"{k} parameters cannot be fitted to {2 * len(train)} residuals "
                        f"(the {name} without {group} = {g})",
                        field="folds",
                    )
                fit = _fit(job, train, dt, threads, starts)
                sims += fit.simulations + len(test)
                folds.append(_fold_record(_plain(g), fit))
                parts.append(fit.predict(test))
                index += list(np.flatnonzero(mask))
                tick(f"{name}: {job.law.name}, without {group} = {g}")
            oos = pd.concat(parts, ignore_index=True)
            oos.index = index
            oos = oos.sort_index()
    rows = _rows(m, oos.reset_index(drop=True), group)
    stop_order = _stop_order(rows) if job.body == "chain" else None
    dof = n_res - k
    oos_chi2 = _chi2(oos)
    return {
        "dataset": name,
        "law": job.law.name,
        "available": True,
        "reason": "",
        "n_params": k,
        "params": list(job.params),
        "n_rows": len(m),
        "n_residuals": n_res,
        "chi2": chi2,
        "dof": dof,
        "chi2_dof": chi2 / dof if dof > 0 else math.nan,
        "aic": chi2 + 2.0 * k,
        "bic": chi2 + k * math.log(n_res),
        "oos_chi2": oos_chi2,
        "failed_in_sample": failed_in,
        "failed_out_of_sample": sum(1 for r in rows if r["failed"]),
        "depth_within_1sd": _count(rows, "depth", 1.0),
        "ts_within_1sd": _count(rows, "t_s", 1.0),
        "ts_within_2sd": _count(rows, "t_s", 2.0),
        "stop_order": stop_order,
        "group": group,
        "rows": rows,
        "folds": folds,
        "simulations": sims,
        "seconds": time.perf_counter() - t0,
        "result": full,
    }


def compare(
    laws: Iterable[str | Law] | str | Law | None = None,
    measurements: Any = None,
    *,
    folds: str | Mapping[str, str] | None = "auto",
    dt: float = 1e-4,
    starts: int = 1,
    threads: int | None = None,
    progress: bool | None = None,
    cases: Any = None,
) -> pd.DataFrame:
    """Fit every law to every dataset and cross-validate it; one row per dataset and law.

    Args:
        laws: law names from :data:`~granrs.compare.LAWS` or
            :class:`~granrs.compare.Law` objects; None: every law of
            :data:`~granrs.compare.LAWS`.
        measurements: a :class:`granrs.Measurements` (the dataset is named after its body),
            a thesis name (``"table_3_1"``), a mapping of dataset name to either, or None:
            the thesis's three datasets (:data:`~granrs.compare.DATASETS`:
            ``"free_link"``, ``"chain"``, ``"leg"``).
        folds: the column whose values are the groups left out one at a time; ``"auto"``
            (default): ``q_deg`` (free link), ``v0_case`` (chain), ``height_case`` or
            ``subject`` (leg: Table 5.1's means have only the heights, the per-subject table
            is cut by subject); None: no cross-validation (the "out-of-sample" numbers are
            then in sample). A mapping gives one per dataset name.
        dt: the integration step [s].
        starts: starts of each fit (:func:`granrs.calibrate`).
        threads: the sweeps' worker threads (default: every core).
        progress: a tqdm bar over the fits (None: on a terminal).
        cases: for measurements of bodies in space (body ``"space"``), the function of a
            measurement row that returns its :class:`granrs.space.Scene` (as
            :func:`granrs.calibrate` takes it), or a mapping of dataset name to one. Their
            folds are not guessed: name the column (``folds="v0"``).

    Returns:
        A DataFrame with the columns of the module's notes, one row per (dataset, law), in
        the order given; ``rank`` orders the available laws of a dataset by ``oos_chi2``,
        those with failed runs last (``failed_out_of_sample``). A law whose term is not
        in this build, or that cannot run on a body, has ``available`` False and its
        ``reason``; its numbers are NaN.

    Raises:
        UnknownNameError: an unknown law or folds column (did-you-mean in the message).
        InvalidParameterError: bad measurements, no law or a law given twice
            (``field="laws"``), an invalid ``dt`` (the scene's rule, ``field="dt"``),
            ``threads`` (the sweep's rule) or ``starts``; all before any run.
    """
    import pandas as pd

    law_list = _law_list(laws)
    data = _datasets(measurements)
    if isinstance(starts, bool) or not isinstance(starts, int) or starts < 1:
        raise InvalidParameterError(f"invalid starts: {starts!r}", field="starts")
    # Before any run, by the rules every run uses: the step by a scene's, the threads by
    # the sweep's. A bad one is the caller's error, not a failed run of each law.
    _check_dt(dt)
    _check_threads(threads)
    groups = {name: _group_column(name, m, folds) for name, m in data.items()}
    scene_fns = {name: _scene_fn(cases, name, m) for name, m in data.items()}
    plans: list[tuple[str, Law, Measurements, str | None, _Job | None, str]] = []
    total = 0
    for name, m in data.items():
        for law in law_list:
            reason = _unavailable(law, m.body)
            job = None
            if not reason:
                job = _job(law, name, m, scene_fns[name])
                n_groups = len(pd.unique(m.rows[groups[name]])) if groups[name] else 0
                total += 1 + (n_groups if job.params else 0)
            plans.append((name, law, m, groups[name], job, reason))

    import sys

    from tqdm.auto import tqdm

    disable = (not sys.stderr.isatty()) if progress is None else not progress
    bar = tqdm(total=total, unit="fit", desc="granrs compare", disable=disable)

    def tick(label: str) -> None:
        bar.set_postfix_str(label, refresh=False)
        bar.update(1)

    records = []
    try:
        for name, law, m, group, job, reason in plans:
            if job is not None:
                try:
                    records.append(_entry(name, job, m, group, dt, threads, starts, tick))
                    continue
                except GranrsError as error:
                    reason = f"{type(error).__name__}: {error}"
            records.append(_missing(name, law, m, reason))
    finally:
        bar.close()
    frame = pd.DataFrame.from_records(records)
    frame["rank"] = _rank(frame)
    return frame


def sums(
    pieces: Iterable[str | Law],
    measurements: Any = None,
    *,
    base: str | Law | None = None,
    max_terms: int = 2,
    **options: Any,
) -> pd.DataFrame:
    """Search over small sums of laws in one call: every sum of 1 to ``max_terms`` of
    ``pieces`` (law names or :class:`Law` objects, added with ``+``), each on top of
    ``base`` when given (``base`` itself is compared too), fitted and cross-validated by
    :func:`granrs.compare` (``options``: its keywords). A sum in which two pieces list the same term
    is left out. Returns :func:`granrs.compare`'s frame, one row per dataset and sum, ranked."""
    items = _law_list(pieces)
    if isinstance(max_terms, bool) or not isinstance(max_terms, int) or max_terms < 1:
        raise InvalidParameterError(
            f"max_terms must be an integer >= 1; got {max_terms!r}", field="max_terms"
        )
    start = _law_list([base])[0] if base is not None else None
    laws = [start] if start is not None else []
    for k in range(1, min(max_terms, len(items)) + 1):
        for combo in itertools.combinations(items, k):
            try:
                law = combo[0] if start is None else start + combo[0]
                for piece in combo[1:]:
                    law = law + piece
            except InvalidParameterError:
                continue  # two of them list the same term
            laws.append(law)
    return compare(laws, measurements, **options)


def _check_dt(dt: Any) -> None:
    """Refuse an invalid step by the rule of every scene (``field="dt"``)."""
    Scene(dt=dt).validate()


def _rank(frame: pd.DataFrame) -> pd.Series:
    """Per dataset: the available laws whose rows all ran out of sample by ``oos_chi2``
    (1 the best), then those with failed rows, by how many failed (ties share a rank);
    NA for a law that did not run."""
    import pandas as pd

    rank = pd.array([pd.NA] * len(frame), dtype="Int64")
    for _, sub in frame[frame["available"]].groupby("dataset", sort=False):
        at = frame.index.get_indexer(sub.index)
        failed = sub["failed_out_of_sample"].to_numpy(dtype=float)
        clean = failed == 0
        chi2 = pd.Series(sub["oos_chi2"].to_numpy(dtype=float)[clean])
        rank[at[clean]] = chi2.rank(method="min").to_numpy(dtype=float)
        after = pd.Series(failed[~clean]).rank(method="min").to_numpy(dtype=float)
        rank[at[~clean]] = int(np.count_nonzero(clean)) + after
    return pd.Series(rank, index=frame.index)


def _missing(name: str, law: Law, m: Measurements, reason: str) -> dict[str, Any]:
    nan = math.nan
    return {
        "dataset": name,
        "law": law.name,
        "available": False,
        "reason": reason,
        "n_params": len(law.params_for(m.body)),
        "params": list(law.params_for(m.body)),
        "n_rows": len(m),
        "n_residuals": 2 * len(m),
        "chi2": nan,
        "dof": nan,
        "chi2_dof": nan,
        "aic": nan,
        "bic": nan,
        "oos_chi2": nan,
        "failed_in_sample": nan,
        "failed_out_of_sample": nan,
        "depth_within_1sd": nan,
        "ts_within_1sd": nan,
        "ts_within_2sd": nan,
        "stop_order": None,
        "group": None,
        "rows": [],
        "folds": [],
        "simulations": 0,
        "seconds": 0.0,
        "result": None,
    }


#: The keys of each law's entry in :func:`~granrs.compare.to_json`.
JSON_KEYS: tuple[str, ...] = (
    "available",
    "reason",
    "n_params",
    "params",
    "n_rows",
    "chi2",
    "dof",
    "chi2_dof",
    "aic",
    "bic",
    "oos_chi2",
    "rank",
    "failed_in_sample",
    "failed_out_of_sample",
    "depth_within_1sd",
    "ts_within_1sd",
    "ts_within_2sd",
    "stop_order",
    "group",
    "rows",
    "folds",
    "simulations",
    "seconds",
)


def _json_value(value: Any) -> Any:
    import pandas as pd

    if isinstance(value, Mapping):
        return {str(k): _json_value(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_json_value(v) for v in value]
    value = _plain(value)
    if value is pd.NA:
        return None
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


#: Keys that are counts (whole numbers, or None when the law did not run).
_COUNT_KEYS = (
    "n_params",
    "n_rows",
    "dof",
    "rank",
    "failed_in_sample",
    "failed_out_of_sample",
    "depth_within_1sd",
    "ts_within_1sd",
    "ts_within_2sd",
    "simulations",
)


def to_json(frame: pd.DataFrame) -> dict[str, dict[str, dict[str, Any]]]:
    """The comparison as plain data, ``{dataset: {law: {...}}}`` (what ``laws.json`` and
    ``granrs compare --json`` hold): per law the keys of
    :data:`~granrs.compare.JSON_KEYS`; NaN as None."""
    out: dict[str, dict[str, dict[str, Any]]] = {}
    for rec in frame.to_dict("records"):
        entry = {k: _json_value(rec.get(k)) for k in JSON_KEYS}
        for k in _COUNT_KEYS:
            if isinstance(entry[k], float):
                entry[k] = int(entry[k])
        out.setdefault(str(rec["dataset"]), {})[str(rec["law"])] = entry
    return out


def synthetic(
    law: str | Law,
    values: Mapping[str, float],
    like: Measurements | str,
    *,
    rel_sd: float = 0.05,
    seed: int = 0,
    dataset: str | None = None,
    dt: float = 1e-4,
    cases: Any = None,
) -> Measurements:
    """Measurements made by granrs under ``law`` at the parameter ``values``, with noise:
    the rows of ``like`` (its angles, speeds, cases), each mean drawn from a normal
    distribution around the simulated value with sd ``rel_sd`` times that value, which is
    also the row's sd. For checking that :func:`granrs.compare` picks the law that made the data
    and recovers its parameters. A run that fails (no value to draw around) raises
    :class:`~granrs.errors.SimulationError`; an invalid ``dt`` the scene's typed error.

    ``values`` gives every fitted parameter of the law on that body (its own and the
    body's unknowns, as :func:`granrs.compare` fits them; ``dataset`` names the settings of
    :data:`~granrs.compare.DATASETS` to use, default the body's name; ``cases``: for
    measurements of bodies in space, the function of a row that makes its scene, as
    :func:`granrs.compare` takes it)."""
    (law_obj,) = _law_list([law])
    m = like if isinstance(like, Measurements) else Measurements.load(like)
    _check_dt(dt)
    if not (isinstance(rel_sd, (int, float)) and 0.0 < rel_sd < 1.0):
        raise InvalidParameterError(f"rel_sd must be in (0, 1); got {rel_sd!r}", field="rel_sd")
    reason = _unavailable(law_obj, m.body)
    if reason:
        raise InvalidParameterError(f"law {law_obj.name}: {reason}", field="law")
    name = dataset or m.body
    job = _job(law_obj, name, m, _scene_fn(cases, name, m))
    missing = [p for p in job.params if p not in values]
    extra = [p for p in values if p not in job.params]
    if missing or extra:
        raise InvalidParameterError(
            f"values must give exactly the law's parameters {list(job.params)}; "
            f"missing {missing}, not fitted {extra}",
            field="values",
        )
    sim = _pinned(job, m, dt, [float(values[k]) for k in job.params])
    failed = _failed(sim)
    if failed:
        raise SimulationError(
            f"synthetic: the runs of {failed} of {len(m)} rows failed under {law_obj.name} "
            f"at dt = {dt:g} s (no value to draw the measurements around); use a smaller dt"
        )
    rng = np.random.default_rng(seed)
    rows = m.rows.copy()
    for q in ("depth", "t_s"):
        truth = sim[f"{q}_sim"].to_numpy(dtype=float)
        sd = rel_sd * np.abs(truth)
        rows[f"{q}_mean"] = truth + rng.normal(0.0, 1.0, len(truth)) * sd
        rows[f"{q}_sd"] = sd
    return Measurements(
        m.body, rows, f"synthetic: {law_obj.name} at {dict(values)}", {"depth": 0.0, "t_s": 0.0}
    )


def _model(job: _Job, dt: float) -> Any:
    """The calibration model of a job (its parameters, law and settings)."""
    from .calibrate.fit import _check_law
    from .calibrate.model import _Model

    parsed = [_parse_param(p, job.body) for p in job.params]
    return _Model(
        job.body,
        tuple(parsed),
        None,
        float(dt),
        dict(job.overrides),
        dict(job.joints or {}),
        _check_law(job.law.terms_for(job.body)),
        scene_of=job.cases if job.body == "space" else None,
    )


def _pinned(job: _Job, m: Measurements, dt: float, values: Sequence[float]) -> pd.DataFrame:
    """The simulated rows of ``m`` with the job's parameters at ``values``."""
    depth, t_s, _ = _model(job, dt).simulate(m.rows, [values], None)
    return _residual_frame(m, depth[0], t_s[0])


def scenes(
    law: str | Law,
    measurements: Measurements | str,
    values: Mapping[str, float] | None = None,
    *,
    dataset: str | None = None,
    dt: float = 1e-4,
    cases: Any = None,
) -> list[Any]:
    """The scenes :func:`granrs.compare` runs for the rows of ``measurements`` under ``law`` at
    the parameter ``values`` (e.g. one fold's ``folds[i]["values"]``): one per row (one
    per case for the chain), to rerun or record a prediction (``cases`` as
    :func:`granrs.compare` takes it)."""
    (law_obj,) = _law_list([law])
    m = measurements if isinstance(measurements, Measurements) else Measurements.load(measurements)
    name = dataset or m.body
    job = _job(law_obj, name, m, _scene_fn(cases, name, m))
    given = dict(values or {})
    if set(given) != set(job.params):
        raise InvalidParameterError(
            f"values must give exactly the law's parameters {list(job.params)}; got {list(given)}",
            field="values",
        )
    return _model(job, dt).scenes(m.rows, [float(given[k]) for k in job.params])
