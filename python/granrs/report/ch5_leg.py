"""Chapter 5 of the report: the leg (Table 5.1, the joint study, Fig. 5.10)."""

from __future__ import annotations

import math
import statistics
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import cases
from ..coefficients import Coefficients
from ..result import Result
from .format import (
    _fmt,
    _pct,
    _pm,
    _rms,
    _rows,
    _status_note,
    md_table,
    relative_error,
)
from .framework import ReportContext, register_chapter

__all__ = ["chapter_5"]

#: The thesis's drop heights and the speed each was simulated at (secs. 5.2.2, 5.3.2).
_HEIGHT_SPEEDS: dict[str, float] = {"h1": 3.28, "h2": 2.35}
#: What sec. 5.2.2's text says the average subject does (depth [m], t_s [s]) at each
#: speed; compared with the Table 5.1 means in the report.
_THESIS_TEXT_MEANS: dict[str, tuple[float, float]] = {"h1": (0.05, 0.030), "h2": (0.06, 0.035)}
#: Joint stiffnesses of the spring-damper study [N m/rad] (log-spaced, 3 per decade).
_LEG_STIFFNESS: tuple[float, ...] = tuple(
    float(f"{k:.3g}") for k in np.logspace(math.log10(3.0), math.log10(30000.0), 13)
)
#: Damping ratio of the spring-dampers: c = 2 zeta sqrt(k I_ref), I_ref the half trunk's
#: moment of inertia about the hip (Winter's segment data as scaled by granrs).
_LEG_DAMPING_RATIO = 0.1
_LEG_RECORD = ("state", "forces")


@dataclass(frozen=True)
class _JointSetting:
    """One joint setting of the leg study: a name, the scene fields it sets, k and c."""

    name: str
    fields: dict[str, Any]
    k: float = math.nan
    c: float = math.nan


def _human_coefficients(height: str) -> tuple[Coefficients, dict[str, Any]]:
    """The thesis's coefficients for drop height ``height`` (sec. 5.3.2) and their row."""
    speed = _HEIGHT_SPEEDS[height]
    row = next(r for r in _rows("human_coefficients") if math.isclose(r["v0"], speed))
    coefficients = Coefficients(
        eta_h=row["eta_h"], eta_d=row["eta_d"], eta_v=row["eta_v"], lam=row["lambda"]
    )
    return coefficients, row


def _subject_means(rows: Sequence[Mapping[str, Any]]) -> dict[str, tuple[float, float]]:
    """Mean and sd across subjects of t_s, depth and v0 (the subjects' means)."""
    out = {}
    for key in ("t_s_mean", "depth_mean", "v0_mean"):
        values = [row[key] for row in rows]
        out[key] = (statistics.fmean(values), statistics.stdev(values))
    return out


def _leg_reference_inertia() -> float:
    """The half trunk's moment of inertia about the hip [kg m^2] (I_ref of the damping)."""
    segments = {s["name"]: s for s in cases.leg().leg_segments()}
    trunk = segments["half_trunk"]
    return float(trunk["inertia"] + trunk["mass"] * trunk["com"] ** 2)


def _leg_settings() -> list[_JointSetting]:
    """The joint settings of the study, in report order."""
    i_ref = _leg_reference_inertia()
    settings = [
        _JointSetting("locked (default)", {}),
        _JointSetting("free", {"joints": "free"}),
        _JointSetting("locked, thesis sole (eqs. 5.5-5.7)", {"sole_model": "thesis"}),
    ]
    for k in _LEG_STIFFNESS:
        c = round(2.0 * _LEG_DAMPING_RATIO * math.sqrt(k * i_ref), 4)
        settings.append(
            _JointSetting(f"spring-damper k = {k:g}", {"joints": {"k": k, "c": c}}, k, c)
        )
    return settings


def _combined_error(pairs: Iterable[tuple[float, float]]) -> float:
    """RMS of the relative errors (eq. 5.16 form) of (reference, value) pairs."""
    rms, _ = _rms(relative_error(ref, value) for ref, value in pairs)
    return rms


def _ch5_table_5_1(ctx: ReportContext) -> tuple[str, dict[str, dict[str, tuple[float, float]]]]:
    """Table 5.1 per subject and height against granrs (locked joints, box sole).

    Returns the Markdown and the experiments' means across subjects per height.
    """
    experiments = _rows("table_5_1")
    means: dict[str, dict[str, tuple[float, float]]] = {}
    body = []
    thesis_eps = []
    with ctx.step("chapter 5: Table 5.1 (experiments) vs granrs"):
        for height, speed in _HEIGHT_SPEEDS.items():
            coefficients, th = _human_coefficients(height)
            rows = [row for row in experiments if row["height_case"] == height]
            for row in rows:
                r = ctx.leg(row["v0_mean"], coefficients=coefficients)
                body.append(
                    [
                        height,
                        f"subject {int(row['subject'])}",
                        _pm(row["v0_mean"], row["v0_sd"], ".2f"),
                        _pm(row["t_s_mean"], row["t_s_sd"], ".0f", 1e3),
                        _pm(row["depth_mean"], row["depth_sd"], ".0f", 1e3),
                        f"{r.scene.v0:.2f}",
                        _fmt(r.t_s, ".1f", 1e3) + _status_note(r),
                        _fmt(r.t_s - row["t_s_mean"], "+.1f", 1e3),
                        _fmt(r.depth, ".1f", 1e3),
                        _pct(relative_error(row["depth_mean"], r.depth)),
                    ]
                )
            m = means[height] = _subject_means(rows)
            r = ctx.leg(m["v0_mean"][0], coefficients=coefficients)
            body.append(
                [
                    height,
                    f"**mean of {len(rows)} subjects** (± sd across subjects)",
                    _pm(*m["v0_mean"], ".2f"),
                    _pm(*m["t_s_mean"], ".1f", 1e3),
                    _pm(*m["depth_mean"], ".1f", 1e3),
                    f"{r.scene.v0:.2f}",
                    _fmt(r.t_s, ".1f", 1e3) + _status_note(r),
                    _fmt(r.t_s - m["t_s_mean"][0], "+.1f", 1e3),
                    _fmt(r.depth, ".1f", 1e3),
                    _pct(relative_error(m["depth_mean"][0], r.depth)),
                ]
            )
            r = ctx.leg(speed, coefficients=coefficients)
            thesis_eps.append((height, relative_error(m["depth_mean"][0], th["depth_sim"]), th))
            body.append(
                [
                    height,
                    "thesis simulation (sec. 5.3.2; Δ and ε vs it)",
                    f"{speed:.2f}",
                    _fmt(th["t_s_sim"], ".0f", 1e3),
                    _fmt(th["depth_sim"], ".0f", 1e3),
                    f"{r.scene.v0:.2f}",
                    _fmt(r.t_s, ".1f", 1e3) + _status_note(r),
                    _fmt(r.t_s - th["t_s_sim"], "+.1f", 1e3),
                    _fmt(r.depth, ".1f", 1e3),
                    _pct(relative_error(th["depth_sim"], r.depth)),
                ]
            )
    header = [
        "height",
        "row",
        "v0 [m/s]",
        "t_s exp. / thesis [ms]",
        "depth exp. / thesis [mm]",
        "v0 run [m/s]",
        "t_s granrs [ms]",
        "Δt_s granrs - ref. [ms]",
        "depth granrs [mm]",
        "ε depth (eq. 5.16) [%]",
    ]
    thesis_lines = "\n".join(
        f"- {height} (v0 = {_HEIGHT_SPEEDS[height]} m/s): the thesis's simulated depth "
        f"{_fmt(th['depth_sim'], '.0f', 1e3)} mm against the subjects' mean "
        f"{_fmt(means[height]['depth_mean'][0], '.1f', 1e3)} mm is ε = {_pct(eps)} % by eq. "
        f"5.16; the thesis prints {_fmt(th['depth_rel_err_pct'], '.2f')} %. Its t_s "
        f"{_fmt(th['t_s_sim'], '.0f', 1e3)} ms against the mean "
        f"{_fmt(means[height]['t_s_mean'][0], '.1f', 1e3)} ms. Sec. 5.2.2's text says the "
        f"average subject stops at {_fmt(_THESIS_TEXT_MEANS[height][0], '.2f')} m after "
        f"{_fmt(_THESIS_TEXT_MEANS[height][1], '.3f')} s at this speed."
        for height, eps, th in thesis_eps
    )
    text = f"""### Table 5.1: the experiments against granrs

Table 5.1 (per subject: mean ± sd of the jumps from each height; units m and m/s although the
source prints "in") against granrs's leg (chapter 5's average subject: 75.35 kg, 1.78 m, foot
0.254 m, shoe 0.086 m, tibia 0.432 m; Dempster/Winter segments; all joints locked; box sole;
force at the tip) dropped at each subject's mean speed with the thesis's coefficients of that
height (sec. 5.3.2: h1 at {_HEIGHT_SPEEDS["h1"]} m/s, h2 at {_HEIGHT_SPEEDS["h2"]} m/s; the
thesis gives no per-subject anthropometry, so every subject is the average body). The mean
row is the mean (± sd) of the five subjects' means, run at their mean speed; the thesis row
is the thesis's own simulation, and granrs at the thesis's speed, Δ and ε there taken
against the thesis.

{md_table(header, body, "ll")}

{thesis_lines}
"""
    return text, means


def _ch5_joint_study(
    ctx: ReportContext, means: Mapping[str, Mapping[str, tuple[float, float]]]
) -> tuple[str, list[_JointSetting], dict[tuple[str, str], Result], dict[str, str]]:
    """The leg's joints: locked, free, spring-dampers, and the thesis sole.

    Returns the Markdown, the settings, the runs by (setting name, height), and the names
    of the settings closest to the thesis and to the experiments.
    """
    settings = _leg_settings()
    runs: dict[tuple[str, str], Result] = {}
    with ctx.step(f"chapter 5: joint study ({len(settings)} settings x 2 speeds)"):
        for setting in settings:
            for height, speed in _HEIGHT_SPEEDS.items():
                runs[(setting.name, height)] = ctx.leg(speed, record=_LEG_RECORD, **setting.fields)
    thesis = {h: _human_coefficients(h)[1] for h in _HEIGHT_SPEEDS}

    def errors(name: str) -> tuple[float, float]:
        """Combined RMS relative error of depth and t_s at both speeds: vs the thesis, vs
        the experiments' mean."""
        pairs_th, pairs_exp = [], []
        for h in _HEIGHT_SPEEDS:
            r = runs[(name, h)]
            t_s = r.t_s if r.stopped else math.nan
            pairs_th += [(thesis[h]["depth_sim"], r.depth), (thesis[h]["t_s_sim"], t_s)]
            pairs_exp += [(means[h]["depth_mean"][0], r.depth), (means[h]["t_s_mean"][0], t_s)]
        return _combined_error(pairs_th), _combined_error(pairs_exp)

    scores = {s.name: errors(s.name) for s in settings}

    def score(name: str, which: int) -> float:
        """The score ``which`` (0: thesis, 1: experiments), infinite when undefined."""
        value = scores[name][which]
        return value if math.isfinite(value) else math.inf

    best_th = min(scores, key=lambda n: score(n, 0))
    best_exp = min(scores, key=lambda n: score(n, 1))

    body = [
        [
            "**thesis simulation** (sec. 5.3.2)",
            "",
            "",
            *(
                cell
                for h in _HEIGHT_SPEEDS
                for cell in (
                    _fmt(thesis[h]["t_s_sim"], ".0f", 1e3),
                    _fmt(thesis[h]["depth_sim"], ".0f", 1e3),
                )
            ),
            "",
            "",
        ],
        [
            "**experiments**, mean of 5 subjects (Table 5.1)",
            "",
            "",
            *(
                cell
                for h in _HEIGHT_SPEEDS
                for cell in (
                    _fmt(means[h]["t_s_mean"][0], ".1f", 1e3),
                    _fmt(means[h]["depth_mean"][0], ".1f", 1e3),
                )
            ),
            "",
            "",
        ],
    ]
    for s in settings:
        spring = math.isfinite(s.k)
        cells = [s.name, _fmt(s.k, "g") if spring else "-", _fmt(s.c, ".3g") if spring else "-"]
        for h in _HEIGHT_SPEEDS:
            r = runs[(s.name, h)]
            cells += [_fmt(r.t_s, ".1f", 1e3) + _status_note(r), _fmt(r.depth, ".1f", 1e3)]
        th, ex = scores[s.name]
        mark_th = " (closest)" if s.name == best_th else ""
        mark_ex = " (closest)" if s.name == best_exp else ""
        body.append([*cells, _pct(th) + mark_th, _pct(ex) + mark_ex])
    header = ["setting", "k [N m/rad]", "c [N m s/rad]"]
    for h, speed in _HEIGHT_SPEEDS.items():
        header += [f"t_s {h}, {speed} m/s [ms]", f"depth {h}, {speed} m/s [mm]"]
    header += ["RMS ε vs thesis [%]", "RMS ε vs experiments [%]"]

    # A convergence check of the stiffest setting: the same run at dt / 4.
    stiff = settings[-1]
    check = []
    with ctx.step("chapter 5: stiffest spring-damper at dt / 4 (convergence check)"):
        for h, speed in _HEIGHT_SPEEDS.items():
            fine = ctx.run(cases.leg(v0=speed, dt=ctx.dt / 4.0, **stiff.fields))
            coarse = runs[(stiff.name, h)]
            check.append(
                f"{h}: depth {_fmt(coarse.depth, '.2f', 1e3)} / {_fmt(fine.depth, '.2f', 1e3)} "
                f"mm, t_s {_fmt(coarse.t_s, '.2f', 1e3)} / {_fmt(fine.t_s, '.2f', 1e3)} ms"
            )

    def describe(name: str) -> str:
        """``name``'s numbers at both speeds."""
        parts = []
        for h, speed in _HEIGHT_SPEEDS.items():
            r = runs[(name, h)]
            parts.append(
                f"{_fmt(r.depth, '.0f', 1e3)} mm / {_fmt(r.t_s, '.0f', 1e3)} ms at {speed} m/s"
            )
        return ", ".join(parts)

    springs = [s for s in settings if math.isfinite(s.k)]
    edges = {springs[0].name: "softest", springs[-1].name: "stiffest"}

    def edge(name: str) -> str:
        """A warning when ``name`` is the softest or stiffest spring of the sweep."""
        return (
            f" (the {edges[name]} spring swept: the best may lie outside the range)"
            if name in edges
            else ""
        )

    within = [n for n in scores if score(n, 0) <= 0.1 or score(n, 1) <= 0.1]
    gap = (
        "No setting comes within 10 % (RMS) of either reference."
        if not within
        else "Within 10 % (RMS) of a reference: " + ", ".join(within) + "."
    )
    ctx.add_headline(
        f"Leg (chapter 5): closest to the thesis's simulation: {best_th} "
        f"({describe(best_th)}; RMS ε {_pct(scores[best_th][0])} %){edge(best_th)}; "
        f"closest to the "
        f"experiments' mean: {best_exp} ({describe(best_exp)}; RMS ε "
        f"{_pct(scores[best_exp][1])} %){edge(best_exp)}. Locked joints (the default): "
        f"{describe(settings[0].name)}. {gap}"
    )
    i_ref = _leg_reference_inertia()
    text = f"""### The joints: locked, free, spring-dampers

The thesis's mannequin had joints "to preserve the necessary degrees of freedom" (sec. 5.3.1)
but does not say how stiff they were, and its foot depth hangs on it. granrs runs the leg at
the thesis's two speeds with its coefficients for each, for: every joint (ankle, knee, hip)
locked; every joint free; a rotational spring-damper at every joint, relaxed at the touchdown
posture, for {len(_LEG_STIFFNESS)} stiffnesses k from {_LEG_STIFFNESS[0]:g} to
{_LEG_STIFFNESS[-1]:g} N m/rad (log-spaced), with damping c = 2 ζ sqrt(k I_ref), ζ =
{_LEG_DAMPING_RATIO:g} and I_ref = {i_ref:.2f} kg m² (the half trunk about the hip, the
largest segment; a light damping, so that the stiffness is what varies); and the locked leg
with the thesis's sole (eqs. 5.5-5.7 with the shank's angle) instead of the box. RMS ε is
the root mean square of the four relative errors (depth and t_s at both speeds, eq. 5.16
form) against the thesis's simulation or the experiments' mean.

{md_table(header, body, "l")}

- **Closest to the thesis's simulation: {best_th}** ({describe(best_th)}; RMS ε
  {_pct(scores[best_th][0])} %){edge(best_th)}.
- **Closest to the experiments' mean: {best_exp}** ({describe(best_exp)}; RMS ε
  {_pct(scores[best_exp][1])} %){edge(best_exp)}.
- {gap}
- Convergence check, stiffest setting (k = {stiff.k:g} N m/rad) at dt and dt / 4:
  {"; ".join(check)}.
"""
    return text, settings, runs, {"thesis": best_th, "experiments": best_exp}


def _ch5_figures(
    ctx: ReportContext,
    means: Mapping[str, Mapping[str, tuple[float, float]]],
    settings: Sequence[_JointSetting],
    runs: Mapping[tuple[str, str], Result],
    best: Mapping[str, str],
) -> str:
    """Fig. 5.10 (foot depth and velocity) for a few joint settings, and depth and t_s
    against the joint stiffness."""
    from .. import plots

    shown = [settings[0].name, settings[1].name, settings[2].name]
    for name in (best["thesis"], best["experiments"]):
        if name not in shown:
            shown.append(name)
    links = []
    with ctx.step("chapter 5: Fig. 5.10 and the stiffness figure"):
        rows = []
        for h, speed in _HEIGHT_SPEEDS.items():
            thesis = _human_coefficients(h)[1]
            d_curves, v_curves, d_points, v_points = [], [], [], []
            for i, name in enumerate(shown):
                r = runs[(name, h)]
                assert r.series is not None
                t = r.series["t"]
                d_curves.append(plots.Curve(t, r.series["depth"], i, name))
                v_curves.append(plots.Curve(t, -r.series["v_tip_y"], i, name))
                if r.stopped:
                    d_points.append(plots.Point(r.t_s, r.depth, i, "stop"))
                    v_points.append(plots.Point(r.t_s, 0.0, i, "stop"))
            m = means[h]
            d_points.append(
                plots.Point(
                    m["t_s_mean"][0],
                    m["depth_mean"][0],
                    None,
                    x_sd=m["t_s_mean"][1],
                    y_sd=m["depth_mean"][1],
                )
            )
            v_points.append(plots.Point(m["t_s_mean"][0], 0.0, None, x_sd=m["t_s_mean"][1]))
            d_points.append(plots.Point(thesis["t_s_sim"], thesis["depth_sim"], None, "thesis"))
            v_points.append(plots.Point(thesis["t_s_sim"], 0.0, None, "thesis"))
            rows.append(
                [
                    plots.Panel(
                        f"Fig. 5.10 (a): foot depth, {h}, v0 = {speed} m/s",
                        "foot depth d [mm]",
                        d_curves,
                        d_points,
                        y_scale=1e3,
                        legend=h == "h1",
                    ),
                    plots.Panel(
                        f"Fig. 5.10 (b): foot vertical velocity, {h}, v0 = {speed} m/s",
                        r"downward foot velocity $-v_{y,T}$ [m/s]",
                        v_curves,
                        v_points,
                        y_from_zero=False,
                        zero_line=True,
                    ),
                ]
            )
        fig = plots.panel_grid(
            rows,
            title="Fig. 5.10: the foot against time for several joint settings",
            point_labels={
                "experiment": "experiments' end, mean ± sd of 5 subjects (Table 5.1)",
                "thesis": "thesis simulation end (sec. 5.3.2)",
                "stop": "granrs stop",
            },
            row_height=4.4,
        )
        links.append(
            ctx.add_figure(
                "fig_5_10_depth_velocity.png",
                plots.png_bytes(fig),
                "Fig. 5.10: foot depth and velocity for several joint settings",
            )
            + "\n\n*Left: Fig. 5.10 (a), foot depth against time; right: Fig. 5.10 (b), "
            "downward foot velocity; top: h1, bottom: h2.*"
        )

        springs = [s for s in settings if math.isfinite(s.k)]
        panels = []
        for key, name, unit_label in (
            ("depth", "foot depth at the stop", "depth [mm]"),
            ("t_s", "stopping time", "t_s [ms]"),
        ):
            curves, lines = [], []
            for i, (h, speed) in enumerate(_HEIGHT_SPEEDS.items()):
                values = np.array([getattr(runs[(s.name, h)], key) for s in springs])
                ks = np.array([s.k for s in springs])
                curves.append(plots.Curve(ks, values, i, f"granrs, {h}, {speed} m/s", marker="."))
                thesis = _human_coefficients(h)[1]
                ref = thesis["depth_sim"] if key == "depth" else thesis["t_s_sim"]
                lines.append(plots.RefLine(ref, f"thesis simulation, {h}", i, "--"))
                mean = means[h]["depth_mean" if key == "depth" else "t_s_mean"][0]
                lines.append(plots.RefLine(mean, f"experiments' mean, {h}", i, ":"))
                locked = getattr(runs[(settings[0].name, h)], key)
                lines.append(plots.RefLine(locked, f"granrs locked, {h}", i, "-."))
            panels.append(
                plots.Panel(
                    f"{name} against the joint stiffness (ζ = {_LEG_DAMPING_RATIO:g})",
                    unit_label,
                    curves,
                    lines=lines,
                    xlabel="joint stiffness k [N m/rad] (ankle, knee and hip)",
                    x_scale=1.0,
                    y_scale=1e3,
                    xlog=True,
                    legend=key == "depth",
                )
            )
        fig = plots.panel_grid([panels], row_height=4.8, width=12.0)
        links.append(
            ctx.add_figure(
                "fig_5_joint_stiffness.png",
                plots.png_bytes(fig),
                "Foot depth and stopping time against the joint stiffness",
            )
        )
    return f"""### Fig. 5.10: the foot against time

Foot depth and downward velocity at both speeds for: {", ".join(shown)}; the experiments'
end points (the mean ± sd of the five subjects' means, Table 5.1), the thesis's simulated end
points (sec. 5.3.2) and the granrs stops. The second figure: depth and t_s of the
spring-damper settings against k, with the thesis's simulation (dashed), the experiments'
mean (dotted) and the locked leg (dash-dotted).

{chr(10).join(chr(10) + link for link in links)}
"""


@register_chapter("5", "Chapter 5: the leg")
def chapter_5(ctx: ReportContext) -> str:
    """Chapter 5: the leg against Table 5.1 and sec. 5.3.2, the joints, Fig. 5.10."""
    table_5_1, means = _ch5_table_5_1(ctx)
    study, settings, runs, best = _ch5_joint_study(ctx, means)
    figures = _ch5_figures(ctx, means, settings, runs, best)
    return "\n".join(
        [
            "One leg of the thesis's average subject landing on both feet on fine sand "
            "(rho_g = 1600 kg/m³, sec. 5.3.2): foot, shank, thigh and half of head-arms-trunk "
            "(half the body), segment data from Dempster as tabulated by Winter, scaled to "
            "75.35 kg and 1.78 m; posture at touchdown: knee and hip flexed 20°, trunk 10° "
            "forward, flat foot (granrs assumptions; the thesis gives none). The sole is a "
            "box of the foot's length and the shoe's width (docs/model.md), the coefficients the "
            "thesis's for each speed (sec. 5.3.2), the force at the tip (the sole). The "
            "thesis's human model (SolidWorks, GrabCAD parts) is not published, so this "
            "chapter compares end results only.",
            "",
            table_5_1,
            study,
            figures,
            _watch(ctx),
        ]
    )


def _watch(ctx: ReportContext) -> str:
    """The leg at 3.28 m/s, joints locked, as an animation."""
    scene = cases.leg(v0=3.28, dt=ctx.dt)
    return ctx.watch(
        "ch5_leg_3_28.gif",
        scene,
        f"The {scene.v0:g} m/s landing, joints locked, one frame per 2 ms (the second panel "
        "zooms on the foot).",
        frame_dt=2e-3,
    )
