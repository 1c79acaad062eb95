"""granrs.mujoco.Sand: its accuracy against granrs.simulate, and its cost per MuJoCo step.

**Accuracy (``--part table``).** The thesis's free link dropped in MuJoCo
(:func:`granrs.mujoco.rod_drop`: a cylinder geom on slide x, slide z and hinge y, its tip at
the surface, v0 = 2 m/s straight down) under a law's contact terms, against
:func:`granrs.simulate` of the same scene (RK4 at 1e-4 s with its events located: the
converged answer), for q = 0, 30 and 60 deg, MuJoCo timesteps 1e-4, 1e-3 and 2e-3 s, and the
Euler (MuJoCo's default), RK4 and implicitfast integrators, with ``Sand.step`` before
``mj_step`` (the force held through MuJoCo's step) and, for RK4, also as the passive callback
(evaluated at each stage). The stop is the first step whose end has the tip's vertical
velocity >= 0 (within the Sand's ``rest_speed``), interpolated linearly inside the step. The
laws: the thesis's (Table 3.4's row nearest q) and, where the core has it, ``rft(zeta=1e6,
elements=64)``. A row passes when the depth is within 2 % and t_s within 5 %.

**Cost (``--part cost``).** The gallery's walker (:func:`granrs.mujoco.walker_mjcf`, 7 dofs,
2 sand geoms), landed and standing in sand under the thesis's law (both geoms in the sand, the
static terms as reactions): the time of ``mj_step`` alone, of ``Sand.step`` + ``mj_step``, and
of ``mj_step`` with the Sand installed as the passive callback, each over ``--steps`` steps
from the same state, timed in turn within each of ``--repeats`` repeats. The coupling's cost
is the difference to ``mj_step`` alone, quoted as a ratio to it: of the minimum times, and
the median (and range) of the ratios within each repeat (two times of the same stretch). Build
the extension with ``maturin develop --release`` first (the dev build is several times
slower); the machines are shared and noisy: read the ratios.

**In three dimensions (``--part space-table``, ``--part space-cost``).** A sphere (r 20 mm)
and a capsule (r 10 mm, 60 mm) of density 2500 kg/m^3 dropped at 1 m/s into sand under
``rft3d(zeta=1e6)`` (vertical, the capsule also tilted 30 and 60 degrees and side-on, the
sphere also on a path 30 degrees from vertical) with :func:`granrs.mujoco.body_drop`, against
:func:`granrs.simulate` of the same :class:`granrs.space.Scene`, at MuJoCo timesteps 1e-4,
1e-3, 2e-3, 5e-3 and 1e-2 s and the Euler, implicitfast and RK4 integrators; and the cost of
``Sand`` on gymnasium's Ant (its four ankle capsules as sand geoms, standing in the sand under
``rft3d``, RK4 at its own 0.01 s), at 3, 5 and 6 Gauss nodes per panel (93, 265 and 396
elements per foot), as ratios to ``mj_step`` measured in the same repeats: each call of
``Sand.step`` and of ``mj_step`` timed on its own in one rollout, so that both meet the
states of the Ant in the sand (not ``mj_step`` of an Ant falling onto the floor without the
sand, nor ``Sand.step`` repeated on one state, whose solve then starts converged).

**A Gymnasium rollout (``--part rollout``).** ``Ant-v5`` with seeded random actions, with
:class:`granrs.gym.SandWrapper` and on its rigid floor, timed in turn within each repeat: env
steps per second and their ratio.

**At rest (``--part rest``).** Gymnasium's own hopper (``hopper.xml``, RK4 at 2 ms, no
floor) held upright by a PD controller on its motors, its whole weight on its foot in the
sand (the capsule foot, or a box of 0.39 x 0.1 x 0.06 m in its place), 10 s under each law
(the thesis's, ``rft``, ``rft`` + ``rft_inertial`` and ``poncelet`` in the plane with
``apply_at="centroid"``; ``rft3d``, ``rft3d`` + ``rft3d_inertial`` and ``poncelet`` in space),
with ``Sand.step`` and as the callback. Over the last 5 s: how far the foot moves, the sand's
vertical force's largest step-to-step change and its mean over the load, the largest power
of the sand's generalized force (at the step's mean velocity), the largest rise of its work
over ``max(t, 1 s)`` from the window's start, its net work over the window per second, and
in space how many of the 10 s's steps fell back from the implicit solve (``Sand.fallbacks``;
the foot's landing may, its rest does not).
The work is the sand's own (its generalized force on the model's velocities), not MuJoCo's
energy: the PD controller's motors do work on the hopper. A row passes below 0.1 mm, 5 % of
the load and a rise of 1e-6 J/s.

Usage::

    python benches/bench_mujoco.py [--part all|table|cost|space-table|space-cost|rollout|rest]
                                   [--repeats 15] [--steps 1000]
"""

from __future__ import annotations

import argparse
import time
import warnings

import mujoco
import numpy as np

import granrs
from granrs import forces, space
from granrs.mujoco import WALKER_SAND_GEOMS, Sand, body_drop, rod_drop, walker_mjcf

TIMESTEPS = (1e-4, 1e-3, 2e-3)
RUNS = (("Euler", "step"), ("RK4", "step"), ("RK4", "callback"), ("implicitfast", "step"))


def laws(q_deg: float) -> dict[str, granrs.Scene]:
    """The free-link scenes of each law the core has, at q_deg and v0 = 2 m/s."""
    scenes = {"thesis": granrs.cases.free_link(q_deg=q_deg, v0=2.0)}
    try:
        rft = forces.term("rft", zeta=1e6, elements=64)
    except granrs.GranrsError:
        return scenes  # the core has no rft yet
    scenes["rft(zeta=1e6, elements=64)"] = granrs.cases.free_link(
        q_deg=q_deg, v0=2.0, forces=[forces.gravity(), rft]
    )
    return scenes


def table() -> list[dict[str, object]]:
    rows = []
    print(
        "| law | q [deg] | integrator | coupling | timestep [s] | depth [mm] | simulate "
        "[mm] | error | t_s [ms] | simulate [ms] | error | within 2 % / 5 % |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for q_deg in (0.0, 30.0, 60.0):
        for law, scene in laws(q_deg).items():
            ref = granrs.simulate(scene)
            for integrator, mode in RUNS:
                for h in TIMESTEPS:
                    with warnings.catch_warnings(record=True) as caught:
                        warnings.simplefilter("always")
                        got = rod_drop(scene, timestep=h, integrator=integrator, mode=mode)
                    e_d = got["depth"] / ref.depth - 1.0
                    e_t = got["t_s"] / ref.t_s - 1.0
                    ok = abs(e_d) <= 0.02 and abs(e_t) <= 0.05
                    warned = any(issubclass(w.category, granrs.StepSizeWarning) for w in caught)
                    rows.append(
                        {
                            "law": law,
                            "q_deg": q_deg,
                            "integrator": integrator,
                            "mode": mode,
                            "timestep": h,
                            "depth_error": e_d,
                            "t_s_error": e_t,
                            "ok": ok,
                        }
                    )
                    print(
                        f"| {law} | {q_deg:g} | {integrator} | {mode} | {h:g} | "
                        f"{got['depth'] * 1e3:.2f} | {ref.depth * 1e3:.2f} | {e_d * 100:+.2f} % | "
                        f"{got['t_s'] * 1e3:.2f} | {ref.t_s * 1e3:.2f} | {e_t * 100:+.2f} % | "
                        f"{'yes' if ok else 'no'}{' (StepSizeWarning)' if warned else ''} |"
                    )
    return rows


def cost(repeats: int, steps: int) -> dict[str, float]:
    model = mujoco.MjModel.from_xml_string(walker_mjcf())
    data = mujoco.MjData(model)
    data.qvel[1] = -2.0
    thesis = [forces.drag(), forces.static_h(), forces.static_v()]
    sand = Sand(model, list(WALKER_SAND_GEOMS), thesis)
    for _ in range(round(0.3 / model.opt.timestep)):  # land
        sand.step(data)
        mujoco.mj_step(model, data)
    assert np.all(sand.output[:, 3] > 0.0), "both shanks in the sand"
    start = (data.qpos.copy(), data.qvel.copy(), data.qacc.copy(), data.time)
    base = data.qfrc_applied.copy()

    def restore() -> None:
        data.qpos[:], data.qvel[:], data.qacc[:], data.time = start
        data.qfrc_applied[:] = base

    def alone() -> None:
        for _ in range(steps):
            mujoco.mj_step(model, data)

    def stepped() -> None:
        for _ in range(steps):
            sand.step(data)
            mujoco.mj_step(model, data)

    def callback() -> None:
        for _ in range(steps):
            mujoco.mj_step(model, data)

    best = {"mj_step": np.inf, "Sand.step + mj_step": np.inf, "mj_step, callback": np.inf}
    ratios: dict[str, list[float]] = {"Sand.step + mj_step": [], "mj_step, callback": []}
    for _ in range(repeats):
        this: dict[str, float] = {}
        for name, run in (
            ("mj_step", alone),
            ("Sand.step + mj_step", stepped),
            ("mj_step, callback", callback),
        ):
            restore()
            if name == "mj_step, callback":
                sand.install()
            t = time.perf_counter()
            try:
                run()
            finally:
                if name == "mj_step, callback":
                    sand.uninstall()
            this[name] = (time.perf_counter() - t) / steps
            best[name] = min(best[name], this[name])
        for name, r in ratios.items():
            r.append(this[name] / this["mj_step"] - 1.0)
    step = best["mj_step"]
    print(f"walker, {model.nv} dofs, 2 sand geoms, {steps} steps, {repeats} repeats:")
    print(
        "| run | us per step (min) | coupling's cost [us] | cost / mj_step (of the mins) | "
        "cost / mj_step (median of the repeats, range) |"
    )
    print("|---|---|---|---|---|")
    for name, t in best.items():
        extra = t - step
        if name == "mj_step":
            print(f"| {name} | {t * 1e6:.2f} | | | |")
            continue
        r = np.array(ratios[name])
        print(
            f"| {name} | {t * 1e6:.2f} | {extra * 1e6:.2f} | {extra / step:.2f} | "
            f"{np.median(r):.2f} ({r.min():.2f} to {r.max():.2f}) |"
        )
    return best


def _q_about_y(deg: float) -> tuple[float, float, float, float]:
    a = np.radians(deg) / 2
    return (float(np.cos(a)), 0.0, float(np.sin(a)), 0.0)


def space_table() -> list[dict[str, object]]:
    """Bodies in space dropped in MuJoCo against granrs.simulate."""

    def drop(shape: object, **kw: object) -> space.Scene:
        return space.Scene(
            body=space.Body(shape, density=2500.0),
            forces=[forces.rft3d(zeta=1e6), forces.gravity()],
            **{"velocity": (0.0, 0.0, -1.0), **kw},
        )

    cases = {
        "sphere": drop(space.Sphere(0.02)),
        "sphere, path at 30 deg": drop(space.Sphere(0.02), velocity=(0.5, 0.0, -0.866)),
        "capsule vertical": drop(space.Capsule(0.01, 0.06)),
        "capsule at 30 deg": drop(space.Capsule(0.01, 0.06), orientation=_q_about_y(30)),
        "capsule at 60 deg": drop(space.Capsule(0.01, 0.06), orientation=_q_about_y(60)),
        "capsule side-on": drop(space.Capsule(0.01, 0.06), orientation=_q_about_y(90)),
    }
    rows = []
    print(
        "| body | integrator | timestep [s] | depth / simulate - 1 | t_s / simulate - 1 | "
        "fallback steps | pass (2 %, 5 %) |"
    )
    print("|---|---|---|---|---|---|---|")
    for name, scene in cases.items():
        ref = granrs.simulate(scene)
        for integrator in ("Euler", "implicitfast", "RK4"):
            for h in (1e-4, 1e-3, 2e-3, 5e-3, 1e-2):
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", granrs.StepSizeWarning)
                    d = body_drop(scene, timestep=h, integrator=integrator)
                dd = d["depth"] / ref.depth - 1
                dt = d["t_s"] / ref.t_s - 1
                ok = abs(dd) < 0.02 and abs(dt) < 0.05
                rows.append(
                    {
                        "body": name,
                        "integrator": integrator,
                        "timestep": h,
                        "depth": dd,
                        "t_s": dt,
                        "pass": ok,
                    }
                )
                print(
                    f"| {name} | {integrator} | {h:g} | {dd:+.4f} | {dt:+.4f} | "
                    f"{d['sand'].fallbacks} | {'yes' if ok else 'no'} |"
                )
    return rows


def ant_in_sand(nodes: int) -> tuple[mujoco.MjModel, mujoco.MjData, Sand]:
    """Gymnasium's Ant (its own ant.xml: RK4 at 0.01 s) with its four ankle capsules as sand
    geoms under ``rft3d`` at ``nodes`` Gauss nodes per panel, standing in the sand."""
    import gymnasium

    path = f"{gymnasium.__path__[0]}/envs/mujoco/assets/ant.xml"
    model = mujoco.MjModel.from_xml_path(path)
    for g in ANT_FEET:
        i = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, g)
        model.geom_contype[i] = model.geom_conaffinity[i] = 0
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    sand = Sand(model, ANT_FEET, [forces.rft3d(zeta=space.xi_n(1520.0, 0.4))], quadrature=nodes)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", granrs.StepSizeWarning)
        for _ in range(300):  # stand
            sand.step(data)
            mujoco.mj_step(model, data)
    return model, data, sand


#: The Ant's sand geoms (its four ankle capsules).
ANT_FEET = ["left_ankle_geom", "right_ankle_geom", "third_ankle_geom", "fourth_ankle_geom"]


def space_cost(repeats: int, steps: int) -> None:
    """Sand on gymnasium's Ant standing in the sand, against mj_step.

    Each repeat runs the rollout ``Sand.step`` then ``mj_step`` for ``steps`` steps from the
    same standing state and times each call on its own: both in the states the sand's own
    rollout meets (``mj_step`` without the sand would let the Ant fall onto the floor, whose
    contacts change its cost; ``Sand.step`` repeated on one state would find the last solve's
    twist already converged). Then the same rollout with the Sand as the passive callback
    (inside each of RK4's four stages), timed as a whole against the first's ``mj_step``."""
    print(f"Ant standing in sand under rft3d, {steps} steps, {repeats} repeats:")
    print(
        "| nodes | elements per foot | mj_step [us, min] | Sand.step [us, min] | "
        "Sand.step / mj_step (median of repeats, range) | callback's extra / mj_step | "
        "Newton iterations per step |"
    )
    print("|---|---|---|---|---|---|---|")
    clock = time.perf_counter
    for nodes in (3, 5, 6):
        model, data, sand = ant_in_sand(nodes)
        start = (data.qpos.copy(), data.qvel.copy(), data.qacc.copy(), data.time)
        elements = int(sand.output[0, 1])

        def restore(data: mujoco.MjData = data, start: tuple = start) -> None:
            data.qpos[:], data.qvel[:], data.qacc[:], data.time = start
            data.qfrc_applied[:] = 0.0

        best = {"mj_step": np.inf, "Sand.step": np.inf, "callback": np.inf}
        ratio, extra, iterations = [], [], []
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", granrs.StepSizeWarning)
            for _ in range(repeats):
                this = {"mj_step": 0.0, "Sand.step": 0.0}
                restore()
                newton = 0
                for _ in range(steps):
                    t0 = clock()
                    sand.step(data)
                    t1 = clock()
                    mujoco.mj_step(model, data)
                    t2 = clock()
                    this["Sand.step"] += t1 - t0
                    this["mj_step"] += t2 - t1
                    newton += sand.iterations
                iterations.append(newton / steps)
                restore()
                sand.install()
                try:
                    t = clock()
                    for _ in range(steps):
                        mujoco.mj_step(model, data)
                    this["callback"] = clock() - t
                finally:
                    sand.uninstall()
                for k, v in this.items():
                    best[k] = min(best[k], v / steps)
                ratio.append(this["Sand.step"] / this["mj_step"])
                extra.append(this["callback"] / this["mj_step"] - 1.0)
        r, e = np.array(ratio), np.array(extra)
        print(
            f"| {nodes} | {elements} | {best['mj_step'] * 1e6:.1f} | "
            f"{best['Sand.step'] * 1e6:.1f} | {np.median(r):.2f} ({r.min():.2f} to "
            f"{r.max():.2f}) | {np.median(e):.2f} ({e.min():.2f} to {e.max():.2f}) | "
            f"{np.mean(iterations):.2f} |",
            flush=True,
        )


def rollout(repeats: int, steps: int) -> None:
    """Gymnasium's Ant-v5 with random actions (seeded), with :class:`granrs.gym.SandWrapper`
    and on its rigid floor: env steps per second over ``steps`` steps, the two timed in turn
    within each repeat (reset at the start and whenever an episode ends)."""
    import gymnasium

    from granrs.gym import SandWrapper

    def run(env: gymnasium.Env) -> float:
        env.reset(seed=0)
        env.action_space.seed(0)
        actions = [env.action_space.sample() for _ in range(steps)]
        t = time.perf_counter()
        for a in actions:
            _, _, terminated, truncated, _ = env.step(a)
            if terminated or truncated:
                env.reset()
        return steps / (time.perf_counter() - t)

    rigid = gymnasium.make("Ant-v5")
    sand = SandWrapper(gymnasium.make("Ant-v5"))
    ratios, best = [], {"rigid": 0.0, "sand": 0.0}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", granrs.StepSizeWarning)
        for _ in range(repeats):
            r, s = run(rigid), run(sand)
            best["rigid"], best["sand"] = max(best["rigid"], r), max(best["sand"], s)
            ratios.append(s / r)
    q = np.array(ratios)
    print(f"Ant-v5, random actions, {steps} env steps, {repeats} repeats:")
    print("| rigid floor [steps/s, max] | sand [steps/s, max] | sand / rigid (median, range) |")
    print("|---|---|---|")
    print(
        f"| {best['rigid']:.0f} | {best['sand']:.0f} | {np.median(q):.2f} "
        f"({q.min():.2f} to {q.max():.2f}) |"
    )


#: The laws of ``--part rest``: the Sand's arguments (zeta as the docs' Ant and hopper).
REST_ZETA = space.xi_n(1520.0, 0.4)
REST_PONCELET = {"c": 1.0, "k": 2000.0}


def rest_laws() -> dict[str, dict[str, object]]:
    rft = forces.term("rft", zeta=REST_ZETA)
    return {
        "thesis": {"forces": [forces.drag(), forces.static_h(), forces.static_v()]},
        "rft": {"forces": [rft]},
        "rft + rft_inertial": {"forces": [rft, forces.term("rft_inertial")]},
        "poncelet": {"forces": [forces.poncelet(**REST_PONCELET)]},
        "rft3d": {"forces": [forces.rft3d(zeta=REST_ZETA)]},
        "rft3d + rft3d_inertial": {
            "forces": [forces.rft3d(zeta=REST_ZETA), forces.term("rft3d_inertial")]
        },
        "poncelet in space": {"forces": [forces.poncelet(**REST_PONCELET)], "space": True},
    }


def hopper_model(foot: str) -> mujoco.MjModel:
    """Gymnasium's hopper, no contacts (no floor), its foot a capsule or a box."""
    from granrs.gym import hopper_model as model

    return model(foot)


def hopper_rest(law: str, mode: str, foot: str, seconds: float = 10.0) -> dict[str, float]:
    """One row of ``--part rest``."""
    kw = dict(rest_laws()[law])
    m = hopper_model(foot)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    fid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "foot_geom")
    planar = not kw.get("space") and not any(
        t.name.startswith("rft3d")
        for t in kw["forces"]  # type: ignore[attr-defined]
    )
    if planar:
        kw["apply_at"] = "centroid"
    sand = Sand(m, ["foot_geom"], **kw)  # type: ignore[arg-type]
    q0 = d.qpos[3:6].copy()
    h = m.opt.timestep
    weight = m.body_subtreemass[1] * np.linalg.norm(m.opt.gravity)
    pos, fz, power = [], [], []
    if mode == "callback":
        sand.install()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", granrs.StepSizeWarning)
            for _ in range(round(seconds / h)):
                pd = 200.0 * (q0 - d.qpos[3:6]) - 10.0 * d.qvel[3:6]
                d.ctrl[:] = np.clip(pd, -200, 200) / 200
                if mode == "step":
                    sand.step(d)
                v0 = d.qvel.copy()
                mujoco.mj_step(m, d)
                if not np.all(np.isfinite(d.qpos)):
                    inf = float("inf")
                    keys = ("moved", "spread", "load", "power", "rise", "net", "fallbacks")
                    return dict.fromkeys(keys, inf)
                pos.append(d.geom_xpos[fid].copy())
                fz.append(sand.applied[0, 1 if planar else 2])
                power.append(sand._generalized @ (0.5 * (v0 + d.qvel)))
    finally:
        if mode == "callback":
            sand.uninstall()
    last = slice(-round(5.0 / h), None)
    p, f, w = np.array(pos)[last], np.array(fz)[last], np.array(power)[last]
    work = np.cumsum(w) * h
    work -= work[0]
    elapsed = np.arange(len(work)) * h
    return {
        "moved": float(np.max(np.ptp(p, axis=0))),
        "spread": float(np.max(np.abs(np.diff(f))) / weight),
        "load": float(f.mean() / weight),
        "power": float(w.max()),
        "rise": float(np.max(work / np.maximum(elapsed, 1.0))),
        "net": float(work[-1] / elapsed[-1]),
        "fallbacks": float(sand.fallbacks) if sand.space else float("nan"),
    }


def rest() -> None:
    print(
        "| law | foot | mode | moved [mm] | F_z spread / load | mean F_z / load | "
        "largest power [W] | work's rise [J/s] | net work [J/s] | fallbacks | pass |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for law in rest_laws():
        for foot in ("capsule", "box"):
            for mode in ("step", "callback"):
                r = hopper_rest(law, mode, foot)
                ok = r["moved"] < 1e-4 and r["spread"] < 0.05 and r["rise"] <= 1e-6
                fell = "-" if np.isnan(r["fallbacks"]) else f"{r['fallbacks']:.0f}"
                print(
                    f"| {law} | {foot} | {mode} | {r['moved'] * 1e3:.3g} | {r['spread']:.2g} | "
                    f"{r['load']:.4f} | {r['power']:.2g} | {r['rise']:.2g} | {r['net']:.2g} | "
                    f"{fell} | {'yes' if ok else 'no'} |",
                    flush=True,
                )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument(
        "--part",
        choices=("all", "table", "cost", "space-table", "space-cost", "rollout", "rest"),
        default="all",
    )
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--steps", type=int, default=1000)
    args = parser.parse_args()
    if args.part in ("all", "cost"):
        cost(args.repeats, args.steps)
    if args.part in ("all", "table"):
        table()
    if args.part in ("all", "space-table"):
        space_table()
    if args.part in ("all", "space-cost"):
        space_cost(args.repeats, args.steps)
    if args.part in ("all", "rollout"):
        rollout(args.repeats, args.steps)
    if args.part in ("all", "rest"):
        rest()


if __name__ == "__main__":
    main()
