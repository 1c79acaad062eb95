"""Granular media as data (granrs.media): the shipped cards, a scene's medium, a card of
one's own, and bad cards refused naming the entry."""

from __future__ import annotations

import doctest
import math
import pickle
from pathlib import Path

import pytest
from _modules import load_module

import granrs
from granrs import forces as f
from granrs import media, scenefile, space
from granrs.errors import InvalidParameterError, MediumError, UnknownNameError

CARDS = media.names()

#: The terms a drop of a rod can run under.
ROD_TERMS = [n for n in f.TERMS if (f.info(n).shapes or ()) and "rod" in f.info(n).shapes]


def test_cards_are_shipped() -> None:
    assert {"thesis_sand", "thesis_fine_sand", "li2013_generic"} <= set(CARDS)
    assert list(CARDS) == sorted(CARDS)


@pytest.mark.parametrize("name", CARDS)
def test_every_shipped_card_loads_and_every_value_has_a_source(name: str) -> None:
    card = media.load(name)
    assert card.name == name and card.description
    assert card.medium or card.params
    for key, v in [*card.medium.items(), *card.params.items()]:
        assert isinstance(v.value, float) and math.isfinite(v.value), key
        assert v.source.strip() and card.source(key) == v.source, key
        if v.interval is not None:
            assert v.interval[0] <= v.value <= v.interval[1], key
    for key, why in card.missing.items():
        assert why.strip(), key
        with pytest.raises(UnknownNameError, match="has no value") as caught:
            card.source(key)
        assert caught.value.field == key
    # The text round-trips exactly.
    assert media.loads(card.dumps()) == card
    assert media.load(name) is card  # read once


@pytest.mark.parametrize("name", CARDS)
def test_a_drop_runs_in_each_card_s_medium(name: str) -> None:
    """The free link dropped under every rod term the card has values for (with a required
    parameter it lacks given here), and under the thesis's law, in its medium."""
    card = media.load(name)
    terms = [n for n in ROD_TERMS if card.params_for(n)]
    assert terms, f"{name} has values for no term"
    listed = []
    for n in terms:
        lacking = [p for p in f.info(n).params if p.required and p.name not in card.params_for(n)]
        listed.append(f.term(n, **{p.name: 1e6 for p in lacking}))
    for law in ([f.gravity(), *listed], list(f.thesis())):
        scene = granrs.Scene(medium=name, forces=law, q_deg=30.0, v0=2.0, t_end=0.5)
        if card.rho_g is not None:
            assert scene.rho_g == card.rho_g
        r = granrs.simulate(scene)
        assert r.status == "stopped", (name, law)
        assert 0.0 < r.depth < 0.19 and 0.0 < r.t_s < 0.5


def test_a_body_in_space_takes_its_medium() -> None:
    ball = space.Body(space.Sphere(0.02), density=7800.0)
    scene = space.Scene(
        body=ball,
        forces=[f.gravity(), f.poncelet()],
        velocity=(0.0, 0.0, -2.0),
        medium="thesis_sand",
    )
    card = media.load("thesis_sand")
    assert scene.forces[1].params == {"c": 5.32, "k": 273.0}
    assert scene.rho_g == card.rho_g and scene.medium is card
    r = granrs.simulate(scene)
    assert r.status == "stopped" and r.depth > 0.0
    text = scenefile.dumps(scene)
    assert 'medium = "thesis_sand"' in text
    assert scenefile.loads(text) == scene
    rft3d = space.Scene(body=ball, forces=[f.rft3d()], medium="thesis_sand")
    assert rft3d.forces[0].params["zeta"] == card.value("rft3d.zeta").value
    with pytest.raises(granrs.InvalidSceneError) as caught:
        space.Scene(body=ball, forces=[f.rft3d()], medium="thesis_fine_sand")
    assert caught.value.field == "rft3d.zeta"
    assert "thesis_fine_sand" in str(caught.value)
    # Without the medium, poncelet has neither c nor k (the scene gave neither).
    with pytest.raises(granrs.InvalidSceneError) as caught:
        scene.replace(medium=None)
    assert caught.value.field == "poncelet.c"
    assert scene.replace(medium=None, forces=[f.gravity()]).rho_g == 1650.0


def test_the_medium_fills_what_is_not_given_and_given_values_win() -> None:
    sand = media.load("thesis_sand")
    s = granrs.Scene(medium="thesis_sand", forces=[f.gravity(), f.rft(), f.poncelet(c=1.0)])
    assert s.forces[1].params["zeta"] == sand.value("rft.zeta").value
    assert s.forces[2].params == {"c": 1.0, "k": 273.0}  # c given, k the card's
    assert s.coefficients_source == "medium thesis_sand"
    assert s.forces[1].params["elements"] == 8  # the card has none: the term's default
    own = granrs.Scene(medium="thesis_sand", forces=[f.rft(zeta=1e6)])
    assert own.forces[0].params["zeta"] == 1e6
    # rho_g: the medium's where the scene's is its default; a value of one's own is kept.
    fine = granrs.Scene(medium="thesis_fine_sand")
    assert fine.rho_g == 1600.0
    assert fine.forces == f.thesis({"eta_h": 10.0, "eta_d": 13.0, "eta_v": 195.0, "lam": 1.05})
    assert granrs.Scene(medium="thesis_fine_sand", rho_g=1700.0).rho_g == 1700.0
    # The thesis's own scenes give their row's coefficients: only rho_g changes.
    case = granrs.cases.free_link(q_deg=45, v0=2.27)
    moved = case.replace(medium="thesis_fine_sand")
    assert moved.forces == case.forces and moved.rho_g == 1600.0


def test_changing_the_medium_undoes_what_the_old_one_set() -> None:
    fine = granrs.Scene(medium="thesis_fine_sand", forces=[f.gravity(), *f.thesis()[1:4]])
    back = fine.replace(medium=None)
    assert back.rho_g == 1650.0 and back.medium is None
    assert back.forces == (f.gravity(), *f.thesis()[1:4])
    assert back.coefficients_source == granrs.Scene().coefficients_source
    assert granrs.Scene(medium="thesis_fine_sand").replace(medium=None) == granrs.Scene()
    other = fine.replace(medium="thesis_sand")
    assert other == granrs.Scene(medium="thesis_sand", forces=[f.gravity(), *f.thesis()[1:4]])
    assert other.forces[1].params["eta_d"] == 15.2
    # A required parameter the new medium lacks is refused, naming it.
    rft = granrs.Scene(medium="thesis_sand", forces=[f.gravity(), f.rft()])
    with pytest.raises(granrs.InvalidSceneError) as caught:
        rft.replace(medium="thesis_fine_sand")
    assert caught.value.field == "rft.zeta"


def test_a_required_parameter_without_a_medium_is_refused_naming_it() -> None:
    with pytest.raises(granrs.InvalidSceneError, match="medium") as caught:
        granrs.Scene(forces=[f.gravity(), f.poncelet(c=1.0)])
    assert caught.value.field == "poncelet.k"
    with pytest.raises(granrs.InvalidSceneError) as caught:
        granrs.Scene(medium="li2013_generic", forces=[f.rft()])
    assert caught.value.field == "rft.zeta"


def test_unknown_media_are_refused_with_the_nearest_name() -> None:
    with pytest.raises(UnknownNameError, match="did you mean 'thesis_sand'") as caught:
        granrs.Scene(medium="thesis_snad")
    assert caught.value.field == "medium"
    with pytest.raises(InvalidParameterError) as caught:
        granrs.Scene(medium=3.0)  # type: ignore[arg-type]
    assert caught.value.field == "medium"
    with pytest.raises(UnknownNameError):
        scenefile.loads('medium = "no_such_sand"\n')
    with pytest.raises(granrs.InvalidSceneError) as caught:
        granrs.sweep(granrs.Scene(), medium=["thesis_sand"])
    assert caught.value.field == "medium"


def test_a_card_of_one_s_own_round_trips(tmp_path: Path) -> None:
    card = (
        media.load("thesis_sand")
        .replace(name="my_sand", description="mine")
        .with_value(
            "rft.zeta", 2.5e6, "fitted by me", sd=1e5, interval=(2.3e6, 2.7e6), samples=[2.4e6]
        )
        .with_value("rft3d.zeta", 4.0e5, "fitted by me, too")
    )
    assert "rft3d.zeta" not in card.missing
    path = tmp_path / "my_sand.toml"
    card.save(path)
    again = media.load(path)
    assert again == card and again.path == str(path.resolve())
    assert again.value("rft.zeta").samples == (2.4e6,)
    assert pickle.loads(pickle.dumps(again)) == again
    assert media.load(card.to_dict()) == card
    # A scene names it by its path; a scene file relative to itself.
    scene = granrs.Scene(medium=str(path), forces=[f.gravity(), f.rft()])
    assert scene.forces[1].params["zeta"] == 2.5e6
    (tmp_path / "run.toml").write_text(
        'medium = "my_sand.toml"\n[[forces]]\nterm = "gravity"\n[[forces]]\nterm = "rft"\n',
        encoding="utf-8",
    )
    assert scenefile.load(tmp_path / "run.toml") == scene
    assert scenefile.loads(scenefile.dumps(scene)) == scene
    # A card made in memory is written into the scene file whole.
    memory = granrs.Scene(medium=card.replace(name="unsaved"), forces=[f.gravity(), f.rft()])
    text = scenefile.dumps(memory)
    assert "[medium]" in text and "[medium.terms.rft.zeta]" in text
    assert scenefile.loads(text) == memory
    assert pickle.loads(pickle.dumps(memory)) == memory


def _card_text(extra: str) -> str:
    return f'format = 1\nname = "bad"\ndescription = "a bad card"\n{extra}'


@pytest.mark.parametrize(
    ("extra", "field", "words"),
    [
        ('[terms.rfx.zeta]\nvalue = 1.0\nsource = "s"\n', "rfx.zeta", "did you mean 'rft'"),
        ('[terms.rft.zetta]\nvalue = 1.0\nsource = "s"\n', "rft.zetta", "did you mean 'zeta'"),
        ('[terms.rft.zeta]\nvalue = -1.0\nsource = "s"\n', "rft.zeta", ">= 0"),
        ('[terms.rft.elements]\nvalue = 2000.0\nsource = "s"\n', "rft.elements", "1024"),
        ("[terms.rft.zeta]\nvalue = 1e6\n", "rft.zeta.source", "no source"),
        ('[terms.rft.zeta]\nvalue = 1e6\nsource = "  "\n', "rft.zeta.source", "no source"),
        ('[terms.rft.zeta]\nvalue = 1e6\nsource = "s"\nsdd = 1.0\n', "rft.zeta.sdd", "'sd'"),
        ('[terms.rft.zeta]\nvalue = 1e6\nsource = "s"\nsd = -1.0\n', "rft.zeta.sd", ">= 0"),
        (
            '[terms.rft.zeta]\nvalue = 1e6\nsource = "s"\ninterval = [2.0, 1.0]\n',
            "rft.zeta.interval",
            "low <= high",
        ),
        ('[medium.rho]\nvalue = 1.0\nsource = "s"\n', "rho", "did you mean 'rho_g'"),
        ('[medium.rho_g]\nvalue = 0.0\nsource = "s"\n', "rho_g", "> 0"),
        ('[medium.rho_g]\nvalue = "x"\nsource = "s"\n', "rho_g", "finite number"),
        ('colour = "red"\n', "colour", "unknown key"),
        ('[missing]\n"rft.zeta" = ""\n', "rft.zeta", "why"),
        ('[missing]\n"poncelet.d1" = "no"\n', "poncelet.d1", "no parameter"),
    ],
)
def test_bad_cards_raise_the_typed_error_naming_the_entry(
    extra: str, field: str, words: str, tmp_path: Path
) -> None:
    path = tmp_path / "bad.toml"
    path.write_text(_card_text(extra), encoding="utf-8")
    with pytest.raises(MediumError, match=words) as caught:
        media.load(path)
    assert isinstance(caught.value, ValueError) and isinstance(caught.value, granrs.GranrsError)
    assert caught.value.field == field
    assert str(path.resolve()) in str(caught.value)
    # In a scene, the same error, before any run.
    with pytest.raises(MediumError) as caught:
        granrs.Scene(medium=str(path))
    assert caught.value.field == field


def test_bad_cards_made_in_python_raise_too() -> None:
    with pytest.raises(MediumError) as caught:
        media.MediumCard(name="a b")
    assert caught.value.field == "name"
    with pytest.raises(MediumError) as caught:
        media.MediumCard(name="x", params={"poncelet.c": media.Value(1.0, "")})
    assert caught.value.field == "poncelet.c.source"
    with pytest.raises(MediumError, match="both"):
        media.MediumCard(
            name="x", params={"rft.zeta": {"value": 1.0, "source": "s"}}, missing={"rft.zeta": "?"}
        )
    with pytest.raises(MediumError) as caught:
        media.loads("format = 2\nname = 'x'\n")
    assert caught.value.field == "format"
    with pytest.raises(MediumError) as caught:
        media.loads("name = \n")
    assert caught.value.field == "card"
    with pytest.raises(UnknownNameError):
        media.load("thesis_sand").params_for("rfx")


def test_the_module_s_examples_run() -> None:
    failures, tried = doctest.testmod(media, verbose=False, report=True)
    assert tried > 0 and failures == 0


def test_the_docs_table_lists_every_card_s_every_value() -> None:
    docs = Path(__file__).resolve().parents[1] / "docs"
    gen = load_module("granrs_docs", docs / "_ext" / "granrs_docs.py", reuse=True)
    page = (docs / "media.md").read_text(encoding="utf-8")
    assert ".. granrs-media-table::" in page
    rows = gen.media_table_rows()
    for name in CARDS:
        card = media.load(name)
        keys = [*card.medium, *card.params, *card.missing]
        listed = [r[1] for r in rows if r[0] == f"``{name}``"]
        assert listed == [f"``{k}``" for k in keys], name


def test_mujoco_sand_takes_a_medium() -> None:
    mujoco = pytest.importorskip("mujoco")
    from granrs.mujoco import Sand

    xml = (
        '<mujoco><worldbody><body name="b" pos="0 0 0.1"><freejoint/>'
        '<geom name="ball" type="sphere" size="0.02" density="7800"/></body></worldbody>'
        "</mujoco>"
    )
    model = mujoco.MjModel.from_xml_string(xml)
    sand = Sand(model, ["ball"], [f.rft3d(), f.poncelet()], medium="thesis_sand")
    assert sand.medium is media.load("thesis_sand")
    data = mujoco.MjData(model)
    sand.install()
    try:
        for _ in range(200):
            mujoco.mj_step(model, data)
    finally:
        sand.uninstall()
    assert math.isfinite(float(data.qpos[2]))
    with pytest.raises(granrs.InvalidSceneError) as caught:
        Sand(model, ["ball"], [f.rft3d()], medium="thesis_fine_sand")
    assert caught.value.field == "rft3d.zeta"
