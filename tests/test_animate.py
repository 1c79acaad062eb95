"""``granrs.animate`` (``granrs.animation``) and ``granrs animate`` (issue 20: an impact you
can watch; issue 33: any linkage, any law): frame count and times, frames that change, the
body and the arrows where the recorded numbers put them, typed errors before anything is
drawn, the CLI writing a GIF per example scene, and ``Result._repr_html_``.

Expected positions and forces come from the recorded series (the core's own ``tip_x``,
``tip_y``, ``depth``, ``v_E_x`` ... columns), never from the drawing code.
"""

from __future__ import annotations

import importlib
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import matplotlib
import numpy as np
import pytest
from matplotlib import animation as mpl_animation
from matplotlib.backends.backend_agg import FigureCanvasAgg
from PIL import Image

import granrs
from granrs import animation, cases, forces
from granrs._animation import ImpactAnimation
from granrs.animation import DEFAULT_FRAMES, MAX_FRAMES, check_output, frame_count, playback
from granrs.bodies import Contact, Joint, Link, Linkage, Root
from granrs.cli import main
from granrs.errors import AnimationSizeWarning, GranrsError, InvalidParameterError
from granrs.forces import select, thesis

# The drawing module (it imports matplotlib; granrs.animate, the attribute, is the function).
drawing = importlib.import_module("granrs._animation")
EXAMPLES = sorted((Path(__file__).resolve().parents[1] / "examples" / "scenes").glob("*.toml"))
RECORD = ("state", "forces")


def run(scene: granrs.Scene, record: tuple[str, ...] = RECORD) -> granrs.Result:
    return granrs.simulate(scene.replace(record=record))


@pytest.fixture(scope="module")
def free_link() -> granrs.Result:
    return run(cases.free_link(q_deg=45.0, v0=2.27))


@pytest.fixture(scope="module")
def chain() -> granrs.Result:
    return run(cases.chain(case=1))


@pytest.fixture(scope="module")
def leg() -> granrs.Result:
    return run(cases.leg(v0=3.28))


def rgba(anim: ImpactAnimation, k: int) -> np.ndarray:
    """Frame ``k`` rendered with the Agg canvas, as an (h, w, 4) array."""
    anim.draw(k)
    canvas = anim.figure.canvas
    assert isinstance(canvas, FigureCanvasAgg)
    canvas.draw()
    return np.asarray(canvas.buffer_rgba()).copy()


# --- frames ---------------------------------------------------------------------------------


@pytest.mark.parametrize("frame_dt", [0.001, 0.0025, 0.004, 0.007, 0.02, 1.0])
def test_frame_count_is_floor_of_span_over_frame_dt_plus_one(
    free_link: granrs.Result, frame_dt: float
) -> None:
    """Issue 20: one frame per frame_dt of simulated time, floor(t_end / frame_dt) + 1."""
    assert free_link.series is not None
    t_end = float(free_link.series["t"][-1])  # 0.02567... s: no quotient is whole here
    anim = granrs.animate(free_link, frame_dt=frame_dt)
    assert anim.n_frames == math.floor(t_end / frame_dt) + 1
    assert anim.frame_times[0] == 0.0
    np.testing.assert_allclose(np.diff(anim.frame_times), frame_dt, rtol=1e-12)
    assert anim.frame_times[-1] <= t_end


def test_frame_count_counts_a_whole_quotient_despite_round_off() -> None:
    """0.3 / 0.1 is 2.9999999999999996 in floating point; the run of 0.3 s has frames at
    0, 0.1, 0.2 and 0.3 s: 4 frames, not 3."""
    result = run(cases.free_link(q_deg=45.0, v0=2.27).replace(end="time", t_end=0.3))
    assert result.series is not None
    assert math.isclose(result.series["t"][-1], 0.3, rel_tol=1e-12)
    anim = granrs.animate(result, frame_dt=0.1)
    assert anim.n_frames == 4
    np.testing.assert_allclose(anim.frame_times, [0.0, 0.1, 0.2, 0.3], rtol=1e-12)
    assert frame_count(0.3, 0.1) == 4
    assert frame_count(0.0299, 0.01) == 3


def test_first_and_last_frames_differ(free_link: granrs.Result) -> None:
    """The picture moves: frame 0 (at the surface) and the last (at the stop) differ, while
    frame 0 drawn again is the same picture (so the difference is the frame's)."""
    anim = granrs.animate(free_link, frame_dt=0.005)
    first = rgba(anim, 0)
    last = rgba(anim, anim.n_frames - 1)
    again = rgba(anim, 0)
    assert first.shape == last.shape
    changed = np.any(first != last, axis=-1).mean()
    assert changed > 0.005, changed
    np.testing.assert_array_equal(first, again)


def test_animate_is_the_animation_module_s_function(free_link: granrs.Result) -> None:
    """granrs.animate (loaded with matplotlib on first use) returns a FuncAnimation; a
    Result has no animate method (result.py does not import the animation: no import
    cycle)."""
    assert granrs.animate is drawing.animate
    anim = granrs.animate(free_link, frame_dt=0.005)
    assert isinstance(anim, mpl_animation.FuncAnimation)
    assert anim.result is free_link
    assert "animate" in granrs.__all__ and "animation" in granrs.__all__
    assert not hasattr(free_link, "animate")


def test_animation_shows_inline_as_a_javascript_player(free_link: granrs.Result) -> None:
    """Jupyter: _repr_html_ gives the JavaScript player with one embedded image per frame."""
    anim = granrs.animate(free_link, frame_dt=0.01)
    html = anim._repr_html_()
    assert "<script" in html
    assert html.count("data:image/png;base64") == anim.n_frames == 3


# --- the picture follows the numbers --------------------------------------------------------


@pytest.mark.parametrize("body", ["free_link", "chain", "leg"])
def test_drawn_contacts_are_at_the_recorded_tips(
    body: str, free_link: granrs.Result, chain: granrs.Result, leg: granrs.Result
) -> None:
    """Each contact's reference point placed from the recorded coordinates and the scene's
    geometry (rod tip, middle of the sole) is where the core recorded it, and the depth shown
    is the recorded depth. frame_dt is a multiple of dt, so every frame is a recorded sample."""
    result = {"free_link": free_link, "chain": chain, "leg": leg}[body]
    series = result.series
    assert series is not None
    anim = granrs.animate(result, frame_dt=0.002)
    rows = np.searchsorted(series["t"], anim.frame_times - 1e-12)
    np.testing.assert_allclose(series["t"][rows], anim.frame_times, atol=1e-12)
    n = len(result.contacts)
    assert len(anim._pose.contacts) == n
    for i, contact in enumerate(anim._pose.contacts):
        prefix = f"c{i}." if n > 1 else ""
        np.testing.assert_allclose(
            contact.reference[:, 0], series[f"{prefix}tip_x"][rows], atol=1e-12
        )
        np.testing.assert_allclose(
            contact.reference[:, 1], series[f"{prefix}tip_y"][rows], atol=1e-12
        )
        np.testing.assert_allclose(anim.depths[:, i], series[f"{prefix}depth"][rows], atol=1e-12)
    anim.draw(anim.n_frames - 1)
    for i in range(n):
        text = anim._depth_text.get_text()
        prefix = f"c{i}." if n > 1 else ""
        assert f"{series[f'{prefix}depth'][rows[-1]] * 1e3:.1f} mm" in text


def test_force_arrows_end_where_the_recorded_force_says(chain: granrs.Result) -> None:
    """The sum's arrow runs from the tip to tip + scale * (F_dx + F_sh, F_dy + F_sv), and
    the terms laid tip to tail end at the same point."""
    series = chain.series
    assert series is not None
    anim = granrs.animate(chain, frame_dt=0.001)
    k = anim.n_frames // 2
    row = int(np.searchsorted(series["t"], anim.frame_times[k] - 1e-12))
    anim.draw(k)
    scale = anim.force_scale
    assert scale > 0.0
    for i, arrows in enumerate(anim._views[0].arrows):
        p = f"c{i}."
        tip = np.array([series[p + "tip_x"][row], series[p + "tip_y"][row]])
        force = np.array(
            [
                series[p + "F_dx"][row] + series[p + "F_sh"][row],
                series[p + "F_dy"][row] + series[p + "F_sv"][row],
            ]
        )
        assert np.hypot(*force) > 0.1  # both links are in the sand by mid-run
        start, end = (np.array(xy) * 1e-3 for xy in arrows["total"]._posA_posB)
        np.testing.assert_allclose(start, tip, atol=1e-9)
        np.testing.assert_allclose(end, tip + scale * force, atol=1e-9)
        last_term_end = np.array(arrows["static_v"]._posA_posB[1]) * 1e-3
        np.testing.assert_allclose(last_term_end, tip + scale * force, atol=1e-9)
        drag_end = np.array(arrows["drag"]._posA_posB[1]) * 1e-3
        drag = np.array([series[p + "F_dx"][row], series[p + "F_dy"][row]])
        np.testing.assert_allclose(drag_end, tip + scale * drag, atol=1e-9)


def test_centroid_forces_start_at_the_body_point_moving_at_v_E() -> None:
    """apply_at="centroid": the arrows start at the immersed centroid E, the body point whose
    velocity the core records as v_E (v_centre + omega * s * n for the rod)."""
    result = run(cases.free_link(q_deg=30.0, v0=2.0).replace(apply_at="centroid"))
    series = result.series
    assert series is not None
    anim = granrs.animate(result, frame_dt=0.002)
    rows = np.searchsorted(series["t"], anim.frame_times - 1e-12)
    e_point = anim._pose.contacts[0].applied
    centre = np.stack([series["x"][rows], series["y"][rows]], axis=-1)
    q, omega = series["q"][rows], series["omega"][rows]
    axis = np.stack([np.sin(q), np.cos(q)], axis=-1)
    s = np.einsum("ij,ij->i", e_point - centre, axis)  # E's place along the rod
    normal = np.stack([np.cos(q), -np.sin(q)], axis=-1)
    v_point = (
        np.stack([series["vx"][rows], series["vy"][rows]], axis=-1) + (omega * s)[:, None] * normal
    )
    immersed = series["depth"][rows] > 0.0
    assert immersed.sum() > 5
    np.testing.assert_allclose(v_point[immersed, 0], series["v_E_x"][rows][immersed], atol=1e-9)
    np.testing.assert_allclose(v_point[immersed, 1], series["v_E_y"][rows][immersed], atol=1e-9)
    # E lies on the rod's axis, between the tip and the surface.
    assert np.all(s[immersed] >= -0.5 * result.scene.length - 1e-12)
    assert np.all(e_point[immersed, 1] <= 1e-12)


def test_state_without_forces_draws_the_body_without_arrows() -> None:
    """record=("state",): the body moves, no arrow, and the legend says why."""
    result = run(cases.free_link(q_deg=45.0, v0=2.27), record=("state",))
    anim = granrs.animate(result, frame_dt=0.005)
    assert anim.force_scale == 0.0
    assert all(not arrows for arrows in anim._views[0].arrows)
    legend = anim.figure.legends[0]
    assert legend.get_title().get_text() == "forces not recorded"


def test_only_the_scene_s_terms_get_arrows() -> None:
    """A vertical drop with gravity and static_v only records no drag and no static_h: one
    term arrow (static_v) and the sum."""
    scene = cases.free_link(q_deg=0.0, v0=1.0).replace(
        forces=select(thesis(), *("gravity", "static_v"))
    )
    anim = granrs.animate(run(scene), frame_dt=0.005)
    assert set(anim._views[0].arrows[0]) == {"static_v", "total"}
    labels = [t.get_text() for t in anim.figure.legends[0].get_texts()]
    assert "static_v" in labels and "drag" not in labels


# --- any linkage, any law (issue 33) -------------------------------------------------------

#: Each segment of the two-segment leg [m].
SEGMENT = 0.3


def _segment(name: str, q_deg: float) -> Link:
    """A segment built as docs/bodies/linkage.md builds links: "a rod runs from its tip along
    +s", so the axis points up from the segment's lower end, at (-L, 0) from its joint."""
    return Link(name, mass=1.0, inertia=0.01, length=SEGMENT, com=(-SEGMENT / 2, 0.0), q_deg=q_deg)


def two_segment_leg(t_end: float = 1.0) -> granrs.Result:
    """A thigh and a shank hanging below a pelvis carried along at constant velocity: the
    hip driven at 2 Hz, the knee a spring, a rod foot at the shank's lower end."""
    leg = Linkage(
        links=[_segment("pelvis", 90.0), _segment("thigh", 10.0), _segment("shank", -15.0)],
        joints=[
            Joint(
                "hip",
                parent="pelvis",
                child="thigh",
                at=(-SEGMENT / 2, 0.0),
                kind="driven",
                amplitude_deg=20.0,
                frequency=2.0,
            ),
            Joint(
                "knee",
                parent="thigh",
                child="shank",
                at=(-SEGMENT, 0.0),
                kind="spring",
                k=20.0,
                c=0.1,
            ),
        ],
        contacts=[
            Contact.rod("shank", length=SEGMENT, diameter=0.02, at=(-SEGMENT, 0.0), name="foot")
        ],
        root=Root("moving", link="pelvis", position=(0.0, 0.6), velocity=(0.2, -0.05), rate=0.0),
    )
    scene = granrs.Scene(
        body=leg,
        forces=[forces.gravity(), forces.joint_springs(), forces.rft(zeta=1e6)],
        end="time",
        t_end=t_end,
    )
    return run(scene)


def _on_segment(point: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    """Distance [m] from ``point`` to the segment ``a``-``b``."""
    ab = b - a
    t = np.clip(np.dot(point - a, ab) / np.dot(ab, ab), 0.0, 1.0)
    return float(np.hypot(*(a + t * ab - point)))


def test_two_segment_leg_is_drawn_attached_at_its_joints() -> None:
    """Issue 33: the two-segment leg of docs/bodies (hip driven at 2 Hz, knee spring, foot
    contact) was drawn with each link from its joint along +s over [0, L], i.e. pointing up
    and away from the joint it hangs from, and disconnected. Each drawn bar (the line's end
    points, in mm) must now start at the joint that carries its link and pass through the
    joints it carries, and the shank's bar must end at the foot's tip the core recorded
    (tip_x, tip_y). The joints are placed here from the recorded root and angles by the docs'
    convention (axis (sin q, cos q), normal (cos q, -sin q)), not by the drawing code."""
    result = two_segment_leg()
    series = result.series
    assert series is not None
    anim = granrs.animate(result, frame_dt=0.01)
    rows = np.searchsorted(series["t"], anim.frame_times - 1e-12)
    assert series["depth"][rows].max() > 0.01  # the foot goes into the sand

    def axis(q: float) -> np.ndarray:
        return np.array([math.sin(q), math.cos(q)])

    bars = anim._views[0].links
    for k in range(0, anim.n_frames, 7):
        anim.draw(k)
        row = rows[k]
        root = np.array([series["x_root"][row], series["y_root"][row]])
        hip = root - SEGMENT / 2 * axis(series["q_pelvis"][row])
        knee = hip - SEGMENT * axis(series["q_thigh"][row])
        tip = np.array([series["tip_x"][row], series["tip_y"][row]])
        np.testing.assert_allclose(knee - SEGMENT * axis(series["q_shank"][row]), tip, atol=1e-9)
        drawn = {name: line.get_xydata() * 1e-3 for name, line in bars.items()}
        carried_by = {"pelvis": root, "thigh": hip, "shank": knee}
        carries = {"pelvis": [hip], "thigh": [knee], "shank": [tip]}
        for name, (a, b) in drawn.items():
            # The bar runs from the joint that carries the link ...
            assert min(np.hypot(*(a - carried_by[name])), np.hypot(*(b - carried_by[name]))) < 1e-9
            # ... and through every joint it carries (the shank: to the foot's tip).
            for point in carries[name]:
                assert _on_segment(point, a, b) < 1e-9, (name, k)
        assert min(np.hypot(*(end - tip)) for end in drawn["shank"]) < 1e-9  # an end, the tip
        joints = anim._views[0].joints.get_xydata() * 1e-3
        for point in (root, hip, knee):
            assert np.min(np.hypot(*(joints - point).T)) < 1e-9


def test_a_link_spans_its_own_geometry() -> None:
    """Each link's bar covers what the link defines along its axis, at least its length:
    hanging below its joint (the docs' rods, joints at (-L, 0)), rising from it (the leg's
    segments), about its centre of mass (the free link, a bare rod). Before, every bar ran
    over [0, L] from the joint, whatever the link's geometry."""
    length = 0.4
    hanging = Link("a", 1.0, 0.01, length, com=(-length / 2, 0.0))
    below = Joint("j", "a", "b", at=(-length, 0.0))
    assert drawing._link_span(hanging, [below], []) == (-length, 0.0)
    assert drawing._link_span(hanging, [], []) == (-length, 0.0)
    rising = Link("b", 1.0, 0.01, length, com=(0.3 * length, 0.0))
    assert drawing._link_span(rising, [], []) == (0.0, length)
    bare = Link("c", 1.0, 0.01, length)
    assert drawing._link_span(bare, [], []) == (-length / 2, length / 2)
    rod = Contact.rod("c", length=length, diameter=0.01, at=(-length / 2, 0.0))
    assert drawing._link_span(bare, [], [rod]) == (-length / 2, length / 2)
    longer = Contact.rod("c", length=2 * length, diameter=0.01, at=(-0.5 * length, 0.0))
    assert drawing._link_span(bare, [], [longer]) == (-0.5 * length, 1.5 * length)
    c_leg = Contact.arc("c", radius=0.1, start_deg=180.0, end_deg=360.0, width=0.01, at=(0.1, 0))
    lo, hi = drawing._link_span(Link("c", 1.0, 0.01, 0.2, com=(0.1, -0.06)), [], [c_leg])
    assert (lo, hi) == pytest.approx((0.0, 0.2), abs=1e-15)


def test_a_joint_off_the_axis_gets_a_spoke() -> None:
    """A joint at (s, n) with n != 0 is joined to its parent's axis by a spoke from (s, 0),
    so that the child's bar still meets its parent's drawing."""
    arm = Linkage(
        links=[
            Link("upper", 1.0, 0.01, 0.3, com=(0.15, 0.0), q_deg=120.0),
            Link("lower", 1.0, 0.01, 0.3, com=(0.15, 0.0), q_deg=150.0),
        ],
        joints=[Joint("elbow", "upper", "lower", at=(0.3, 0.05))],
        root=Root("pinned", link="upper", position=(0.0, 1.0)),
    )
    scene = granrs.Scene(body=arm, forces=[forces.gravity()], end="time", t_end=0.02)
    anim = granrs.animate(run(scene), frame_dt=0.01)
    series = anim.result.series
    assert series is not None
    q = series["q_upper"][0]
    root = np.array([series["x_root"][0], series["y_root"][0]])
    axis, normal = np.array([math.sin(q), math.cos(q)]), np.array([math.cos(q), -math.sin(q)])
    (spoke,) = anim._views[0].spokes[0]
    a, b = spoke.get_xydata() * 1e-3
    np.testing.assert_allclose(a, root + 0.3 * axis, atol=1e-12)
    np.testing.assert_allclose(b, root + 0.3 * axis + 0.05 * normal, atol=1e-12)
    start = anim._views[0].links["lower"].get_xydata()[0] * 1e-3
    np.testing.assert_allclose(start, b, atol=1e-12)


def test_built_in_bodies_are_drawn_from_their_linkages(
    chain: granrs.Result, leg: granrs.Result
) -> None:
    """The chain's links hang from the pin (each bar from the pin down to its recorded tip);
    the leg's shank, thigh and trunk rise from the ankle, knee and hip: every body, built-in
    or not, is drawn from its linkage."""
    anim = granrs.animate(chain, frame_dt=0.002)
    series = chain.series
    assert series is not None
    rows = np.searchsorted(series["t"], anim.frame_times - 1e-12)
    k = anim.n_frames - 1
    anim.draw(k)
    pin = np.array([series["x_pin"][rows[k]], series["y_pin"][rows[k]]])
    for i, name in enumerate(("link1", "link2")):
        a, b = anim._views[0].links[name].get_xydata() * 1e-3
        tip = np.array([series[f"c{i}.tip_x"][rows[k]], series[f"c{i}.tip_y"][rows[k]]])
        np.testing.assert_allclose(sorted([tuple(a), tuple(b)]), sorted([tuple(pin), tuple(tip)]),
                                   atol=1e-9)  # fmt: skip
    anim = granrs.animate(leg, frame_dt=0.002)
    anim.draw(0)
    ends = {n: line.get_xydata() * 1e-3 for n, line in anim._views[0].links.items()}
    for lower, upper in (("shank", "thigh"), ("thigh", "trunk")):
        np.testing.assert_allclose(ends[lower][1], ends[upper][0], atol=1e-9)
    title = "leg: v0 = 3.28 m/s, knee_deg = 20°, hip_deg = 20°, trunk_deg = 10°"
    assert anim.title == title
    suptitle = anim.figure.get_suptitle()
    assert " ".join(suptitle.split()) == title  # over both views, wrapped to their width
    assert [ax.get_title() for ax in anim.figure.axes] == ["body", "contacts"]


# The arrows, whether or not the step resolves the run: the poncelet rod (k = 2e5) warns
# at dt = 1e-4, rightly (t_s 1.4523 ms against 1.4701 ms at dt = 1e-5).
@pytest.mark.filterwarnings("ignore::granrs.StepSizeWarning")
@pytest.mark.parametrize(
    "term", [forces.rft(zeta=1e6), forces.poncelet(c=0.5, k=2e5)], ids=lambda t: t.name
)
def test_every_recorded_term_gets_an_arrow_and_a_legend_entry(term: forces.Term) -> None:
    """Issue 33: under rft or poncelet the legend said "forces not recorded" although the
    series held the term's force (F_rft_x/y, F_px/y) and no arrow was drawn. The recorded
    terms are read from the run's terms and the core's columns: the legend lists the term
    with the arrows' scale, and its arrow ends where the recorded force puts it."""
    scene = cases.free_link(q_deg=30.0, v0=2.0).replace(forces=[forces.gravity(), term])
    result = run(scene)
    series = result.series
    assert series is not None
    x, y = forces.info(term.name).columns
    anim = granrs.animate(result, frame_dt=0.002)
    legend = anim.figure.legends[0]
    labels = [t.get_text() for t in legend.get_texts()]
    assert term.name in labels and "sum" in labels
    assert legend.get_title().get_text().startswith("force arrows")
    rows = np.searchsorted(series["t"], anim.frame_times - 1e-12)
    k = int(np.argmax(np.hypot(series[x][rows], series[y][rows])))
    anim.draw(k)
    force = np.array([series[x][rows[k]], series[y][rows[k]]])
    assert np.hypot(*force) > 0.1
    start, end = (np.array(p) * 1e-3 for p in anim._views[0].arrows[0][term.name]._posA_posB)
    np.testing.assert_allclose(end - start, anim.force_scale * force, atol=1e-9)


def test_titles_come_from_the_scene_s_own_fields(free_link: granrs.Result) -> None:
    """Issue 33: a linkage was titled "linkage, v0 = 2.214 m/s" (the default v0 of a field
    a linkage does not have). A linkage's title names its links and root; a built-in body's
    its start fields."""

    def drawn_title(anim: ImpactAnimation) -> str:
        """The title as drawn: over the views, or the only view's (wrapped to its width)."""
        fig = anim.figure
        text = fig.get_suptitle() if len(fig.axes) > 1 else fig.axes[0].get_title()
        return " ".join(text.split())

    title = drawn_title(granrs.animate(two_segment_leg(0.05), frame_dt=0.01))
    assert "v0" not in title and "2.214" not in title
    assert title.startswith("linkage: 3 links, root moving") and "(0.2, -0.05) m/s" in title
    title = drawn_title(granrs.animate(free_link, frame_dt=0.01))
    assert title == "free_link: q_deg = 45°, v0 = 2.27 m/s"


def test_a_long_run_s_default_movie_stays_small(tmp_path: Path) -> None:
    """Issue 33: left to its defaults, a 1 s run made 1251 frames (50x slow motion at 25
    fps), whose GIF ran past 10 minutes and 6 GB. A movie left to the defaults has at most
    DEFAULT_FRAMES frames (a long run plays faster); the GIF has them all."""
    result = two_segment_leg(t_end=1.0)
    anim = granrs.animate(result, dpi=40.0)
    assert anim.n_frames == DEFAULT_FRAMES <= 300
    assert anim.fps == 25.0 and anim.speed == pytest.approx(1.0 / (DEFAULT_FRAMES - 1) * 25.0)
    assert anim.frame_times[-1] == pytest.approx(1.0, rel=1e-9)
    short = granrs.animate(run(cases.free_link(q_deg=45.0, v0=2.27)))
    assert short.speed == 0.02  # a short impact keeps the 50x slow motion
    out = tmp_path / "long.gif"
    anim.write(out)  # no warning (the test suite turns warnings into errors)
    assert gif_frames(out) == DEFAULT_FRAMES


def test_a_big_save_warns_with_its_size_before_any_frame(tmp_path: Path) -> None:
    """Issue 33: a big save started without a word. Writing more than BIG_SAVE_BYTES of
    frames warns first with the estimate (an AnimationSizeWarning, a UserWarning); as an
    error (as this suite runs) it stops the write before any frame is drawn."""
    anim = granrs.animate(two_segment_leg(t_end=1.0), frame_dt=0.0008)
    assert anim.n_frames == 1251
    width, height = anim.frame_pixels()
    estimate = animation.saved_bytes(anim.n_frames, width, height)
    assert estimate > animation.BIG_SAVE_BYTES
    out = tmp_path / "big.gif"
    with pytest.raises(AnimationSizeWarning, match=rf"1251 frames .* {estimate / 1e6:,.0f} MB"):
        anim.write(out)
    assert not out.exists() and not any(tmp_path.iterdir())
    assert issubclass(AnimationSizeWarning, UserWarning)
    assert "AnimationSizeWarning" in granrs.__all__


def test_the_documented_constants_are_reachable() -> None:
    """Issue 33: the docstring of animate() named granrs.animate.MAX_FRAMES, but
    granrs.animate is the function: the constant could not be reached. Every
    ``granrs.animation.NAME`` (or ``granrs.animate.NAME``) the animation's docstrings name
    resolves, as an attribute and as an import."""
    texts = [
        granrs.animate.__doc__ or "",
        animation.__doc__ or "",
        ImpactAnimation.write.__doc__ or "",
        AnimationSizeWarning.__doc__ or "",
    ]
    named = {m for text in texts for m in re.findall(r"granrs\.animat(?:e|ion)\.\w+", text)}
    assert "granrs.animation.MAX_FRAMES" in named
    for dotted in sorted(named):
        _, module, name = dotted.split(".")
        assert hasattr(getattr(granrs, module), name), dotted
        assert hasattr(importlib.import_module(f"granrs.{module}"), name), dotted
    assert granrs.animation.MAX_FRAMES == MAX_FRAMES == 10_000


# --- playback -------------------------------------------------------------------------------


def test_playback_speed_is_frame_dt_times_fps() -> None:
    """Any two of frame_dt, speed, fps give the third; defaults fps 25 and speed 0.02."""
    assert playback() == pytest.approx((0.02 / 25, 0.02, 25.0))
    assert playback(frame_dt=0.002) == pytest.approx((0.002, 0.05, 25.0))
    assert playback(speed=0.1) == pytest.approx((0.004, 0.1, 25.0))
    assert playback(fps=10) == pytest.approx((0.002, 0.02, 10.0))
    assert playback(frame_dt=0.001, speed=0.01) == pytest.approx((0.001, 0.01, 10.0))
    assert playback(frame_dt=0.001, fps=50) == pytest.approx((0.001, 0.05, 50.0))
    assert playback(speed=0.03, fps=15) == pytest.approx((0.002, 0.03, 15.0))
    assert playback(0.001, 0.02, 20) == pytest.approx((0.001, 0.02, 20.0))


# --- errors, before anything is drawn -------------------------------------------------------


@pytest.fixture
def nothing_drawn(monkeypatch: pytest.MonkeyPatch) -> None:
    """Fail the test if the animation gets as far as placing the body."""

    def boom(*_: object) -> None:
        raise AssertionError("a frame was drawn before the error")

    monkeypatch.setattr(drawing, "_pose", boom)


@pytest.mark.usefixtures("nothing_drawn")
@pytest.mark.parametrize("field", ["frame_dt", "speed", "fps", "dpi"])
@pytest.mark.parametrize("value", [0.0, -1.0, math.nan, math.inf, "fast", True])
def test_non_positive_playback_is_a_typed_error(
    free_link: granrs.Result, field: str, value: object
) -> None:
    with pytest.raises(InvalidParameterError) as info:
        granrs.animate(free_link, **{field: value})  # type: ignore[arg-type]
    assert info.value.field == field
    assert field in str(info.value)
    assert isinstance(info.value, ValueError) and isinstance(info.value, GranrsError)


@pytest.mark.usefixtures("nothing_drawn")
def test_inconsistent_playback_is_a_typed_error(free_link: granrs.Result) -> None:
    with pytest.raises(InvalidParameterError, match="frame_dt \\* fps") as info:
        granrs.animate(free_link, frame_dt=0.001, speed=0.5, fps=25)
    assert info.value.field == "speed"


@pytest.mark.usefixtures("nothing_drawn")
def test_too_many_frames_is_a_typed_error(free_link: granrs.Result) -> None:
    with pytest.raises(InvalidParameterError, match="frames") as info:
        granrs.animate(free_link, frame_dt=1e-7)
    assert info.value.field == "frame_dt"


@pytest.mark.usefixtures("nothing_drawn")
@pytest.mark.parametrize("record", [(), ("energy",)])
def test_a_result_without_state_is_a_typed_error(record: tuple[str, ...]) -> None:
    result = run(cases.free_link(q_deg=45.0, v0=2.27), record=record)
    with pytest.raises(InvalidParameterError, match="recorded no state") as info:
        granrs.animate(result)
    assert info.value.field == "record"


@pytest.mark.usefixtures("nothing_drawn")
def test_not_a_result_is_a_typed_error() -> None:
    with pytest.raises(InvalidParameterError, match=r"granrs\.Result") as info:
        granrs.animate(cases.free_link(q_deg=45.0, v0=2.27))  # type: ignore[arg-type]
    assert info.value.field == "result"


@pytest.mark.usefixtures("nothing_drawn")
@pytest.mark.parametrize("name", ["impact.avi", "impact", "impact.png"])
def test_unknown_output_suffix_is_a_typed_error(
    free_link: granrs.Result, tmp_path: Path, name: str
) -> None:
    with pytest.raises(InvalidParameterError, match="unknown suffix") as info:
        granrs.animate(free_link, out=tmp_path / name)
    assert info.value.field == "out"


@pytest.mark.usefixtures("nothing_drawn")
def test_unwritable_output_paths_are_typed_errors(free_link: granrs.Result, tmp_path: Path) -> None:
    """A missing directory, a file where the directory should be, a directory where the
    file should be, and (for a user other than root) a read-only directory."""
    a_file = tmp_path / "file.txt"
    a_file.write_text("x")
    a_dir = tmp_path / "taken.gif"
    a_dir.mkdir()
    for out, why in [
        (tmp_path / "missing" / "impact.gif", "does not exist"),
        (a_file / "impact.gif", "does not exist"),
        (a_dir, "a directory"),
    ]:
        with pytest.raises(InvalidParameterError, match=why) as info:
            granrs.animate(free_link, out=out)
        assert info.value.field == "out"
    if os.geteuid() != 0:  # root writes anywhere
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        with pytest.raises(InvalidParameterError, match="not writable"):
            check_output(locked / "impact.gif")


@pytest.mark.usefixtures("nothing_drawn")
def test_mp4_without_ffmpeg_is_a_typed_error(
    free_link: granrs.Result, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(mpl_animation.writers, "is_available", lambda name: False)
    with pytest.raises(InvalidParameterError, match="ffmpeg") as info:
        granrs.animate(free_link, out=tmp_path / "impact.mp4")
    assert info.value.field == "out"


# --- writing --------------------------------------------------------------------------------


def gif_frames(path: Path) -> int:
    with Image.open(path) as image:
        assert image.format == "GIF"
        return int(image.n_frames)


def test_animate_writes_gif_and_html(free_link: granrs.Result, tmp_path: Path) -> None:
    anim = granrs.animate(free_link, frame_dt=0.01, out=tmp_path / "impact.gif")
    assert gif_frames(tmp_path / "impact.gif") == anim.n_frames == 3
    anim.write(tmp_path / "impact.html")
    html = (tmp_path / "impact.html").read_text()
    assert html.count("data:image/png;base64") == 3


def test_animate_writes_mp4_where_ffmpeg_is(
    free_link: granrs.Result, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """An .mp4 through matplotlib's ffmpeg writer. Where no ffmpeg is on PATH, matplotlib is
    pointed at the binary of the imageio-ffmpeg wheel (a ``test`` extra), so the test runs
    in the environment the README's test command makes."""
    if not mpl_animation.writers.is_available("ffmpeg"):
        imageio_ffmpeg = pytest.importorskip(
            "imageio_ffmpeg", reason="no ffmpeg on PATH and no imageio-ffmpeg (a test extra)"
        )
        monkeypatch.setitem(
            matplotlib.rcParams, "animation.ffmpeg_path", imageio_ffmpeg.get_ffmpeg_exe()
        )
    assert mpl_animation.writers.is_available("ffmpeg")
    granrs.animate(free_link, frame_dt=0.01, out=tmp_path / "impact.mp4")
    assert (tmp_path / "impact.mp4").stat().st_size > 1000


# --- the command line -----------------------------------------------------------------------


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_cli_animate_writes_a_gif_per_example_scene(
    path: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Issue 20: `granrs animate SCENE.toml --out impact.gif` for each example scene; the GIF
    has one frame per 10 ms of the run (its length from the same scene run directly)."""
    out = tmp_path / "impact.gif"
    code = main(["animate", str(path), "--out", str(out), "--frame-dt", "0.01", "--dpi", "50"])
    _, err = capsys.readouterr()
    assert code == 0, err
    assert f"animation written to {out}" in err
    scene = granrs.scenefile.load(path)
    record = True if isinstance(scene, granrs.space.Scene) else ("state",)
    series = granrs.simulate(scene.replace(record=record)).series  # type: ignore[arg-type]
    assert series is not None
    assert gif_frames(out) == math.floor(series["t"][-1] / 0.01) + 1


def test_cli_animate_checks_the_output_before_the_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A bad --out or --fps is exit code 2 with one line naming it, and nothing runs."""

    def no_run(*_: object) -> None:
        raise AssertionError("the scene ran")

    monkeypatch.setattr(granrs.api, "simulate", no_run)
    scene = str(EXAMPLES[0])
    for argv, needle in [
        (["--out", str(tmp_path / "x.avi")], "unknown suffix"),
        (["--out", str(tmp_path / "no" / "x.gif")], "does not exist"),
        (["--out", str(tmp_path / "x.gif"), "--fps", "0"], "fps"),
        (["--out", str(tmp_path / "x.gif"), "--frame-dt", "-0.01"], "frame_dt"),
    ]:
        code = main(["animate", scene, *argv])
        _, err = capsys.readouterr()
        assert code == 2, err
        lines = err.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("granrs: error: ") and needle in lines[0]
    assert not any(tmp_path.iterdir())


def test_cli_animate_writes_html(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "impact.html"
    code = main(["animate", str(EXAMPLES[0]), "--out", str(out), "--speed", "0.2", "--fps", "10"])
    _, err = capsys.readouterr()
    assert code == 0, err
    assert "<script" in out.read_text()


# --- Result._repr_html_ ---------------------------------------------------------------------


def test_result_repr_html_has_a_row_per_contact(chain: granrs.Result) -> None:
    """Notebooks: a table with the status and each link's t_s, depth and dE with units."""
    html = chain._repr_html_()
    assert html.startswith("<table>") and html.endswith("</table>")
    assert "stopped" in html and "t_s [ms]" in html and "depth [mm]" in html and "dE [J]" in html
    assert html.count("<tr>") == 3  # the header and two links
    for name, contact in zip(["link1", "link2"], chain.contacts, strict=True):
        assert f"<td>{name}</td>" in html
        assert f"{contact.depth * 1e3:.4g}" in html
    assert f"{chain.contacts[1].t_s * 1e3:.4g}" in html
    assert math.isnan(chain.contacts[0].t_s) and "<td>-</td>" in html


def test_import_granrs_does_not_import_matplotlib() -> None:
    """``import granrs`` stays light: matplotlib loads with the first animation (or
    ``granrs.ImpactAnimation``), which is then the FuncAnimation subclass."""
    code = (
        "import sys, granrs\n"
        "assert 'matplotlib' not in sys.modules, 'matplotlib imported'\n"
        "from matplotlib.animation import FuncAnimation\n"
        "assert issubclass(granrs.ImpactAnimation, FuncAnimation)\n"
        "assert 'ImpactAnimation' in granrs.__all__ and callable(granrs.animate)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
