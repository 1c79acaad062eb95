"""A joint driven along a piecewise-linear table of (time, angle) (issue 19): it follows the
table, each time is a located event where the rates jump by the impulse the run reports, the
work of the reported torque and impulses is the change in energy, and bad tables are refused
naming ``joints.<name>.table`` before any work."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from scipy.integrate import simpson

import granrs
from granrs.bodies import Joint, Link, Linkage, Root
from granrs.errors import GranrsError

# Times off the grid of any step below (each is a located event, not a grid point), a flat
# last segment, and a table that starts before t = 0 (the run starts mid-segment).
TABLE = ((-0.05, 13.0), (0.1234, 47.7), (0.3011, -10.0), (0.4207, 5.0), (0.45, 5.0))
# The angle at t = 0, from the table's definition (linear interpolation).
ANGLE0 = 13.0 + (47.7 - 13.0) * 0.05 / (0.1234 + 0.05)


def _chain(table: tuple[tuple[float, float], ...] = TABLE, **drive: object) -> Linkage:
    """Three links hanging from a pinned root: a free shoulder, the elbow driven, a free
    wrist (gravity only, no contact)."""
    return Linkage(
        [
            Link("upper", 1.0, 0.0075, 0.3, (0.15, 0.0), q_deg=150.0),
            Link("fore", 0.5, 0.002, 0.2, (0.1, 0.0), q_deg=150.0 + ANGLE0),
            Link("hand", 0.2, 4e-4, 0.1, (0.05, 0.0), q_deg=200.0),
        ],
        [
            Joint("elbow", "upper", "fore", (0.3, 0.0), kind="driven", table=table, **drive),  # type: ignore[arg-type]
            Joint("wrist", "fore", "hand", (0.2, 0.0)),
        ],
        root=Root("pinned", link="upper", position=(0.0, 1.0)),
    )


def _scene(body: Linkage, **kw: object) -> granrs.Scene:
    fields: dict[str, object] = {
        "body": body,
        "forces": [granrs.forces.gravity()],
        "end": "time",
        "t_end": 0.5,
        "record": ("state", "energy", "forces"),
    }
    fields.update(kw)
    return granrs.Scene(**fields)  # type: ignore[arg-type]


def _table_angle(t: np.ndarray) -> np.ndarray:
    """The table's angle [rad] at ``t``, held at its ends (np.interp's own rule)."""
    times = [p[0] for p in TABLE]
    return np.interp(t, times, np.radians([p[1] for p in TABLE]))


def _slope(t0: float, t1: float) -> float:
    """The table's slope [rad/s] on the segment that holds (t0, t1)."""
    mid = 0.5 * (t0 + t1)
    times = [p[0] for p in TABLE]
    k = int(np.searchsorted(times, mid, side="right"))
    if k == 0 or k >= len(TABLE):
        return 0.0
    return math.radians(TABLE[k][1] - TABLE[k - 1][1]) / (TABLE[k][0] - TABLE[k - 1][0])


def _segments(t: np.ndarray) -> list[slice]:
    """The recorded samples of each segment: a time of the table is recorded twice (before
    and after its impulse), and splits the series there."""
    cuts = [0, *(np.flatnonzero(np.diff(t) == 0.0) + 1), len(t)]
    return [slice(a, b) for a, b in itertools.pairwise(cuts)]


def test_table_joint_follows_its_table_and_its_work_is_the_change_in_energy() -> None:
    r = granrs.simulate(_scene(_chain()))
    s = r.series
    t = s["t"]
    assert r.status == "end_time"
    # Every time of the table inside the run is recorded, before and after its impulse.
    inside = [p[0] for p in TABLE if 0.0 < p[0] <= 0.5]
    for tk in inside:
        assert np.count_nonzero(t == tk) == 2, tk
    assert np.abs((s["q_fore"] - s["q_upper"]) - _table_angle(t)).max() < 1e-9
    # The impulses: one per time (the last, between two flat segments, is zero).
    assert [i["t"] for i in r.impulses] == inside
    assert all(i["joint"] == "elbow" for i in r.impulses)
    assert abs(r.impulses[-1]["impulse"]) < 1e-12
    # Each impulse is the jump of the joint's rate times the body's inertia it meets: the
    # relative rate before it is the old slope and after it the new one.
    rel = s["omega_fore"] - s["omega_upper"]
    for imp, seg, nxt in zip(r.impulses, _segments(t), _segments(t)[1:], strict=False):
        before, after = rel[seg][-1], rel[nxt][0]
        assert abs(before - _slope(t[seg][0], t[seg][-1])) < 1e-9
        assert abs(after - _slope(t[nxt][0], t[nxt][-1])) < 1e-9
        ke_jump = s["KE"][nxt][0] - s["KE"][seg][-1]
        assert abs(imp["energy"] - ke_jump) < 1e-12 * max(abs(ke_jump), 1e-3)
    # Work of the reported torque: Simpson's rule on each segment, plus the impulses.
    pieces = [
        simpson(s["elbow.torque"][seg] * _slope(t[seg][0], t[seg][-1]), x=t[seg])
        for seg in _segments(t)
        if t[seg][-1] > t[seg][0]
    ]
    impulses = [i["energy"] for i in r.impulses]
    d_e = (s["KE"][-1] + s["PE"][-1]) - (s["KE"][0] + s["PE"][0])
    exchanged = sum(abs(w) for w in pieces + impulses)
    assert exchanged > 0.01  # the drive does work, and its impulses too
    assert min(abs(w) for w in impulses[:-1]) > 1e-3
    assert abs(sum(pieces) + sum(impulses) - d_e) < 1e-8 * exchanged, (pieces, impulses, d_e)
    assert r.joints["elbow"]["impulse_work"] == pytest.approx(sum(impulses), rel=1e-12)
    assert r.joints["wrist"]["impulse_work"] == 0.0


def test_table_joint_converges_at_fourth_order_between_its_times() -> None:
    """The state at 0.5 s (after four times of the table): differences as dt halves fall by
    2^p, p >= 3.7 (RK4: 4; the times are off the grid, each step ends on them)."""
    scene = _scene(_chain(), record=("state",))
    names = [f"{k}_{n}" for k in ("q", "omega") for n in ("upper", "fore", "hand")]

    def final(dt: float) -> np.ndarray:
        s = granrs.simulate(scene.replace(dt=dt)).series
        assert s["t"][-1] == 0.5
        return np.array([s[n][-1] for n in names])

    states = [final(dt) for dt in (1.6e-3, 8e-4, 4e-4, 2e-4)]
    diffs = [np.abs(a - b).max() for a, b in itertools.pairwise(states)]
    orders = [math.log2(a / b) for a, b in itertools.pairwise(diffs)]
    assert min(orders) >= 3.7, f"differences {diffs}, orders {orders}"


def test_a_table_of_equal_slopes_is_the_constant_rate_drive() -> None:
    """A table whose segments all have the slope 3 rad/s, with its times inside the run,
    runs as ``rate=3`` (to round-off: the impulses are zero, the steps end on the times)."""
    rate = 3.0
    times = (0.0, 0.1234, 0.3011, 0.6)
    table = tuple((tk, ANGLE0 + math.degrees(rate * tk)) for tk in times)
    by_table = granrs.simulate(_scene(_chain(table)))
    body = _chain()
    joints = (Joint("elbow", "upper", "fore", (0.3, 0.0), kind="driven", rate=rate),)
    by_rate = granrs.simulate(_scene(Linkage(body.links, joints + body.joints[1:], root=body.root)))
    assert [abs(i["impulse"]) < 1e-15 for i in by_table.impulses] == [True, True]
    a, b = by_table.series, by_rate.series
    # The table's runs has each time twice (before and after its impulse) where the other
    # has the grid point next to it (the grid's 0.12340000000000001 is the table's 0.1234).
    keep = np.concatenate([np.diff(a["t"]) != 0.0, [True]])
    assert np.abs(a["t"][keep] - b["t"]).max() < 1e-15
    for name in ("q_upper", "q_fore", "q_hand", "omega_upper", "omega_fore", "omega_hand"):
        diff = np.abs(a[name][keep] - b[name]).max()
        assert diff < 1e-13, (name, diff)


def test_a_coaxial_pair_takes_the_impulse_of_its_reduced_inertia() -> None:
    """Two links pinned at the same point (the child's joint at the root), so that the mass
    matrix of their angles is diag(I1, I2) with I = I_c + m |c|^2 about the pin. A jump of
    the relative rate by ds takes the impulse P = ds I1 I2 / (I1 + I2): the child's rate
    moves by P / I2, the parent's by -P / I1, and the work is P (s_before + s_after) / 2."""
    m1, i1c, c1 = 2.0, 0.01, (0.1, 0.02)
    m2, i2c, c2 = 0.7, 0.003, (0.15, -0.01)
    i1 = i1c + m1 * (c1[0] ** 2 + c1[1] ** 2)
    i2 = i2c + m2 * (c2[0] ** 2 + c2[1] ** 2)
    table = ((0.0, 30.0), (0.05, 50.0), (0.12, -40.0))
    s0 = math.radians(20.0) / 0.05
    s1 = math.radians(-90.0) / 0.07
    body = Linkage(
        [
            Link("base", m1, i1c, 0.2, c1, q_deg=100.0),
            Link("arm", m2, i2c, 0.3, c2, q_deg=130.0),
        ],
        [Joint("pivot", "base", "arm", (0.0, 0.0), kind="driven", table=table)],
        root=Root("pinned", link="base", position=(0.0, 0.5)),
    )
    r = granrs.simulate(_scene(body, t_end=0.1))
    first = r.impulses[0]
    assert first["t"] == 0.05
    expected = (s1 - s0) * i1 * i2 / (i1 + i2)
    assert abs(first["impulse"] - expected) < 1e-12 * abs(expected), (first, expected)
    s = r.series
    at = np.flatnonzero(s["t"] == 0.05)
    before, after = at
    assert abs((s["omega_arm"][after] - s["omega_arm"][before]) - expected / i2) < 1e-12 * abs(
        expected / i2
    )
    assert abs((s["omega_base"][after] - s["omega_base"][before]) + expected / i1) < 1e-12 * abs(
        expected / i1
    )
    work = expected * (s0 + s1) / 2.0
    assert abs(first["energy"] - work) < 1e-12 * abs(work)


def _bad(table: object, **drive: object) -> Linkage:
    return _chain(table, **drive)  # type: ignore[arg-type]


BAD_TABLES = {
    "one point": ((0.0, ANGLE0),),
    "no point": (),
    "times not increasing": ((0.0, ANGLE0), (0.2, 10.0), (0.1, 20.0)),
    "a repeated time": ((0.0, ANGLE0), (0.2, 10.0), (0.2, 20.0)),
    "an infinite time": ((0.0, ANGLE0), (math.inf, 10.0)),
    "a NaN angle": ((0.0, ANGLE0), (0.2, math.nan)),
    "a row of three": ((0.0, ANGLE0, 1.0), (0.2, 10.0)),
    "a row that is a number": ((0.0, ANGLE0), 0.2),
    "a string entry": ((0.0, ANGLE0), (0.2, "ten")),
    "not a list": "0 0; 1 10",
    "its start is not the initial angle": ((0.0, ANGLE0 + 1.0), (0.2, 10.0)),
}


@pytest.mark.parametrize("table", BAD_TABLES.values(), ids=list(BAD_TABLES))
def test_a_bad_table_is_refused_naming_it(table: object) -> None:
    with pytest.raises(GranrsError) as info:
        _bad(table)
    assert info.value.field == "joints.elbow.table", str(info.value)
    assert isinstance(info.value, ValueError)


@pytest.mark.parametrize(
    "drive",
    [{"rate": 1.0}, {"amplitude_deg": 5.0, "frequency": 1.0}, {"phase_deg": 3.0}],
    ids=["rate", "sinusoid", "phase"],
)
def test_a_table_with_another_drive_is_refused(drive: dict[str, float]) -> None:
    with pytest.raises(GranrsError) as info:
        _bad(TABLE, **drive)
    assert info.value.field == "joints.elbow.table"
    assert next(iter(drive)) in str(info.value)


def test_a_table_on_a_joint_that_is_not_driven_is_refused() -> None:
    body = _chain()
    joint = Joint("elbow", "upper", "fore", (0.3, 0.0), kind="locked", table=TABLE)
    with pytest.raises(GranrsError) as info:
        Linkage(body.links, (joint, body.joints[1]), root=body.root)
    assert info.value.field == "joints.elbow.table"


def test_a_table_round_trips_through_toml_and_a_bad_one_names_its_line() -> None:
    scene = _scene(_chain(), record=())
    text = granrs.scenefile.dumps(scene)
    assert "table = [[" in text
    back = granrs.scenefile.loads(text)
    assert back == scene
    assert granrs.simulate(back).impulses == granrs.simulate(scene).impulses
    line = next(t for t in text.splitlines() if t.startswith("table = "))
    bad = text.replace(line, 'table = [[0.0, 1.0], [0.2, "ten"]]')
    with pytest.raises(GranrsError) as info:
        granrs.scenefile.loads(bad)
    assert info.value.field == "joints.elbow.table"
    number = next(i for i, t in enumerate(bad.splitlines(), 1) if t.startswith("table = "))
    assert f"<string>:{number}:" in str(info.value)


def test_the_adaptive_stepper_lands_on_the_times_too() -> None:
    """With dopri5 the steps end on the table's times as well: the joint follows the table
    to 1e-9 rad and takes the new slope at each time, by the impulse the run reports."""
    scene = _scene(_chain(), method="dopri5", rtol=1e-10, atol=1e-12)
    r = granrs.simulate(scene)
    s = r.series
    t = s["t"]
    assert [i["t"] for i in r.impulses] == [p[0] for p in TABLE if 0.0 < p[0] <= 0.5]
    assert np.abs((s["q_fore"] - s["q_upper"]) - _table_angle(t)).max() < 1e-9
    segments = [seg for seg in _segments(t) if t[seg][-1] > t[seg][0]]
    # (The adaptive steps are long, so Simpson's rule on its samples is not the work to
    # 1e-8: each impulse is checked against the jump of the kinetic energy instead.)
    rel = s["omega_fore"] - s["omega_upper"]
    for imp, seg, nxt in zip(r.impulses, segments, segments[1:], strict=False):
        assert abs(rel[nxt][0] - _slope(t[nxt][0], t[nxt][-1])) < 1e-9
        ke_jump = s["KE"][nxt][0] - s["KE"][seg][-1]
        assert abs(imp["energy"] - ke_jump) < 1e-12 * max(abs(ke_jump), 1e-3)
