"""Soak: a million random valid free-link scenes through ``granrs.sweep`` (issue 6), and
beside them (``--table-share``, 2 % by default) two-link linkages whose knee is driven along a
random table (issue 19), and (``--arc-share``, 2 %) random arc contacts, C-legs (issue 19,
:func:`random_arc`; half of them with a box contact too), and (``--space-share``, 0.5 %)
random bodies in space (:func:`random_space`: every shape, every term in space, random
orientation, velocity and spin), each kind swept separately.

Checks that a long batch never returns NaN or infinity in a run that did not fail, never
hangs and keeps its memory flat. Scenes are drawn from the valid domain of
tests/test_properties.py (angle in (-90, 90) deg, v0 in [0, 10] m/s, coefficients 0..10x
Table 3.4, masses 1 g .. 100 kg, every sign model, both points of application) with the
thesis's step (dt = 1e-4 s by default; ``--dt-range`` draws dt from 1e-6 .. 1e-3 s) and
``t_end`` capped so that a run takes at most ``--max-steps`` steps.

They run in chunks (``--chunk``, 50,000 by default), each one ``granrs.sweep`` over a list
of scenes; after each chunk the script prints the chunk, its seconds, the runs per second,
its status counts and the resident memory (VmRSS from /proc/self/status). At the end: the
totals, every failed run (with its scene and message; at most 20 printed), every run with
a non-finite result, and the RSS growth from the first chunk to the last.

Usage::

    nice -n 10 python benches/soak.py [--n 1000000] [--chunk 50000] [--seed 0]

Exits 1 if any run returned a non-finite number or memory grew by more than ``--max-growth``
MB over the second half of the chunks (the first chunks warm the allocator up).
"""

from __future__ import annotations

import argparse
import collections
import math
import sys
import time
import warnings
from typing import Any

import numpy as np

import granrs
from granrs import Coefficients, Scene, forces, space

SCALE = {"eta_h": 6.5, "eta_d": 15.2, "eta_v": 248.0, "lam": 0.106}
SIGN_MODELS = ("modes", "raw", "smooth")
APPLY_AT = ("tip", "centroid")


def rss_mb() -> float:
    """Resident set size of this process [MB] (Linux /proc)."""
    with open("/proc/self/status", encoding="ascii") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return math.nan


def random_scenes(rng: np.random.Generator, n: int, dt_range: bool, max_steps: int) -> list[Scene]:
    """``n`` random valid free-link scenes (vectorized draws, then one Scene each)."""
    q = rng.uniform(-89.99, 89.99, n)
    v0 = rng.uniform(0.0, 10.0, n)
    vx0 = np.where(rng.random(n) < 0.3, rng.uniform(-2.0, 2.0, n), 0.0)
    omega0 = np.where(rng.random(n) < 0.3, rng.uniform(-20.0, 20.0, n), 0.0)
    mass = 10.0 ** rng.uniform(-3.0, 2.0, n)
    factors = rng.uniform(0.0, 10.0, (n, 4))
    dt = 10.0 ** rng.uniform(-6.0, -3.0, n) if dt_range else np.full(n, 1e-4)
    t_end = np.minimum(1.0, max_steps * dt)
    sign = rng.integers(0, 3, n)
    apply = rng.integers(0, 2, n)
    out = []
    for i in range(n):
        f = factors[i]
        out.append(
            Scene(
                q_deg=float(q[i]),
                v0=float(v0[i]),
                vx0=float(vx0[i]),
                omega0=float(omega0[i]),
                mass=float(mass[i]),
                # A third of the scenes give the law as force terms: a random subset of
                # the thesis's terms (issue 16), the rest as coefficients.
                **_law(rng, f),
                dt=float(dt[i]),
                t_end=float(t_end[i]),
                sign_model=SIGN_MODELS[sign[i]],
                apply_at=APPLY_AT[apply[i]],
            )
        )
    return out


def _law(rng: np.random.Generator, f: np.ndarray) -> dict[str, object]:
    """The thesis's terms at 0..10x Table 3.4's q = 0 row; in a third of the scenes a random
    subset of them (issue 16); in a quarter, one of the field's laws (issue 17) with random
    parameters: rft (zeta 0..1e7 N/m^3, 1..16 elements), rft + rft_inertial, poncelet
    (c 0..5, k 0..1000 N/m), or the thesis's static terms with the axial drag (eta_a
    0..20)."""
    u = rng.random()
    if u < 0.25:
        zeta = 1e7 * f[0] / 10.0
        n = int(rng.integers(1, 17))
        law = rng.integers(0, 4)
        if law == 0:
            extra: tuple[forces.Term, ...] = (forces.rft(zeta=zeta, elements=n),)
        elif law == 1:
            extra = (
                forces.rft(zeta=zeta, elements=n),
                forces.rft_inertial(lam=float(f[1]) / 5.0, elements=n),
            )
        elif law == 2:
            extra = (forces.poncelet(c=float(f[2]) / 2.0, k=100.0 * float(f[3])),)
        else:
            extra = (
                forces.axial_drag(eta_a=2.0 * float(f[2])),
                forces.static_h(eta_h=SCALE["eta_h"] * float(f[0])),
                forces.static_v(eta_v=SCALE["eta_v"] * float(f[1]), lam=SCALE["lam"] * float(f[3])),
            )
        return {"forces": (forces.gravity(), *extra)}
    values = {k: SCALE[k] * x for k, x in zip(("eta_h", "eta_d", "eta_v", "lam"), f, strict=True)}
    terms = forces.thesis(Coefficients(**values))
    if u < 0.25 + 0.75 / 3:
        keep = rng.random(len(terms)) < 0.75
        terms = tuple(t for t, k in zip(terms, keep, strict=True) if k)
    return {"forces": terms}


def random_table_scenes(
    rng: np.random.Generator, n: int, dt_range: bool, max_steps: int
) -> list[Scene]:
    """``n`` random valid linkages with a table-driven joint: a thigh on a root moved into the
    sand at 0..3 m/s, a shank hanging from it with a rod contact at its tip, the knee driven
    along 2..6 random points (times -0.1 .. 1.2 t_end, angles -60..60 deg), the law as in
    :func:`random_scenes`, gravity always."""
    out = []
    for _ in range(n):
        dt = float(10.0 ** rng.uniform(-6.0, -3.0)) if dt_range else 1e-4
        t_end = min(0.2, max_steps * dt)
        k = int(rng.integers(2, 7))
        times = np.unique(rng.uniform(-0.1, 1.2 * t_end, k))
        if len(times) < 2:
            times = np.array([0.0, t_end])
        angles = rng.uniform(-60.0, 60.0, len(times))
        start = float(np.interp(0.0, times, angles))
        l1, l2 = rng.uniform(0.05, 0.4, 2)
        m1, m2 = 10.0 ** rng.uniform(-2.0, 1.0, 2)
        q1 = float(rng.uniform(-30.0, 30.0))
        q2 = q1 + start
        # The root above the shank's tip, which starts at the surface.
        y0 = l1 * math.cos(math.radians(q1)) + l2 * math.cos(math.radians(q2))
        x0 = l1 * math.sin(math.radians(q1)) + l2 * math.sin(math.radians(q2))
        body = granrs.bodies.Linkage(
            [
                granrs.bodies.Link("thigh", m1, m1 * l1 * l1 / 12.0, l1, (-0.5 * l1, 0.0), q1),
                granrs.bodies.Link("shank", m2, m2 * l2 * l2 / 12.0, l2, (-0.5 * l2, 0.0), q2),
            ],
            [
                granrs.bodies.Joint(
                    "knee",
                    "thigh",
                    "shank",
                    (-l1, 0.0),
                    kind="driven",
                    table=tuple(zip(times.tolist(), angles.tolist(), strict=True)),
                )
            ],
            [granrs.bodies.Contact.rod("shank", l2, 0.0127, at=(-l2, 0.0))],
            granrs.bodies.Root(
                "moving",
                link="thigh",
                position=(x0, y0),
                velocity=(float(rng.uniform(-1.0, 1.0)), -float(rng.uniform(0.0, 3.0))),
            ),
        )
        law = _law(rng, rng.uniform(0.0, 10.0, 4))
        terms = tuple(law["forces"])  # type: ignore[arg-type]
        if not any(t.name == "gravity" for t in terms):
            terms = (forces.gravity(), *terms)
        out.append(
            Scene(
                body=body,  # type: ignore[arg-type]
                forces=terms,
                dt=dt,
                t_end=t_end,
                end="time",
                sign_model=SIGN_MODELS[int(rng.integers(0, 3))],
                apply_at=APPLY_AT[int(rng.integers(0, 2))],
            )
        )
    return out


def random_arc(rng: np.random.Generator, dt_range: bool, max_steps: int) -> Scene:
    """A random valid arc contact (issue 19): radius 1 cm .. 20 cm, span 1 .. 360 deg,
    1 .. MAX_CHORDS chords, on a link of 10 g .. 10 kg hung 0 .. 2 radii above the sand; the
    root pinned (its angle driven at -30 .. 30 rad/s, or free), moving (down at 0 .. 3 m/s)
    or free; in half of them a box (a plate one radius long, a fifth of it high) on the
    same link as well, so that boxes soak too; rft with zeta 0 .. 1e7 N/m^3, and
    rft_inertial in half of them."""
    from granrs.bodies import MAX_CHORDS, Contact, Link, Linkage, Root

    dt = float(10.0 ** rng.uniform(-6.0, -3.0)) if dt_range else 1e-4
    t_end = min(0.2, max_steps * dt)
    radius = float(10.0 ** rng.uniform(-2.0, np.log10(0.2)))
    start = float(rng.uniform(-360.0, 360.0))
    span = float(rng.uniform(1.0, 360.0))
    mass = float(10.0 ** rng.uniform(-2.0, 1.0))
    kind = ("pinned", "moving", "free")[int(rng.integers(0, 3))]
    rate = float(rng.uniform(-30.0, 30.0)) if kind != "free" and rng.random() < 0.7 else None
    velocity = (float(rng.uniform(-1.0, 1.0)), float(-rng.uniform(0.0, 3.0)))
    body = Linkage(
        links=[
            Link(
                "leg",
                mass,
                mass * radius * radius,
                2 * radius,
                (radius, 0.0),
                q_deg=float(rng.uniform(-180.0, 180.0)),
            )
        ],
        contacts=[
            Contact.arc(
                "leg",
                radius=radius,
                start_deg=start,
                end_deg=start + span,
                width=float(rng.uniform(0.001, 0.05)),
                at=(radius, 0.0),
                chords=int(rng.integers(1, MAX_CHORDS + 1)),
            ),
            *(
                [Contact.box("leg", radius, 0.2 * radius, float(rng.uniform(0.001, 0.05)))]
                if rng.random() < 0.5
                else []
            ),
        ],
        root=Root(
            kind,
            link="leg",
            position=(0.0, float(rng.uniform(0.0, 2.0)) * radius),
            velocity=(0.0, 0.0) if kind == "pinned" else velocity,
            rate=rate,
        ),
    )
    terms: list[forces.Term] = [forces.gravity(), forces.rft(zeta=float(rng.uniform(0.0, 1e7)))]
    if rng.random() < 0.5:
        terms.append(forces.rft_inertial(lam=float(rng.uniform(0.0, 2.0))))
    return Scene(body=body, forces=terms, dt=dt, t_end=t_end, end="time",
                 sign_model=SIGN_MODELS[int(rng.integers(0, 3))])  # fmt: skip


def random_space(rng: np.random.Generator, dt_range: bool, max_steps: int) -> space.Scene:
    """A random valid body in space: any shape of 2 to 60 mm, density 100 to 20000 kg/m^3,
    a random orientation, velocity (up to 5 m/s, mostly down) and spin (up to 30 rad/s),
    under rft3d (zeta 1e4 to 1e7) with, by chance, its inertial term, Poncelet, a friction
    cap and gravity."""
    size = lambda: float(rng.uniform(0.002, 0.06))  # noqa: E731
    kind = int(rng.integers(5))
    shape: Any
    if kind == 0:
        shape = space.Sphere(size())
    elif kind == 1:
        shape = space.Capsule(size(), size())
    elif kind == 2:
        shape = space.Cylinder(size(), size())
    elif kind == 3:
        shape = space.Cuboid((size(), size(), size()))
    else:
        shape = space.Mesh.icosphere(size(), int(rng.integers(0, 3)))
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    v = rng.normal(size=3) * rng.uniform(0.0, 2.0)
    v[2] = -abs(v[2]) - rng.uniform(0.0, 3.0)
    terms = [
        forces.rft3d(
            zeta=float(10 ** rng.uniform(4, 7)),
            mu_surf=float(rng.uniform(0.1, 1.0)) if rng.random() < 0.3 else float("inf"),
        )
    ]
    if rng.random() < 0.5:
        terms.append(forces.rft3d_inertial(lam=float(rng.uniform(0.0, 2.0))))
    if rng.random() < 0.3:
        terms.append(
            forces.poncelet(c=float(rng.uniform(0.0, 2.0)), k=float(rng.uniform(0.0, 500.0)))
        )
    if rng.random() < 0.8:
        terms.append(forces.gravity())
    dt = float(10 ** rng.uniform(-5, -3)) if dt_range else 1e-4
    return space.Scene(
        body=space.Body(shape, density=float(rng.uniform(100.0, 20000.0))),
        orientation=tuple(q),
        velocity=tuple(v),
        omega=tuple(rng.normal(size=3) * rng.uniform(0.0, 30.0)),
        forces=terms,
        dt=dt,
        t_end=min(0.5, max_steps * dt),
        quadrature=int(rng.integers(2, 7)),
    )


def describe(scene: Any) -> str:
    if isinstance(scene, space.Scene):
        return repr(scene)
    if scene.kind == "linkage":
        return (
            f"Scene(body={scene.body!r}, dt={scene.dt!r}, t_end={scene.t_end!r}, "
            f"sign_model={scene.sign_model!r}, apply_at={scene.apply_at!r}, "
            f"forces={scene.forces!r})"
        )
    return (
        f"Scene(q_deg={scene.q_deg!r}, v0={scene.v0!r}, vx0={scene.vx0!r}, "
        f"omega0={scene.omega0!r}, mass={scene.mass!r}, dt={scene.dt!r}, t_end={scene.t_end!r}, "
        f"sign_model={scene.sign_model!r}, apply_at={scene.apply_at!r}, forces={scene.forces!r})"
    )


def soak(args: argparse.Namespace) -> int:
    rng = np.random.default_rng(args.seed)
    statuses: collections.Counter[str] = collections.Counter()
    failed: list[tuple[int, str, str]] = []
    non_finite: list[tuple[int, str, list[str]]] = []
    rss: list[float] = []
    t_all = time.perf_counter()
    print(
        f"granrs {granrs.__version__}: {args.n} scenes in chunks of {args.chunk}, seed {args.seed}"
    )
    print(f"{'chunk':>5} {'runs':>8} {'seconds':>8} {'runs/s':>8} {'RSS MB':>8}  statuses")
    done = 0
    chunk = 0
    while done < args.n:
        size = min(args.chunk, args.n - done)
        tables = int(rng.binomial(size, args.table_share))
        n_arcs = int(rng.binomial(size - tables, args.arc_share))
        n_space = int(rng.binomial(size - tables - n_arcs, args.space_share))
        scenes = random_scenes(rng, size - tables - n_arcs - n_space, args.dt_range, args.max_steps)
        driven = random_table_scenes(rng, tables, args.dt_range, args.max_steps)
        arcs = [random_arc(rng, args.dt_range, args.max_steps) for _ in range(n_arcs)]
        # A sweep's columns are its first body's contacts: arcs with a box swept apart.
        arcs_alone = [a for a in arcs if len(a.body.contacts) == 1]
        arcs_box = [a for a in arcs if len(a.body.contacts) != 1]
        bodies = [random_space(rng, args.dt_range, args.max_steps) for _ in range(n_space)]
        t0 = time.perf_counter()
        counts: collections.Counter[str] = collections.Counter()
        for offset, batch in (
            (done, scenes),
            (done + len(scenes), driven),
            (done + len(scenes) + len(driven), arcs_alone),
            (done + len(scenes) + len(driven) + len(arcs_alone), arcs_box),
            (done + len(scenes) + len(driven) + len(arcs), bodies),
        ):
            if not batch:
                continue
            with warnings.catch_warnings():
                # A stiff random body warns; the soak checks finiteness, not resolution.
                warnings.simplefilter("ignore", granrs.StepSizeWarning)
                df = granrs.sweep(batch, progress=False)
            counts.update({str(k): int(v) for k, v in df["status"].value_counts().items() if v})
            bad = (df["status"] == "failed").to_numpy()
            for i in np.flatnonzero(bad):
                failed.append((offset + int(i), describe(batch[i]), str(df["error"].iloc[i])))
            ok = df[~bad]
            # t_s and t_entry are NaN where a contact did not stop or enter (one contact:
            # "t_s"; several: "c0.t_s", ...).
            times = [c for c in ok.columns if c.split(".")[-1] in ("t_s", "t_entry")]
            numeric = ok.drop(columns=["status", "error", *times], errors="ignore")
            numeric = numeric.select_dtypes("number")
            values = numeric.to_numpy()
            # A list of arcs with and without a box: a contact a run does not have is NaN in
            # all its columns (not applicable); infinities, and NaN elsewhere, are failures.
            extra = np.array(
                [c.startswith("c") and c[1:2].isdigit() and c[1] != "0" for c in numeric.columns]
            )
            whole = np.zeros(len(values), bool)
            if extra.any():
                whole = np.isnan(values[:, extra]).all(axis=1)
            bad_values = np.isinf(values) | (np.isnan(values) & ~(extra[None, :] & whole[:, None]))
            rows = np.flatnonzero(bad_values.any(axis=1))
            stopped = (ok["status"] == "stopped").to_numpy()
            t_s = [c for c in times if c.split(".")[-1] == "t_s"]
            no_stop = ok[t_s].isna().all(axis=1).to_numpy() if t_s else np.zeros(len(ok), bool)
            rows = np.union1d(rows, np.flatnonzero(stopped & no_stop))
            index = np.flatnonzero(~bad)
            for r in rows:
                cols = [c for c in numeric.columns if not np.isfinite(numeric[c].iloc[r])]
                non_finite.append((offset + int(index[r]), describe(batch[index[r]]), cols))
            del df, ok, numeric, values
        seconds = time.perf_counter() - t0
        statuses.update(counts)
        del scenes, driven, arcs, arcs_alone, arcs_box, bodies
        rss.append(rss_mb())
        short = ", ".join(f"{k} {int(v)}" for k, v in counts.items() if v)
        print(
            f"{chunk:>5} {size:>8} {seconds:>8.1f} {size / seconds:>8.0f} {rss[-1]:>8.1f}  {short}",
            flush=True,
        )
        done += size
        chunk += 1
    elapsed = time.perf_counter() - t_all
    growth = rss[-1] - rss[0]
    late = rss[-1] - rss[len(rss) // 2]
    print(f"total: {done} runs in {elapsed:.0f} s ({done / elapsed:.0f} runs/s)")
    print("statuses: " + ", ".join(f"{k} {v}" for k, v in sorted(statuses.items())))
    print(
        f"RSS: first chunk {rss[0]:.1f} MB, last {rss[-1]:.1f} MB, max {max(rss):.1f} MB, "
        f"growth after the first chunk {growth:+.1f} MB, over the second half {late:+.1f} MB"
    )
    kinds = collections.Counter(message.split(" at t =")[0] for _, _, message in failed)
    print(f"failed runs: {len(failed)}" + "".join(f"\n  {v} x {k}" for k, v in kinds.items()))
    for i, scene, message in failed[:20]:
        print(f"  run {i}: {message}\n    {scene}")
    print(f"runs with a non-finite result: {len(non_finite)}")
    for i, scene, cols in non_finite[:20]:
        print(f"  run {i}: {', '.join(cols) or 't_s'}\n    {scene}")
    return 1 if non_finite or late > args.max_growth else 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--n", type=int, default=1_000_000, help="scenes (1000000)")
    parser.add_argument("--chunk", type=int, default=50_000, help="scenes per sweep (50000)")
    parser.add_argument("--seed", type=int, default=0, help="random seed (0)")
    parser.add_argument(
        "--dt-range", action="store_true", help="draw dt from 1e-6 .. 1e-3 s (default: 1e-4)"
    )
    parser.add_argument(
        "--max-steps", type=int, default=20_000, help="cap on steps per run via t_end (20000)"
    )
    parser.add_argument(
        "--table-share",
        type=float,
        default=0.02,
        help="share of the scenes that are linkages with a table-driven joint (0.02)",
    )
    parser.add_argument(
        "--arc-share",
        type=float,
        default=0.02,
        help="share of the scenes that are random arc contacts, C-legs (0.02)",
    )
    parser.add_argument(
        "--space-share",
        type=float,
        default=0.005,
        help="share of the scenes that are random bodies in space (0.005)",
    )
    parser.add_argument(
        "--max-growth",
        type=float,
        default=50.0,
        help="allowed RSS growth over the second half [MB] (50)",
    )
    args: Any = parser.parse_args(argv)
    return soak(args)


if __name__ == "__main__":
    sys.exit(main())
