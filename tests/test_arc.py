"""Arc contacts (a C-shaped leg) and a root whose angle is driven (issue 19).

The expected values here come from outside the engine: eq. 1 of Li, Zhang & Goldman 2013
(Science 339, 1408) with the generic coefficients (shared/LAWS.md), written out below and
integrated over the exact circle by a fine quadrature; the closed forms of a flat plate;
the mirror symmetry of the law."""

from __future__ import annotations

import itertools
import math
import pathlib
import subprocess
import sys

import numpy as np
import pytest
from rft_paper import alpha_paper as alpha

import granrs
from granrs import bodies, forces
from granrs.bodies import Contact, Link, Linkage, Root
from granrs.errors import InvalidParameterError, InvalidSceneError

SCENES = pathlib.Path(__file__).parent.parent / "examples" / "scenes"
ZETA = 1e6


def arc_leg(
    *,
    radius: float = 0.035,
    start_deg: float = 180.0,
    end_deg: float = 360.0,
    chords: int | None = None,
    q_deg: float = 0.0,
    axle: tuple[float, float] = (0.0, 0.03),
    rate: float = 5.0,
    centre: tuple[float, float] | None = None,
    kind: str = "pinned",
    velocity: tuple[float, float] = (0.0, 0.0),
) -> Linkage:
    """One link on an axle (the root) carrying an arc; by default a C-leg whose end is on
    the axle, turned at `rate`."""
    centre = (radius, 0.0) if centre is None else centre
    return Linkage(
        links=[Link("leg", 0.02, 2e-5, 2 * radius, (radius, 0.0), q_deg=q_deg)],
        contacts=[
            Contact.arc(
                "leg",
                radius=radius,
                start_deg=start_deg,
                end_deg=end_deg,
                width=0.01,
                at=centre,
                chords=chords,
                name="c",
            )
        ],
        root=Root(kind, link="leg", position=axle, velocity=velocity, rate=rate),
    )


def first_force(body: Linkage, terms: list[forces.Term] | None = None) -> np.ndarray:
    """The sand's force on the contact at t = 0 (rft's columns)."""
    terms = [forces.rft(zeta=ZETA)] if terms is None else terms
    scene = granrs.Scene(body=body, forces=terms, end="time", t_end=1e-6, dt=1e-6,
                         record=("forces",))  # fmt: skip
    s = granrs.simulate(scene).series
    return np.array([s["F_rft_x"][0], s["F_rft_y"][0]])


def exact_arc_force(
    radius: float,
    start_deg: float,
    end_deg: float,
    q_deg: float,
    axle: tuple[float, float],
    rate: float,
    n: int = 200_000,
) -> np.ndarray:
    """eq. 1 over the exact circle of `arc_leg` (centre (R, 0) on a link at `q_deg` hung at
    `axle`, turning at `rate`: q grows, a clockwise turn), by the midpoint rule on `n`
    pieces."""
    q = math.radians(q_deg)
    e = np.array([math.sin(q), math.cos(q)])
    nrm = np.array([math.cos(q), -math.sin(q)])
    phi_edges = np.radians(np.linspace(start_deg, end_deg, n + 1))
    phi = 0.5 * (phi_edges[1:] + phi_edges[:-1])
    dphi = phi_edges[1] - phi_edges[0]
    local = np.stack([radius + radius * np.cos(phi), radius * np.sin(phi)])
    p = np.array(axle)[:, None] + local[0] * e[:, None] + local[1] * nrm[:, None]
    tangent = -np.sin(phi) * e[:, None] + np.cos(phi) * nrm[:, None]
    beta = np.arctan2(tangent[1], tangent[0])
    r = p - np.array(axle)[:, None]
    # q grows: the link turns clockwise, omega_ccw = -rate.
    v = -rate * np.stack([-r[1], r[0]])
    gamma = np.arctan2(-v[1], v[0])
    ax, az = alpha(beta, gamma)
    depth = np.maximum(-p[1], 0.0)
    w = ZETA * 0.01 * depth * radius * dphi
    return np.array([np.sum(-ax * w), np.sum(az * w)])


# --- the outline of chords converges to the arc ------------------------------------------


def test_rft_on_a_deep_arc_converges_at_second_order_in_the_chords() -> None:
    """A C-leg wholly under the surface, turning about its axle: the rft force on its chords
    approaches eq. 1 integrated over the exact circle, the error falling 4x per doubling."""
    kw = {"q_deg": 200.0, "axle": (0.0, -0.1), "rate": 3.0}
    exact = exact_arc_force(0.035, 180.0, 360.0, **kw)  # type: ignore[arg-type]
    errors = []
    for chords in (4, 8, 16, 32, 64):
        f = first_force(arc_leg(chords=chords, **kw))  # type: ignore[arg-type]
        errors.append(np.linalg.norm(f - exact) / np.linalg.norm(exact))
    orders = [math.log2(a / b) for a, b in itertools.pairwise(errors)]
    assert all(1.8 < o < 2.2 for o in orders), (errors, orders)
    assert errors[-1] < 1e-3, errors


def test_rft_on_a_partly_immersed_arc_approaches_the_exact_circle() -> None:
    """The same leg crossing the surface (clipped chords): the error falls at second order
    on average over 8 -> 64 chords (a chord's cut by the surface moves from one count to
    the next, so single doublings scatter)."""
    kw = {"q_deg": 150.0, "axle": (0.0, 0.03), "rate": 3.0}
    exact = exact_arc_force(0.035, 180.0, 360.0, **kw)  # type: ignore[arg-type]
    err = {}
    for chords in (8, 64):
        f = first_force(arc_leg(chords=chords, **kw))  # type: ignore[arg-type]
        err[chords] = np.linalg.norm(f - exact) / np.linalg.norm(exact)
    order = math.log2(err[8] / err[64]) / 3
    assert order > 1.7, (err, order)


def test_a_mirrored_arc_feels_the_mirrored_force() -> None:
    """Mirror x -> -x: the link at -q, the arc's angles negated (n flips), the turn reversed,
    the axle mirrored: over a whole turn F_x and the axle's torque change sign, F_y not."""

    def run(sign: float) -> dict[str, np.ndarray]:
        body = arc_leg(
            q_deg=sign * 20.0,
            start_deg=180.0 if sign > 0 else -360.0,
            end_deg=360.0 if sign > 0 else -180.0,
            axle=(sign * 0.01, 0.03),
            rate=sign * 4.0,
            chords=12,
        )
        scene = granrs.Scene(body=body, forces=[forces.gravity(), forces.rft(zeta=ZETA)],
                             end="time", t_end=2 * math.pi / 4.0, dt=2 * math.pi / 4.0 / 720,
                             record=("state", "forces"))  # fmt: skip
        return granrs.simulate(scene).series

    a, b = run(1.0), run(-1.0)
    scale = np.abs(a["F_rft_y"]).max()
    assert scale > 0.5
    assert np.array_equal(a["t"].shape, b["t"].shape)
    assert np.abs(a["F_rft_x"] + b["F_rft_x"]).max() < 1e-9 * scale
    assert np.abs(a["F_rft_y"] - b["F_rft_y"]).max() < 1e-9 * scale
    torque = np.abs(a["root.torque"]).max()
    assert np.abs(a["root.torque"] + b["root.torque"]).max() < 1e-9 * torque


def flat_plate_force(length: float, depth: float, v: tuple[float, float]) -> np.ndarray:
    """eq. 1 on a level plate `length` long, 0.01 m wide, at `depth`, translating at `v`."""
    gamma = math.atan2(-v[1], v[0])
    ax, az = alpha(np.array(0.0), np.array(gamma))
    w = ZETA * 0.01 * depth * length
    return np.array([-float(ax) * w, float(az) * w])


def test_a_large_radius_arc_approaches_a_flat_plate() -> None:
    """A shallow arc (chord 5 cm) of growing radius, level at 2 cm depth, translated down
    and sideways without turning: its rft force approaches the plate's closed form, the
    difference falling as 1/R and below the sag over the depth (the arc's middle is its sag,
    about L^2 / 8R, deeper than its ends: its mean depth about 2/3 of that)."""
    length, depth, v = 0.05, 0.02, (0.6, -1.0)
    plate = flat_plate_force(length, depth, v)
    diffs = []
    for radius in (0.1, 1.0, 10.0):
        half = math.degrees(math.asin(0.5 * length / radius))
        # The link at 90 deg: axis +x, normal -y; phi = 90 deg points down. The centre R
        # above the ends' chord, the chord at `depth`.
        sag = radius * (1 - math.cos(math.radians(half)))
        body = arc_leg(
            radius=radius,
            start_deg=90.0 - half,
            end_deg=90.0 + half,
            chords=64,
            q_deg=90.0,
            centre=(0.0, -(radius - sag)),
            axle=(0.0, -depth),
            kind="moving",
            velocity=v,
            rate=0.0,
        )
        f = first_force(body)
        diffs.append(np.linalg.norm(f - plate) / np.linalg.norm(plate))
        assert diffs[-1] < sag / depth, (radius, diffs[-1], sag / depth)
    assert diffs[1] < diffs[0] / 8 and diffs[2] < diffs[1] / 8, diffs


# --- rate independence of rft, and the inertial term's omega^2 --------------------------

STEPS = 720


def turn(omega: float, terms: list[forces.Term]) -> dict[str, np.ndarray]:
    """One turn of the C-leg at `omega`, sampled at the same leg angles at every speed
    (events add samples of their own, dropped here)."""
    period = 2 * math.pi / omega
    scene = granrs.Scene(body=arc_leg(rate=omega), forces=terms, end="time", t_end=period,
                         dt=period / STEPS, record=("state", "forces"))  # fmt: skip
    s = granrs.simulate(scene).series
    k = np.rint(s["t"] / (period / STEPS))
    on_grid = np.flatnonzero(np.abs(s["t"] - k * period / STEPS) < 1e-9 * period / STEPS)
    # One sample per grid point (an event that lands on one repeats it).
    on_grid = on_grid[np.concatenate([[True], np.diff(k[on_grid]) != 0])]
    out = {name: col[on_grid] for name, col in s.items()}
    assert len(out["t"]) == STEPS + 1
    return out


SPEEDS = (1.0, 5.0, 20.0)


def test_pure_rft_is_rate_independent_over_a_turn() -> None:
    """Lift and thrust against the leg angle: the same curve at 1, 5 and 20 rad/s, to
    round-off."""
    terms = [forces.gravity(), forces.rft(zeta=ZETA)]
    runs = [turn(w, terms) for w in SPEEDS]
    scale = max(np.abs(runs[0]["F_rft_y"]).max(), np.abs(runs[0]["F_rft_x"]).max())
    assert scale > 1.0
    for r in runs[1:]:
        assert np.abs(r["q_leg"] - runs[0]["q_leg"]).max() < 1e-12
        for col in ("F_rft_x", "F_rft_y"):
            assert np.abs(r[col] - runs[0][col]).max() < 1e-11 * scale, col


def test_the_inertial_term_departs_as_omega_squared() -> None:
    """With rft_inertial the faster turns depart from the rate-independent curve, by
    omega^2 times one function of the leg angle (to round-off), while rft's own part is
    unchanged."""
    base = turn(1.0, [forces.gravity(), forces.rft(zeta=ZETA)])
    terms = [forces.gravity(), forces.rft(zeta=ZETA), forces.rft_inertial()]
    runs = {w: turn(w, terms) for w in SPEEDS}
    shapes = []
    for w, r in runs.items():
        scale = np.abs(base["F_rft_y"]).max()
        assert np.abs(r["F_rft_y"] - base["F_rft_y"]).max() < 1e-11 * scale
        lift = r["F_rft_y"] + r["F_ri_y"]
        departure = np.stack([r["F_ri_x"], lift - base["F_rft_y"]])
        shapes.append(departure / w**2)
    ref = np.abs(shapes[0]).max()
    assert ref > 0.0
    for s in shapes[1:]:
        assert np.abs(s - shapes[0]).max() < 1e-9 * ref
    # The fastest turn departs visibly: more than 5 % of the lift at 20 rad/s.
    fast = np.abs(shapes[-1][1] * SPEEDS[-1] ** 2).max()
    assert fast > 0.05 * np.abs(base["F_rft_y"]).max(), fast


# --- the driven root ----------------------------------------------------------------------


def test_a_driven_root_follows_its_rate_and_its_torque_does_the_work() -> None:
    """The leg's angle is q0 + rate t; over a whole turn (the body back where it started)
    the work of the axle's torque is the work the sand took (Simpson, on the fine grid)."""
    from scipy.integrate import simpson

    rate = 5.0
    period = 2 * math.pi / rate
    scene = granrs.Scene(body=arc_leg(rate=rate), forces=[forces.gravity(), forces.rft(zeta=ZETA)],
                         end="time", t_end=period, dt=period / 4000,
                         record=("state", "forces", "energy"))  # fmt: skip
    r = granrs.simulate(scene)
    s = r.series
    assert np.abs(s["q_leg"] - rate * s["t"]).max() < 1e-9
    assert np.abs(s["x_root"]).max() < 1e-15 and np.abs(s["y_root"] - 0.03).max() < 1e-15
    drive = simpson(s["root.torque"] * rate, x=s["t"])
    d_e = (s["KE"][-1] + s["PE"][-1]) - (s["KE"][0] + s["PE"][0])
    taken = -s["work_sand"][-1]
    assert taken > 0.01
    assert abs(drive - (taken + d_e)) < 1e-6 * taken, (drive, taken, d_e)
    assert r.joints["root"]["torque_max"] == np.abs(s["root.torque"]).max()


# --- errors -------------------------------------------------------------------------------


def _contact(**kw: object) -> dict[str, object]:
    base = {"radius": 0.035, "start_deg": 180.0, "end_deg": 360.0, "width": 0.01}
    base.update(kw)
    return base


BAD_ARCS = [
    ("zero radius", _contact(radius=0.0), "contacts.c.radius"),
    ("negative radius", _contact(radius=-0.01), "contacts.c.radius"),
    ("NaN radius", _contact(radius=math.nan), "contacts.c.radius"),
    ("NaN start", _contact(start_deg=math.nan), "contacts.c.start_deg"),
    ("empty span", _contact(end_deg=180.0), "contacts.c.end_deg"),
    ("reversed span", _contact(end_deg=90.0), "contacts.c.end_deg"),
    ("more than a turn", _contact(end_deg=541.0), "contacts.c.end_deg"),
    ("no chord", _contact(chords=0), "contacts.c.chords"),
    ("too many chords", _contact(chords=bodies.MAX_CHORDS + 1), "contacts.c.chords"),
    ("fractional chords", _contact(chords=2.5), "contacts.c.chords"),
    ("zero width", _contact(width=0.0), "contacts.c.width"),
]


@pytest.mark.parametrize(("what", "kw", "field"), BAD_ARCS, ids=[b[0] for b in BAD_ARCS])
def test_a_bad_arc_is_refused_naming_its_field(what: str, kw: dict, field: str) -> None:
    with pytest.raises(InvalidParameterError) as info:
        Linkage(
            links=[Link("leg", 0.02, 2e-5, 0.07)],
            contacts=[Contact.arc("leg", name="c", **kw)],
            root=Root("pinned", link="leg"),
        )
    assert info.value.field == field, (what, str(info.value))


def test_a_full_turn_arc_is_allowed() -> None:
    body = arc_leg(start_deg=0.0, end_deg=360.0, chords=bodies.MAX_CHORDS)
    assert body.contacts[0].chords == bodies.MAX_CHORDS
    # Left out, the chords are DEFAULT_CHORDS (and differ from one more).
    kw = {"q_deg": 150.0}
    default = first_force(arc_leg(**kw))  # type: ignore[arg-type]
    assert np.array_equal(default, first_force(arc_leg(chords=bodies.DEFAULT_CHORDS, **kw)))  # type: ignore[arg-type]
    assert not np.array_equal(default, first_force(arc_leg(chords=bodies.DEFAULT_CHORDS + 1, **kw)))  # type: ignore[arg-type]


@pytest.mark.parametrize("term", ["drag", "static_h", "static_v", "poncelet"])
def test_a_term_not_defined_on_an_arc_is_refused_before_any_work(term: str) -> None:
    extra = {
        "drag": forces.drag(),
        "static_h": forces.static_h(),
        "static_v": forces.static_v(),
        "poncelet": forces.poncelet(c=1.0, k=1.0),
    }[term]
    terms = [forces.rft(zeta=ZETA), extra]
    with pytest.raises(InvalidSceneError) as info:
        granrs.simulate(granrs.Scene(body=arc_leg(), forces=terms, end="time", t_end=0.01))
    assert info.value.field == f"forces.{term}"
    assert "contacts.c" in str(info.value)


@pytest.mark.parametrize("rate", [math.nan, math.inf])
def test_a_non_finite_root_rate_is_refused(rate: float) -> None:
    with pytest.raises(InvalidParameterError) as info:
        arc_leg(rate=rate)
    assert info.value.field == "root.rate"


# --- the scene file -----------------------------------------------------------------------

C_LEG = SCENES / "c_leg_rft.toml"


def test_the_c_leg_scene_round_trips_and_runs_from_the_cli(tmp_path: pathlib.Path) -> None:
    scene = granrs.scenefile.load(C_LEG)
    assert isinstance(scene.body, Linkage) and scene.body.contacts[0].shape == "arc"
    assert scene.body.root.rate is not None
    back = granrs.scenefile.loads(granrs.scenefile.dumps(scene))
    assert back == scene
    granrs_cli = pathlib.Path(sys.executable).parent / "granrs"
    done = subprocess.run(
        [str(granrs_cli), "run", str(C_LEG), "--series", str(tmp_path / "c_leg.csv")],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stderr


def test_the_c_leg_is_drawn() -> None:
    """The animation draws an arc as a thin band through its vertices, its force arrows on."""
    import matplotlib

    matplotlib.use("Agg")

    scene = granrs.scenefile.load(C_LEG).replace(record=("state", "forces"), t_end=0.5)
    anim = granrs.animate(granrs.simulate(scene), frame_dt=0.1)
    band = anim._pose.contacts[0].shape
    # 2 (chords + 1) points a frame, at 0.95 .. 1.05 radii from the centre (3 cm above
    # the axle, at q = 0: the C's centre is (0, 0.03 + 0.035)).
    assert band.shape == (6, 2 * (16 + 1), 2)
    d = np.linalg.norm(band[0] - np.array([0.0, 0.065]), axis=1)
    assert np.allclose(np.sort(d)[[0, -1]], [0.95 * 0.035, 1.05 * 0.035])
