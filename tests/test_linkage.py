"""User-defined linkages (issue 19): the built-in bodies as linkages, the thesis's cases
through the linkage path, and a bad linkage refused before any work, naming its element."""

from __future__ import annotations

import json
import math
import pathlib
import sys

import numpy as np
import pytest

import granrs
from granrs import bodies
from granrs.bodies import Contact, Joint, Link, Linkage, Root
from granrs.errors import InvalidParameterError, InvalidSceneError, UnknownNameError

sys.path.insert(0, str(pathlib.Path(__file__).parent))
import itertools

from record_thesis_cases import KEYS, cases, record

RECORD = json.loads((pathlib.Path(__file__).parent / "data" / "thesis_cases.json").read_text())
FLOOR = {"dq": 1e-12, "omega_end": 1e-10, "F_s_end": 1e-12, "F_r_end": 1e-12}
CASES = cases()


@pytest.mark.parametrize(
    "scene",
    [granrs.cases.free_link(q_deg=30, v0=2.0), granrs.cases.chain(case=1), granrs.cases.leg()],
    ids=["free_link", "chain", "leg"],
)
def test_built_in_bodies_are_linkages(scene: granrs.Scene) -> None:
    assert isinstance(scene.body, bodies.Linkage)
    assert scene.body.name == scene.kind
    plain = scene.as_linkage()
    assert plain.kind == "linkage" and plain.body.name == "linkage"
    assert plain.body.links == scene.body.links and plain.body.joints == scene.body.joints


def test_the_built_in_linkage_follows_the_scene_fields() -> None:
    a = granrs.cases.chain(case=1)
    b = a.replace(length=0.2)
    assert a.body != b.body
    assert [link.length for link in b.body.links] == [0.2, 0.2]


@pytest.mark.parametrize(("name", "scene"), CASES, ids=[n for n, _ in CASES])
def test_thesis_case_as_a_plain_linkage(name: str, scene: granrs.Scene) -> None:
    """Each thesis case, its body detached into a plain linkage (links, joints, contacts and
    root as values, run through the linkage path), gives the recorded results to 1e-9."""
    plain = scene.as_linkage()
    assert plain.kind == "linkage"
    got = record(plain)
    want = RECORD[name]
    assert len(got) == len(want)
    for ci, (g, w) in enumerate(zip(got, want, strict=True)):
        for key in KEYS:
            a, b = g[key], w[key]
            if b is None:
                assert a is None, f"{name} contact {ci} {key}: {a}, recorded non-finite"
                continue
            assert a is not None, f"{name} contact {ci} {key}: non-finite, recorded {b}"
            tol = max(1e-9 * max(abs(a), abs(b)), FLOOR.get(key, 0.0))
            assert math.isclose(a, b, rel_tol=0.0, abs_tol=tol), (
                f"{name} contact {ci} {key}: {a!r}, recorded {b!r} (diff {a - b:.3e})"
            )


def _two() -> dict[str, object]:
    return {
        "links": [
            Link("a", mass=1.0, inertia=0.01, length=0.3, com=(0.15, 0.0)),
            Link("b", mass=1.0, inertia=0.01, length=0.3, com=(0.15, 0.0)),
        ],
        "joints": [Joint("j", parent="a", child="b", at=(0.3, 0.0))],
        "contacts": [Contact.rod("b", length=0.3, diameter=0.01)],
        "root": Root("pinned", link="a", position=(0.0, 1.0)),
    }


def _with(**changes: object) -> dict[str, object]:
    body = _two()
    body.update(changes)
    return body


def _link(name: str, **kw: object) -> Link:
    args: dict[str, object] = {"mass": 1.0, "inertia": 0.01, "length": 0.3}
    args.update(kw)
    return Link(name, **args)  # type: ignore[arg-type]


BAD = [
    (
        "unconnected link",
        _with(links=[*_two()["links"], _link("c")]),  # type: ignore[list-item]
        InvalidSceneError,
        "links.c",
    ),
    (
        "joint to an unknown link",
        _with(joints=[Joint("j", parent="a", child="x")]),
        UnknownNameError,
        "joints.j.child",
    ),
    (
        "joint cycle",
        _with(
            links=[*_two()["links"], _link("c")],  # type: ignore[list-item]
            joints=[
                Joint("j", parent="a", child="b"),
                Joint("k", parent="c", child="b"),
                Joint("l", parent="b", child="c"),
            ],
        ),
        InvalidSceneError,
        "joints.k.child",
    ),
    (
        "cycle through the root link",
        _with(joints=[Joint("j", parent="a", child="b"), Joint("k", parent="b", child="a")]),
        InvalidSceneError,
        "joints.k.child",
    ),
    (
        "zero mass",
        _with(links=[_link("a", mass=0.0), _link("b")]),
        InvalidParameterError,
        "links.a.mass",
    ),
    (
        "negative inertia",
        _with(links=[_link("a"), _link("b", inertia=-1.0)]),
        InvalidParameterError,
        "links.b.inertia",
    ),
    (
        "too many links",
        _with(
            links=[_link(f"l{i}") for i in range(bodies.MAX_LINKS + 1)],
            joints=[
                Joint(f"j{i}", parent=f"l{i}", child=f"l{i + 1}") for i in range(bodies.MAX_LINKS)
            ],
            contacts=[],
            root=Root(link="l0"),
        ),
        InvalidParameterError,
        "links",
    ),
    (
        "too many contacts",
        _with(contacts=[Contact.rod("a", 0.3, 0.01)] * (bodies.MAX_CONTACTS + 1)),
        InvalidParameterError,
        "contacts",
    ),
    (
        "contact on an unknown link",
        _with(contacts=[Contact.rod("shin", 0.3, 0.01, name="toe")]),
        UnknownNameError,
        "contacts.toe.link",
    ),
    (
        "driven joint with a non-finite trajectory",
        _with(joints=[Joint("j", parent="a", child="b", kind="driven", rate=math.inf)]),
        InvalidParameterError,
        "joints.j.rate",
    ),
    (
        "driven joint with a NaN trajectory",
        _with(joints=[Joint("j", parent="a", child="b", kind="driven", rate=math.nan)]),
        InvalidParameterError,
        "joints.j.rate",
    ),
    (
        "driven joint with an infinite amplitude",
        _with(joints=[Joint("j", "a", "b", kind="driven", amplitude_deg=math.inf, frequency=1.0)]),
        InvalidParameterError,
        "joints.j.amplitude_deg",
    ),
    (
        "driven joint with a NaN frequency",
        _with(joints=[Joint("j", "a", "b", kind="driven", amplitude_deg=10.0, frequency=math.nan)]),
        InvalidParameterError,
        "joints.j.frequency",
    ),
]


@pytest.mark.parametrize(("what", "body", "error", "field"), BAD, ids=[b[0] for b in BAD])
def test_a_bad_linkage_is_refused_naming_its_element(
    what: str, body: dict[str, object], error: type, field: str
) -> None:
    with pytest.raises(error) as info:
        Linkage(**body)  # type: ignore[arg-type]
    assert info.value.field == field, (what, str(info.value))
    assert isinstance(info.value, granrs.GranrsError) and isinstance(info.value, ValueError)


def test_element_dataclasses_follow_the_core_table() -> None:
    import dataclasses

    for element, cls in (("link", Link), ("joint", Joint), ("contact", Contact), ("root", Root)):
        assert {f.name for f in dataclasses.fields(cls)} == set(bodies.ELEMENT_FIELDS[element])


def test_a_linkage_scene_refuses_the_built_in_bodies_start_fields() -> None:
    with pytest.raises(InvalidSceneError) as info:
        granrs.Scene(body=Linkage(**_two()), v0=2.0)  # type: ignore[arg-type]
    assert info.value.field == "v0"


def test_linkage_scene_round_trips_through_toml() -> None:
    scene = granrs.Scene(
        body=Linkage(**_two()),  # type: ignore[arg-type]
        forces=[granrs.forces.gravity()],
        end="time",
        t_end=0.01,
    )
    text = granrs.scenefile.dumps(scene)
    assert "[[body.links]]" in text and "[body.root]" in text
    back = granrs.scenefile.loads(text)
    assert back == scene
    bad = text.replace("mass = 1.0", "mass = -1.0", 1)
    with pytest.raises(InvalidParameterError) as info:
        granrs.scenefile.loads(bad)
    line = next(i for i, t in enumerate(bad.splitlines(), 1) if t.startswith("mass = -1.0"))
    assert info.value.field == "links.a.mass" and f"<string>:{line}:" in str(info.value)


def test_linkage_results_are_named_by_its_links() -> None:
    scene = granrs.Scene(
        body=Linkage(**_two()),  # type: ignore[arg-type]
        forces=[granrs.forces.gravity()],
        end="time",
        t_end=0.01,
        record=("state", "energy"),
    )
    r = granrs.simulate(scene)
    assert set(r.joints) == {"root", "j"}
    assert {"x_root", "q_a", "q_b", "omega_b", "a.KE", "b.PE"} <= set(r.series)
    # A pinned root does not move.
    assert (r.series["x_root"] == 0.0).all() and (r.series["y_root"] == 1.0).all()


# --- no sand, gravity only ------------------------------------------------------------------

PENDULUM = pathlib.Path(__file__).resolve().parent.parent / "examples" / "scenes"
PENDULUM = PENDULUM / "three_link_pendulum.toml"


def test_three_link_pendulum_conserves_energy() -> None:
    """Free joints, a pinned root, released from rest displaced: over 0.5 s at dt = 1e-4,
    |dE| stays below 1e-6 of the energy exchanged between kinetic and potential."""
    scene = granrs.scenefile.load(PENDULUM)
    assert scene.kind == "linkage" and scene.dt == 1e-4 and scene.t_end == 0.5
    assert all(j.kind == "free" for j in scene.body.joints)
    assert scene.body.root.kind == "pinned" and not scene.body.contacts
    r = granrs.simulate(scene.replace(record=("energy",)))
    assert r.status == "end_time" and r.series["t"][-1] == 0.5
    ke, pe = r.series["KE"], r.series["PE"]
    exchanged = ke.max() - ke.min()
    assert exchanged > 1.0  # it swings
    drift = np.abs((ke + pe) - (ke[0] + pe[0])).max()
    assert drift < 1e-6 * exchanged, f"|dE| = {drift:.3e} J of {exchanged:.3f} J exchanged"


def test_three_link_pendulum_converges_at_fourth_order() -> None:
    """The state at 0.5 s: successive differences as dt halves fall by 2^p, p >= 3.7 (RK4:
    4; the finest pair is kept above round-off)."""
    scene = granrs.scenefile.load(PENDULUM).replace(record=("state",))
    names = [f"{k}_{n}" for k in ("q", "omega") for n in scene.body.order]

    def final(dt: float) -> np.ndarray:
        s = granrs.simulate(scene.replace(dt=dt)).series
        assert s["t"][-1] == 0.5
        return np.array([s[n][-1] for n in names])

    states = [final(dt) for dt in (8e-4, 4e-4, 2e-4, 1e-4)]
    diffs = [np.abs(a - b).max() for a, b in itertools.pairwise(states)]
    orders = [math.log2(a / b) for a, b in itertools.pairwise(diffs)]
    assert min(orders) >= 3.7, f"differences {diffs}, orders {orders}"


DRIVES = {
    "constant rate": {"rate": 3.0},
    "sinusoid": {"rate": 0.5, "amplitude_deg": 30.0, "frequency": 2.0, "phase_deg": 20.0},
}


def _prescribed(drive: dict[str, float], t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The drive's relative angle [rad] and rate [rad/s] at ``t``, from its definition."""
    a = math.radians(drive.get("amplitude_deg", 0.0))
    w = 2.0 * math.pi * drive.get("frequency", 0.0)
    ph = math.radians(drive.get("phase_deg", 0.0))
    angle = math.radians(20.0) + drive["rate"] * t + a * (np.sin(w * t + ph) - math.sin(ph))
    return angle, drive["rate"] + a * w * np.cos(w * t + ph)


@pytest.mark.parametrize("drive", DRIVES.values(), ids=list(DRIVES))
def test_driven_joint_follows_its_angle_and_its_torque_does_the_work(
    drive: dict[str, float],
) -> None:
    """A driven joint (constant rate, or a sinusoid on top) follows its angle to 1e-9 rad,
    and the work of the torque it reports, integrated over the run (Simpson), is the change
    in energy."""
    from scipy.integrate import simpson

    body = Linkage(
        [
            Link("arm", 1.0, 0.0075, 0.3, (0.15, 0.0), q_deg=150.0),
            Link("hand", 0.5, 0.002, 0.2, (0.1, 0.0), q_deg=170.0),
        ],
        [Joint("wrist", "arm", "hand", (0.3, 0.0), kind="driven", **drive)],
        root=Root("pinned", link="arm", position=(0.0, 1.0)),
    )
    scene = granrs.Scene(
        body=body,  # type: ignore[arg-type]
        forces=[granrs.forces.gravity()],
        end="time",
        t_end=0.5,
        record=("state", "energy", "forces"),
    )
    r = granrs.simulate(scene)
    s = r.series
    t = s["t"]
    angle, rate = _prescribed(drive, t)
    assert np.abs((s["q_hand"] - s["q_arm"]) - angle).max() < 1e-9
    work = simpson(s["wrist.torque"] * rate, x=t)
    d_e = (s["KE"][-1] + s["PE"][-1]) - (s["KE"][0] + s["PE"][0])
    assert abs(d_e) > 1e-3  # the drive does work
    assert abs(work - d_e) < 1e-8 * abs(d_e), (work, d_e)
    assert r.joints["wrist"]["torque_max"] == np.abs(s["wrist.torque"]).max()
    if "amplitude_deg" in drive:
        assert np.array_equal(s["clock"], t)


def test_moving_root_keeps_its_velocity() -> None:
    """A root moved at a constant velocity: its position is x0 + v t (to round-off)
    whatever the links do."""
    body = Linkage(
        # A rod runs from its tip along +s: the link's axis points up from the tip.
        [Link("leg", 1.0, 0.0075, 0.3, (-0.15, 0.0), q_deg=-20.0)],
        contacts=[Contact.rod("leg", 0.3, 0.01, at=(-0.3, 0.0))],
        root=Root("moving", link="leg", position=(0.0, 0.3), velocity=(0.5, -0.3)),
    )
    scene = granrs.Scene(body=body, end="time", t_end=0.3, record=("state",))  # type: ignore[arg-type]
    r = granrs.simulate(scene)
    s = r.series
    assert np.abs(s["x_root"] - 0.5 * s["t"]).max() < 1e-12
    assert np.abs(s["y_root"] - (0.3 - 0.3 * s["t"])).max() < 1e-12
    assert r.contacts[0].summary["F_d_max"] > 0.0  # it went into the sand


# --- the sole's corners as located events ----------------------------------------------------

LEG_CASES = {
    "flat, locked": granrs.cases.leg(),
    "heel first, locked": granrs.cases.leg(foot_deg=10.0),
    "heel first, sprung": granrs.cases.leg(joints={"k": 300.0, "c": 5.0}, foot_deg=10.0),
}


@pytest.mark.parametrize("scene", LEG_CASES.values(), ids=list(LEG_CASES))
def test_leg_converges_at_second_order_or_better(scene: granrs.Scene) -> None:
    """The leg's depth and t_s against a run at dt = 2.5e-6: from dt = 8e-4 to 1e-4 the
    error falls by at least 2^(2 * 3) (second order on average over the three halvings), and
    at dt = 1e-4 it is below 1e-9 of the value (it was 2e-4 of it, first order, with the
    sole's corners and its touchdown inside the steps)."""
    ref = granrs.simulate(scene.replace(dt=2.5e-6))
    assert ref.status == "stopped"
    errors = {}
    for dt in (8e-4, 1e-4):
        r = granrs.simulate(scene.replace(dt=dt))
        errors[dt] = (abs(r.depth - ref.depth), abs(r.t_s - ref.t_s))
    for k, name in enumerate(("depth", "t_s")):
        coarse, fine = errors[8e-4][k], errors[1e-4][k]
        assert fine <= 1e-9 * abs((ref.depth, ref.t_s)[k]), (name, errors)
        order = math.log2(coarse / max(fine, 1e-300)) / 3.0
        assert order >= 2.0, f"{name}: errors {coarse:.3e} -> {fine:.3e}, order {order:.2f}"


@pytest.mark.parametrize("term", ["rft", "rft_inertial"])
def test_boundary_terms_act_on_a_linkage_contact(term: str) -> None:
    """The terms that integrate over a contact's boundary act on a linkage's rod, moved
    into the sand by a moving root."""
    body = Linkage(
        [Link("rod", 0.1, 1e-4, 0.1, (-0.05, 0.0), q_deg=30.0)],
        contacts=[Contact.rod("rod", 0.1, 0.01, at=(-0.1, 0.0))],
        root=Root("moving", link="rod", position=(0.0, 0.087), velocity=(0.0, -0.1)),
    )
    params = {"zeta": 1e6} if term == "rft" else {}
    forces = [granrs.forces.gravity(), granrs.forces.term(term, **params)]
    scene = granrs.Scene(body=body, forces=forces, end="time", t_end=0.2, record=("forces",))  # type: ignore[arg-type]
    s = granrs.simulate(scene).series
    columns = [k for k in s if k.startswith("F_")]
    assert columns and max(np.abs(s[k]).max() for k in columns) > 0.0
