"""The report's chapter "Force laws": the thesis's three bodies under each of
granrs's force laws, side by side with the thesis's law.

The laws' parameters here are the illustrative ones of ``docs/laws.md`` (``rft``: zeta =
1e6 N/m^3 with the generic coefficients; ``poncelet``: c = 0.8, k = 150 N/m), not fitted:
this chapter shows what each law does to the same drop. Which law fits the experiments,
with fitted parameters and cross-validation, is the comparison of :mod:`granrs.compare`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from .. import forces as f
from ..forces import Term
from .format import _rows, md_table
from .framework import ReportContext, register_chapter

#: The laws of the chapter, by name: a function of the thesis's terms at a scene (its
#: Table 3.4 row) to the law's terms, so that the thesis column is each case's own law.
LAWS: dict[str, Callable[[tuple[Term, ...]], list[Term]]] = {
    "thesis": lambda thesis: list(thesis),
    "rft": lambda _: [f.gravity(), f.rft(zeta=1e6), f.joint_springs()],
    "rft + rft_inertial": lambda _: [
        f.gravity(),
        f.rft(zeta=1e6),
        f.rft_inertial(),
        f.joint_springs(),
    ],
    "poncelet": lambda _: [f.gravity(), f.poncelet(c=0.8, k=150.0), f.joint_springs()],
}

#: The drop of the chapter's figure (a Table 3.1 row).
FIGURE_DROP = (25.0, 2.0)


def _mm(x: float) -> str:
    return f"{x * 1e3:.1f}"


def _ms(x: float) -> str:
    return "not stopped" if x != x else f"{x * 1e3:.1f}"


@register_chapter("force_laws", "Force laws: the thesis's bodies under each law")
def chapter_force_laws(ctx: ReportContext) -> str:
    """Run the free link at the Table 3.1 rows, the chain's three cases and the leg under
    each law; table depth and t_s side by side and draw depth against time for one drop."""
    from ..cases import chain, free_link, leg

    parts = [
        "The thesis's bodies under each of granrs's force laws (`docs/laws.md`), side by "
        "side with the thesis's law. The laws' parameters are illustrative, not fitted "
        "(`rft`: zeta = 1e6 N/m^3 with Li et al.'s generic coefficients; `poncelet`: "
        "c = 0.8, k = 150 N/m): this shows what each law does to the same drop; which law "
        "fits the experiments is the law comparison's question.",
        "",
        "### The free link at the Table 3.1 drops",
        "",
    ]
    rows = []
    with ctx.step("force laws: the free link"):
        for row in _rows("table_3_1_free_link_experiments.csv"):
            q, v0 = float(row["q_deg"]), float(row["v0_mean"])
            cells = [f"{q:g}", f"{v0:.3f}", f"{_mm(float(row['depth_mean']))}"]
            for make in LAWS.values():
                scene = free_link(q, v0, dt=ctx.dt)
                r = ctx.run(scene.replace(forces=make(scene.forces)))
                cells.append(f"{_mm(r.depth)} / {_ms(r.t_s)}")
            rows.append(cells)
    header = ["q [deg]", "v0 [m/s]", "measured depth [mm]"] + [
        f"{name}: depth [mm] / t_s [ms]" for name in LAWS
    ]
    parts += [md_table(header, rows), ""]

    parts += ["### The chain (cases 1-3) and the leg", ""]
    rows = []
    with ctx.step("force laws: the chain and the leg"):
        for case in (1, 2, 3):
            cells = [f"chain case {case}: link 1 / link 2 depth [mm]"]
            for make in LAWS.values():
                scene = chain(case=case, dt=ctx.dt, end="all_stops")
                r = ctx.run(scene.replace(forces=make(scene.forces)))
                cells.append(" / ".join(_mm(c.depth) for c in r.contacts))
            rows.append(cells)
        for v0 in (2.0, 3.28):
            cells = [f"leg at {v0} m/s: depth [mm] / t_s [ms]"]
            for make in LAWS.values():
                scene = leg(v0=v0, dt=ctx.dt)
                r = ctx.run(scene.replace(forces=make(scene.forces)))
                cells.append(f"{_mm(r.depth)} / {_ms(r.t_s)}")
            rows.append(cells)
    parts += [
        md_table(["case", *LAWS], rows),
        "",
        "`poncelet` at k = 150 N/m cannot hold the leg: its k d term carries the 75 kg "
        "body only at d = m g / k, about 5 m; the leg sinks until the run ends. The chain "
        "and the free link weigh grams, and stop.",
        "",
    ]

    with ctx.step("force laws: the figure"):
        parts += [_figure(ctx), ""]
    return "\n".join(parts)


def depth_figure(ctx: ReportContext) -> Any:
    """Tip depth against time of :data:`FIGURE_DROP` under each law (a matplotlib Figure)."""
    from matplotlib.figure import Figure

    from ..cases import free_link

    q, v0 = FIGURE_DROP
    fig = Figure(figsize=(6.0, 3.6))
    ax = fig.subplots()
    for name, make in LAWS.items():
        scene = free_link(q, v0, dt=ctx.dt)
        r = ctx.run(scene.replace(forces=make(scene.forces), record=("state", "forces")))
        depth = [max(0.0, -y) for y in r.series["tip_y"]]
        ax.plot([1e3 * x for x in r.series["t"]], [1e3 * d for d in depth], label=name)
    ax.set_xlabel("t [ms]")
    # Depth grows upwards, as in every other depth-against-time figure of the report.
    ax.set_ylabel("tip depth [mm]")
    ax.set_title(f"The free link at q = {q:g} deg, v0 = {v0:g} m/s, under each law")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    return fig


def _figure(ctx: ReportContext) -> str:
    from .. import plots

    return ctx.add_figure(
        "force_laws_depth.png",
        plots.png_bytes(depth_figure(ctx)),
        "tip depth against time under each law",
    )
