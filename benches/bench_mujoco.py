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
steps per second and their ratio, for each of ``--seeds`` seeds (6). The ratio measures the
Ant's path as much as the sand: random actions throw the Ant about (an episode ends when its
torso leaves 0.2 to 1 m), and a seed whose Ant lies with its feet out of the sand runs
nearly at the rigid floor's speed. So each seed's row also says, from a few more runs of
each (the same seeded paths, their calls timed on their own), on what share of the MuJoCo
steps some foot had elements below the surface (at any RK4 stage), the Sand's time per such
step (its four passive-force calls) and per step out of the sand, MuJoCo's own time per step
with the sand (the Sand's calls taken out, the Python callback's dispatch left in) and on the
rigid floor, and how many resets per 1000 env steps each had (an episode ends when the Ant
is unhealthy or at its 1000th step). The headline is the median over the seeds of the sand
/ rigid ratio, against the line of 0.5. With the defaults (15 repeats of 1000 env steps)
``python benches/bench_mujoco.py --part rollout`` takes about 2.5 minutes on a release
build.

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
                                   [--repeats 15] [--steps 1000] [--seeds 6]
"""

from __future__ import annotations

import argparse
import time
import warnings

import mujoco
import numpy as np

import granrs
from granrs import forces, space
from granrs.mujoco import (
    SPACE_GEOM_OUTPUTS,
    WALKER_SAND_GEOMS,
    Sand,
    body_drop,
    rod_drop,
    walker_mjcf,
)

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


#: The column of ``Sand.output`` that counts a geom's surface elements below the sand.
_ELEMENTS = SPACE_GEOM_OUTPUTS.index("elements")


def sand_steps(calls: list[tuple[int, bool, float]]) -> tuple[int, int, float, float]:
    """MuJoCo steps from the Sand's passive-force calls, in order, each ``(stage, in_sand,
    seconds)``: the call's RK4 stage (1 to 4; each step starts with a stage 1), whether some
    geom had elements below the surface after it, and the call's time.

    Returns the number of steps, how many had a geom in the sand at any of their stages, and
    the Sand's time summed over those steps' calls and over the other steps' calls."""
    steps: list[list] = []  # [in the sand, seconds] of each MuJoCo step
    for stage, inside, seconds in calls:
        if stage == 1:
            steps.append([False, 0.0])
        elif not steps:
            raise ValueError(f"the first call is at RK4 stage {stage}, not a step's first")
        steps[-1][0] = steps[-1][0] or inside
        steps[-1][1] += seconds
    sand = [seconds for inside, seconds in steps if inside]
    out = [seconds for inside, seconds in steps if not inside]
    return len(steps), len(sand), float(sum(sand)), float(sum(out))


def rollout_medians(rows: list[dict[str, float]]) -> dict[str, float]:
    """The median over seeds of each column of the per-seed rows (each seed's sand / rigid
    ratio is itself the median of its repeats)."""
    return {k: float(np.median([row[k] for row in rows])) for k in rows[0]}


#: The columns of ``--part rollout``'s table: (key, header, format).
ROLLOUT_COLUMNS = (
    ("ratio", "sand / rigid (median of repeats)", "{:.2f}"),
    ("rigid", "rigid floor [env steps/s, median]", "{:.0f}"),
    ("share", "MuJoCo steps with a foot in the sand", "{:.0%}"),
    ("sand_us", "Sand per such step [us]", "{:.0f}"),
    ("out_us", "Sand per step out of the sand [us]", "{:.1f}"),
    ("mj_us", "mj_step, sand env [us]", "{:.1f}"),
    ("rigid_us", "mj_step, rigid floor [us]", "{:.1f}"),
    ("resets", "resets per 1000 env steps, sand (rigid)", "{:.1f}"),
)


def rollout(repeats: int, steps: int, seeds: int) -> dict[str, float]:
    """Gymnasium's Ant-v5 with random actions, with :class:`granrs.gym.SandWrapper` and on
    its rigid floor, for seeds 0 to ``seeds - 1`` (the environment's reset and its action
    space seeded alike): env steps per second over ``steps`` steps, the two timed in turn
    within each repeat (reset at the start and whenever an episode ends). Then ``repeats //
    5`` more runs of each (at least one; the medians of their times), the same seeded paths
    with the calls timed on their own (the timed runs are bare): the Sand's passive-force
    callback (its RK4 stage, and whether a foot has elements below the surface after it) and
    MuJoCo's step (``_step_mujoco_simulation`` less the Sand's calls in it, per step of
    ``frame_skip``). Prints a row per seed and the medians over seeds; returns the medians."""
    import gymnasium

    from granrs.gym import SandWrapper

    def actions(env: gymnasium.Env, seed: int) -> list:
        env.reset(seed=seed)
        env.action_space.seed(seed)
        return [env.action_space.sample() for _ in range(steps)]

    def run(env: gymnasium.Env, seed: int) -> tuple[float, int]:
        todo, resets = actions(env, seed), 0
        t = time.perf_counter()
        for a in todo:
            _, _, terminated, truncated, _ = env.step(a)
            if terminated or truncated:
                env.reset()
                resets += 1
        return steps / (time.perf_counter() - t), resets

    def trace(env: gymnasium.Env, seed: int) -> tuple[float, int, int, float, float, int]:
        """MuJoCo's time per step [s], and sand_steps() of the run (zeros on the rigid
        floor), and the resets."""
        clock = time.perf_counter
        inner = env.unwrapped
        calls: list[tuple[int, bool, float]] = []
        sand = env.sand if isinstance(env, SandWrapper) else None
        simulate = inner._step_mujoco_simulation
        mujoco_time, tracing = [0.0], [0.0]

        def timed_simulation(ctrl: object, n_frames: int) -> None:
            before, traced = len(calls), tracing[0]
            t = clock()
            simulate(ctrl, n_frames)
            dt = clock() - t - (tracing[0] - traced)
            mujoco_time[0] += dt - sum(c[2] for c in calls[before:])

        todo, resets = actions(env, seed), 0
        inner._step_mujoco_simulation = timed_simulation
        if sand is not None:
            callback = sand._callback

            def timed_callback(m: mujoco.MjModel, d: mujoco.MjData) -> None:
                t0 = clock()
                callback(m, d)
                t1 = clock()
                stage = sand._stage[0] if sand._rk4 else 1
                calls.append((stage, bool(np.any(sand.output[:, _ELEMENTS] > 0)), t1 - t0))
                tracing[0] += clock() - t1  # this trace's own time, neither MuJoCo's nor sand's

            calls.clear()
            sand._callback = timed_callback
        try:
            for a in todo:
                _, _, terminated, truncated, _ = env.step(a)
                if terminated or truncated:
                    during_step = len(calls)
                    env.reset()  # its mj_forward calls the Sand once: not a step's
                    del calls[during_step:]
                    resets += 1
        finally:
            del inner._step_mujoco_simulation
            if sand is not None:
                del sand._callback
        n_mj = steps * inner.frame_skip
        return (mujoco_time[0] / n_mj, *sand_steps(calls), resets)

    rigid = gymnasium.make("Ant-v5")
    sand = SandWrapper(gymnasium.make("Ant-v5"))
    traces = max(1, repeats // 5)
    print(f"Ant-v5, random actions, {steps} env steps, {repeats} repeats, seeds 0 to {seeds - 1}:")
    headers = ["seed", *(h for _, h, _ in ROLLOUT_COLUMNS)]
    print("| " + " | ".join(headers) + " |")
    print("|---" * len(headers) + "|")
    rows = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", granrs.StepSizeWarning)
        for seed in range(seeds):
            ratios, speeds, resets = [], [], set()
            for _ in range(repeats):
                (r, r_resets), (s, s_resets) = run(rigid, seed), run(sand, seed)
                ratios.append(s / r)
                speeds.append(r)
                resets.add((r_resets, s_resets))
            assert len(resets) == 1, "a seed's path is the same in every repeat"
            # The traces' times: the median of a few (one run's move with the machine's load).
            rigids = [trace(rigid, seed) for _ in range(traces)]
            rigid_us, rigid_resets = float(np.median([t[0] for t in rigids])), rigids[0][-1]
            sands = [trace(sand, seed) for _ in range(traces)]
            mj_us, sand_s, out_s = (float(np.median([t[k] for t in sands])) for k in (0, 3, 4))
            _, n, in_sand, _, _, sand_resets = sands[0]
            assert all(t[1:3] == (n, in_sand) and t[5] == sand_resets for t in sands)
            assert (rigid_resets, sand_resets) in resets, "the traced runs follow the timed paths"
            assert n == steps * sand.unwrapped.frame_skip, "every MuJoCo step's calls traced"
            rows.append(
                {
                    "ratio": float(np.median(ratios)),
                    "rigid": float(np.median(speeds)),
                    "share": in_sand / n,
                    "sand_us": sand_s / in_sand * 1e6 if in_sand else float("nan"),
                    "out_us": out_s / (n - in_sand) * 1e6 if n > in_sand else float("nan"),
                    "mj_us": mj_us * 1e6,
                    "rigid_us": rigid_us * 1e6,
                    "resets": sand_resets * 1000 / steps,
                    "rigid_resets": rigid_resets * 1000 / steps,
                }
            )
            print(_rollout_row(str(seed), rows[-1]), flush=True)
    medians = rollout_medians(rows)
    print(_rollout_row("median", medians))
    print(f"sand / rigid, the median over seeds: {medians['ratio']:.2f} (the line: >= 0.5)")
    return medians


def _rollout_row(label: str, row: dict[str, float]) -> str:
    cells = {k: f.format(row[k]) for k, _, f in ROLLOUT_COLUMNS}
    cells["resets"] += " ({:.1f})".format(row["rigid_resets"])
    return f"| {label} | " + " | ".join(cells.values()) + " |"


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
    parser.add_argument("--seeds", type=int, default=6, help="--part rollout's seeds")
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
        rollout(args.repeats, args.steps, args.seeds)
    if args.part in ("all", "rest"):
        rest()


if __name__ == "__main__":
    main()
