"""A calibration written as a medium card (:meth:`CalibrationResult.card`): each fitted
term's parameter that is one value of the medium becomes a card value with its source, its
standard error, its ~95 % interval and, when the fit sampled its posterior, the samples.

What is not one value of the medium is not written as one: a factor on base values that
differ from row to row (the thesis's Table 3.4 per angle) and angle nodes are listed under
the card's ``missing`` with the reason; the body's unknowns (a link's mass, the leg's
joints) are the body's, not the sand's, and are left out.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import InvalidParameterError, MediumError

if TYPE_CHECKING:
    from ..media import MediumCard
    from .fit import CalibrationResult

__all__ = ["card_of"]

#: The level of a fit's intervals (+-1.96 standard errors in the fitted space).
_LEVEL = 0.95


def _row_values(result: CalibrationResult, term: str, param: str) -> list[Any]:
    """The fitted value of ``term.param`` in every measured row (one per contact)."""
    model = result._model
    values = [result.values[p] for p in result.params]
    out = []
    for row in result._measurements.rows.to_dict("records"):
        scene = model.space_scene(row) if result.body == "space" else None
        for t in model.row_terms(row, values, scene):
            if t.name == term:
                out.append(t.params.get(param))
    return out


def _one(values: Sequence[Any]) -> float | None:
    """The value shared by every row, or None if they differ or one is not a number."""
    if not values or not all(isinstance(v, (int, float)) for v in values):
        return None
    first = float(values[0])
    if all(math.isclose(float(v), first, rel_tol=1e-12, abs_tol=0.0) for v in values):
        return first
    return None


def _rho_g(result: CalibrationResult) -> float | None:
    """The density of the scenes fitted, if every one has the same."""
    values = [result.values[p] for p in result.params]
    scenes = result._model.scenes(result._measurements.rows, values)
    return _one([float(s.rho_g) for s in scenes])


def card_of(
    result: CalibrationResult,
    name: str,
    *,
    base: Any = None,
    description: str | None = None,
    source: str | None = None,
) -> MediumCard:
    """The medium card of ``result`` (see :meth:`CalibrationResult.card`)."""
    from .. import media

    card = media.load(base) if base is not None else media.MediumCard(name)
    if not isinstance(description, (str, type(None))):
        raise InvalidParameterError(
            f"description must be text; got {description!r}", field="description"
        )
    if not isinstance(source, (str, type(None))) or (source is not None and not source.strip()):
        raise InvalidParameterError(f"source must be non-empty text; got {source!r}", "source")
    m = result._measurements
    how = source or (
        f"fitted here: granrs.calibrate (weighted least squares, the {result.body}) to "
        f"{len(m)} rows of {m.source}"
    )
    rho = _rho_g(result)
    if card.rho_g is not None and rho is not None and not math.isclose(card.rho_g, rho):
        raise MediumError(
            f"the card {card.name!r} has rho_g = {card.rho_g:g} kg/m^3 but the fit's scenes "
            f"used {rho:g}: its values would be for another density",
            field="rho_g",
        )
    changes: dict[str, Any] = {"name": name}
    if description is not None:
        changes["description"] = description
    elif base is None:
        changes["description"] = f"written by granrs.calibrate: {how}"
    card = card.replace(**changes)
    if card.rho_g is None and rho is not None:
        card = card.with_value(
            "rho_g",
            rho,
            f"the bulk density of the scenes granrs.calibrate ran (on {len(m)} rows of {m.source})",
        )
    samples = result.posterior.samples if result.posterior is not None else None
    missing = dict(card.missing)
    written = dict(card.params)
    parsed = {p.name: p for p in result._model.params}
    for p in result.params:
        info = parsed[p]
        if info.kind not in ("coef", "scale", "node"):
            continue  # the body's, not the medium's
        key = f"{info.term}.{info.target}"
        if info.kind == "node":
            missing[key] = (
                f"fitted per impact angle ({p} and the other nodes): not one value of the medium"
            )
            written.pop(key, None)
            continue
        factor = 1.0
        if info.kind == "scale":
            fitted = _row_values(result, info.term, info.target)
            one = _one(fitted)
            if one is None:
                numbers = [float(v) for v in fitted if isinstance(v, (int, float))]
                spread = (
                    f" ({min(numbers):.4g} to {max(numbers):.4g} over the rows)" if numbers else ""
                )
                missing[key] = (
                    f"fitted as a factor {result.values[p]:.4g} on base values that differ "
                    f"from row to row{spread}: not one value of the medium"
                )
                written.pop(key, None)
                continue
            factor = one / result.values[p]
        value = result.values[p] * factor
        se = result.std_errors.get(p, math.nan) * factor
        lo, hi = (x * factor for x in result.intervals[p])
        kept = [] if samples is None else [float(x) * factor for x in samples[p]]
        what = f"{how}; sd and ~95 % interval from the fit's Jacobian"
        if p in result.at_bound:
            what += "; the fit ended on its bound, so the interval is not reliable"
        if kept:
            what += f"; {len(kept)} posterior samples (emcee)"
        finite = math.isfinite(lo) and math.isfinite(hi)
        written[key] = media.Value(
            value,
            what,
            sd=se if math.isfinite(se) else None,
            interval=(lo, hi) if finite else None,
            level=_LEVEL if finite else None,
            samples=tuple(np.asarray(kept, dtype=float).tolist()),
        )
        missing.pop(key, None)
    return card.replace(params=written, missing=missing)
