"""Speed of bodies in space, as ratios measured in one run.

1. **A force evaluation on a 1280-facet mesh** (an icosphere of radius 50 mm, half sunk,
   moving obliquely and spinning): ``granrs.space.load`` (each facet cut exactly at the
   surface and at its leading edge, three points per facet) against a vectorized NumPy
   implementation of the same law, written here as a user would (one point per facet, at
   its centroid, no cut): what a user of the 3D-RFT public codes does today. One thread.
   Their forces are printed side by side (they differ by the NumPy version's cruder rule).
2. **A whole impact**: a steel ball (radius 20 mm) dropped straight down at 2 m/s on the
   exact sphere, against the thesis's free link at q = 45 deg (Table 3.5 row), each the
   core's own run time (``run_seconds``), minimum of repeats. Straight down without spin
   the sphere's load is taken in closed form (the rule does not enter); the same ball
   thrown obliquely, (0.5, 0, -2) m/s, takes the general cut at 6, 3 and 2 nodes per panel.

3. **Where 3D-RFT does work on a body** (not a speed figure): the share of leading (normal,
   velocity) pairs, uniform on the sphere, where the stress does positive work
   (``alpha . v > 0``), its largest value, and where those pairs are.

The element kernel's own rate (elements per second on one core) is measured by the
criterion bench: ``cargo bench --bench space -- space_kernel``.

    python benches/bench_space.py [--repeats 30]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import granrs
from granrs import forces, space

#: The 3D-RFT coefficient table (rows f1, f2, f3) for the NumPy version: granrs's own.
C = np.array(granrs._granrs.RFT3D_COEFFICIENTS)


def numpy_rft3d(
    vertices: np.ndarray,
    triangles: np.ndarray,
    centre: np.ndarray,
    v: np.ndarray,
    w: np.ndarray,
    zeta: float,
) -> tuple[np.ndarray, np.ndarray]:
    """3D-RFT on a mesh at its facets' centroids, vectorized in NumPy (the vector form of
    the law; a facet counts where its centroid is below z = 0 and it leads)."""
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    cross = np.cross(b - a, c - a)
    area = 0.5 * np.linalg.norm(cross, axis=1)
    n = cross / (2.0 * area[:, None])
    x = (a + b + c) / 3.0
    r = x - centre
    vel = v + np.cross(w, r)
    speed = np.linalg.norm(vel, axis=1)
    vh = vel / speed[:, None]
    depth = -x[:, 2]
    keep = (depth > 0) & (np.einsum("ij,ij->i", n, vh) >= -1e-12)
    m = np.where((n[:, 2] < -1e-12)[:, None], n, -n)
    x1, x2, x3 = -vh[:, 2], np.abs(n[:, 2]), np.einsum("ij,ij->i", m, vh)
    t = np.stack(
        [np.ones_like(x1), x1, x2, x3, x1**2, x2**2, x3**2, x1 * x2, x2 * x3, x3 * x1,
         x1**3, x2**3, x3**3, x1 * x2**2, x2 * x1**2, x2 * x3**2, x3 * x2**2, x3 * x1**2,
         x1 * x3**2, x1 * x2 * x3]
    )  # fmt: skip
    f1, f2, f3 = C @ t
    alpha = f1[:, None] * m + f2[:, None] * vh - f3[:, None] * np.array([0.0, 0.0, 1.0])
    df = (zeta * depth * area * keep)[:, None] * alpha
    return df.sum(axis=0), np.cross(r, df).sum(axis=0)


def best(f, g, repeats: int) -> tuple[float, float]:  # type: ignore[no-untyped-def]
    """The minimum over ``repeats`` of the time of ``f()`` and of ``g()`` [s], taken in
    turn (on a shared machine both see the same spells of load)."""
    tf = tg = float("inf")
    for _ in range(repeats):
        t = time.perf_counter()
        f()
        tf = min(tf, time.perf_counter() - t)
        t = time.perf_counter()
        g()
        tg = min(tg, time.perf_counter() - t)
    return tf, tg


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=30)
    args = ap.parse_args(argv)
    zeta = 1e6
    mesh = space.Mesh.icosphere(0.05, 3)
    assert len(mesh.triangles) == 1280
    centre = np.array([0.0, 0.0, 0.0])
    v, w = np.array([0.3, -0.2, -1.0]), np.array([1.0, 2.0, -0.5])
    scene = space.Scene(
        body=space.Body(mesh, density=1000.0), position=tuple(centre), velocity=tuple(v),
        omega=tuple(w), forces=[forces.rft3d(zeta=zeta)],
    )  # fmt: skip
    ours = space.load(scene, error=False)
    f_np, _ = numpy_rft3d(mesh.vertices, mesh.triangles, centre, v, w, zeta)
    t_ours, t_np = best(
        lambda: space.load(scene, error=False),
        lambda: numpy_rft3d(mesh.vertices, mesh.triangles, centre, v, w, zeta),
        args.repeats,
    )
    print("1. rft3d on a 1280-facet icosphere, half sunk, oblique and spinning (one thread)")
    print(f"   granrs.space.load: {t_ours * 1e6:8.1f} us  ({ours.elements} elements, cut exactly)")
    print(f"   NumPy, vectorized: {t_np * 1e6:8.1f} us  (1280 facets at their centroids)")
    print(f"   NumPy / granrs:    {t_np / t_ours:8.1f}x")
    print(f"   force granrs {np.round(ours.force, 3)} N, NumPy {np.round(f_np, 3)} N")

    ball = space.Body(space.Sphere(radius=0.02), density=7800.0)
    law = [forces.rft3d(zeta=2e5), forces.gravity()]
    free_link = granrs.cases.free_link(q_deg=45, v0=2.27)
    compiled = free_link._compiled()  # the core's own timer, as for the sphere
    t_free = min(granrs._granrs.run(compiled).run_seconds for _ in range(args.repeats))
    print("2. whole impacts (the core's run time, minimum of repeats)")
    print(f"   thesis free link q = 45 deg:        {t_free * 1e6:9.1f} us")
    for name, vx, nodes in (("straight down", 0.0, 6), *(("oblique", 0.5, k) for k in (6, 3, 2))):
        drop = space.Scene(body=ball, velocity=(vx, 0, -2.0), forces=law, quadrature=nodes)
        runs = [granrs.simulate(drop) for _ in range(max(3, args.repeats // 5))]
        t = min(r.run_seconds for r in runs)
        r = runs[0]
        rule = "closed form" if vx == 0.0 else f"rule {nodes}"
        print(
            f"   steel ball {name:>13}, {rule:>11}: {t * 1e6:9.1f} us = "
            f"{t / t_free:6.1f}x the free link (depth {r.depth * 1e3:.5f} mm, "
            f"{r.summary['max_elements']:.0f} elements)"
        )
    non_dissipative()


def non_dissipative(pairs: int = 200_000, seed: int = 0) -> None:
    """Part 3 (see the module's doc)."""
    rng = np.random.default_rng(seed)
    n = rng.normal(size=(pairs, 3))
    n /= np.linalg.norm(n, axis=1)[:, None]
    v = rng.normal(size=(pairs, 3))
    v /= np.linalg.norm(v, axis=1)[:, None]
    lead = np.nonzero(np.einsum("ij,ij->i", n, v) >= 0)[0]
    power = np.array([np.dot(space.rft3d_alpha(n[i], v[i]), v[i]) for i in lead])
    bad = lead[power > 0]
    print("3. where rft3d does positive work (alpha . v > 0), uniform random pairs")
    print(
        f"   {len(bad)} of {len(lead)} leading pairs ({100 * len(bad) / len(lead):.3f} %), "
        f"largest alpha . v = {power.max():+.5f} (a plate pushed down: -0.87574)"
    )
    if len(bad):
        print(
            f"   all with n_z >= {n[bad, 2].min():.3f} (faces looking up) and v_z >= "
            f"{v[bad, 2].min():.3f} (moving up)"
        )


if __name__ == "__main__":
    main()
