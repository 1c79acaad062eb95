"""Adversarial input over every public constructor and field, with its figures printed.

Each input is one bad or good value put into one field of one public way in:

- ``scene``: a ``granrs.Scene`` field, on each built-in body;
- ``case``: an argument of ``granrs.cases.free_link``, ``chain`` or ``leg``;
- ``term``: a parameter of each ``granrs.forces`` term (every registered term, by
  ``granrs.forces.term`` and by its own constructor), run on a body;
- ``element``: a field of a ``granrs.bodies`` ``Link``, ``Joint``, ``Contact`` (rod, box and
  arc) or ``Root`` of a small linkage;
- ``sweep``: a value of a ``granrs.sweep`` axis;
- ``toml``: a value in a TOML scene file's text;
- ``space``: a field of a ``granrs.space.Scene``, of its body, of its shape (each shape in
  space) or of its terms (``rft3d``, ``rft3d_inertial``, ``poncelet``);
- ``medium``: an entry of a medium card (``granrs.media``: the medium's numbers, a term's
  parameter, a value's source and uncertainty, the card's name), the card then a scene's
  medium. (A scene's ``medium`` field is an input of ``scene``, ``sweep`` and ``space``, with
  the shipped cards' names among the values.)

The values: NaN, infinities, -0, huge floats and ints (``10**400``), strings, None, bools,
numpy bools, numpy scalars and arrays, nested lists, mappings, unknown names, and good
values. The property: the input is refused with a ``granrs.GranrsError`` subclass that names
the field (in its message or ``.field``), or it runs (a short run) to finite results. Any
other exception, a typed error that does not name the field, or a run with non-finite
numbers is a failure.

tests/test_adversarial.py runs the same generators under hypothesis. This script runs N
inputs from a seed and prints what it saw::

    python benches/adversarial.py --n 2000 [--seed 0]

It prints the inputs tried, the typed errors by class, the runs that finished, and the
failures (anything else; should be 0) with their inputs, and exits 1 if there was any.
"""

from __future__ import annotations

import argparse
import collections
import dataclasses
import inspect
import math
import random
import sys
import time
import warnings
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

import granrs
from granrs import Scene, cases, forces, media, scenefile, space
from granrs.bodies import Contact, Joint, Link, Linkage, Root
from granrs.errors import GranrsError, SimulationError, StepSizeWarning

#: A chooser: ``pick(options, label)`` returns one of ``options`` (hypothesis's ``draw``, or
#: a seeded random choice).
Pick = Callable[[Sequence[Any], str], Any]

NAN, INF = math.nan, math.inf

#: Values no field takes, or takes only in part: the adversary's pool.
BAD: tuple[Any, ...] = (
    NAN,
    INF,
    -INF,
    -0.0,
    0.0,
    -1.0,
    1e-300,
    1e300,
    -1e300,
    10**400,
    -(10**400),
    2**64,
    7,
    "",
    "abc",
    "nan",
    "1.0",
    None,
    True,
    False,
    np.True_,
    np.False_,
    np.float64(NAN),
    np.int64(3),
    np.float32(0.5),
    np.array([1.0, 2.0]),
    np.array(1.0),
    [1.0],
    [[1.0, 2.0]],
    [],
    (),
    {},
    {"k": 1.0},
    {"k": NAN, "c": 1.0},
    {"eta_h": 1.0},
    "free",
    "tip",
    "state",
    "rod",
    "driven",
    ["state", "state"],
    ["bogus"],
    b"bytes",
)

#: TOML value texts for a scene file.
TOML_VALUES: tuple[str, ...] = (
    "nan",
    "inf",
    "-inf",
    "-0.0",
    "0",
    "-1.0",
    "1e300",
    "1e-300",
    "99999999999999999999",
    '"abc"',
    '""',
    "true",
    "[1.0, 2.0]",
    "[[1.0]]",
    "[]",
    "{ k = 1.0 }",
    "{ k = nan, c = 1.0 }",
    '["state", "state"]',
    '["bogus"]',
    '"free"',
    '"smooth"',
    '"dopri5"',
    '"thesis_sand"',
    "2.0",
    "0.5",
)


#: Values of a scene's ``medium``: the shipped cards, a near miss, a path to nothing.
MEDIA: tuple[Any, ...] = (*media.names(), "thesis_snad", "/no/such/card.toml")


def good_variants(default: Any, name: str = "") -> list[Any]:
    """Values near a field's default that a scene may well take (the field ``name``'s own
    good values: a medium's names)."""
    if name == "medium":
        return [default, *MEDIA]
    if isinstance(default, float) and math.isfinite(default):
        return [default, default * 0.5 + 1e-3, default * 2.0 + 1e-3]
    return [default]


@dataclasses.dataclass
class Case:
    """One adversarial input: where it goes, the field it sets (and the names an error
    may give for it), its value, and the call that builds and runs it."""

    target: str
    field: str
    value: Any
    build: Callable[[], Any]
    names: tuple[str, ...] = ()
    loose: bool = False  # a reference (a name another element points at): any field will do


def short(scene: Scene) -> Scene:
    """The scene cut to a short run (at most 0.01 s and 2000 steps)."""
    t_end = min(scene.t_end, 0.01, 2000 * scene.dt)
    return scene if t_end == scene.t_end else scene.replace(t_end=t_end)


def run(scene: Scene) -> Any:
    """Run a short copy of ``scene``; a step-size warning is a valid outcome here."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", StepSizeWarning)
        return granrs.simulate(short(scene))


def finite(result: Any) -> bool:
    """No infinity in the run's summary, and its energies and end time finite where the
    scene's outputs ask for them (a scene that asks for none has none of them)."""
    s = result.summary
    values = [v for v in s.values() if isinstance(v, float)]
    return not any(math.isinf(v) for v in values) and all(
        math.isfinite(s[k]) for k in ("energy_start", "energy_end", "t_final") if k in s
    )


# --------------------------------------------------------------------------------------
# The generators


def scene_case(pick: Pick) -> Case:
    body = pick(granrs.scene.BODIES, "body")
    names = [f.name for f in dataclasses.fields(Scene)]
    name = pick(names, "field")
    default = granrs.scene._DEFAULTS.get(name)
    value = pick([*BAD, *good_variants(default, name)], "value")
    kw = {"body": value} if name == "body" else {"body": body, name: value}
    return Case("scene", name, value, lambda: run(Scene(**kw)))


def case_case(pick: Pick) -> Case:
    which = pick(("free_link", "chain", "leg"), "case")
    args: dict[str, tuple[str, ...]] = {
        "free_link": ("q_deg", "v0", "coefficients", "dt", "apply_at"),
        "chain": ("case", "q1_deg", "q2_deg", "coefficients", "dt", "apply_at"),
        "leg": ("v0", "coefficients", "joints", "dt", "apply_at"),
    }
    name = pick(args[which], "argument")
    value = pick([*BAD, "table_3_2", 2, 1.5, 20.0], "value")
    kw: dict[str, Any] = {"q_deg": 10.0, "v0": 1.5} if which == "free_link" else {}
    kw[name] = value
    also = {
        "q1_deg": ("q_deg",),
        "q2_deg": ("q2_deg",),
        "joints": ("ankle", "knee", "hip"),
        "coefficients": ("coefficients", "eta", "lam"),
    }.get(name, ())
    build = getattr(cases, which)
    return Case("case", name, value, lambda: run(build(**kw)), names=also)


def term_case(pick: Pick) -> Case:
    name = pick(forces.TERMS, "term")
    info = forces.info(name)
    params = [p.name for p in info.params]
    constructor = getattr(forces, name)
    # The constructor's own arguments beyond the registry's (rft's coefficients mapping).
    extra = [a for a in inspect.signature(constructor).parameters if a not in params]
    param = pick([*params, *extra] or ["<none>"], "parameter")
    value = pick([*BAD, 0.5, 8, 1e6, 2000, 1024], "value")
    required = {p.name: (1e6 if p.name == "zeta" else 1.0) for p in info.params if p.required}
    by_constructor = pick((True, False), "by constructor")
    body = pick(granrs.scene.BODIES, "body")

    def build() -> Any:
        kw: dict[str, Any] = dict(required)
        if param != "<none>":
            if param == "coefficients":
                kw["coefficients"] = value
            elif by_constructor and param in forces.RFT_COEFFICIENTS:
                kw["coefficients"] = {param: value}
            else:
                kw[param] = value
        if by_constructor:
            term = constructor(**kw)
        else:
            term = forces.term(name, **kw)
        return run(Scene(body=body, forces=[forces.gravity(), term]))

    return Case("term", f"{name}.{param}", value, build, names=(param, "forces"))


def _linkage_parts() -> dict[str, Any]:
    return {
        "link": Link("a", 1.0, 0.01, 0.3, (0.15, 0.0), q_deg=150.0),
        "link_b": Link("b", 0.5, 0.002, 0.2, (0.1, 0.0), q_deg=170.0),
        "joint": Joint("j", "a", "b", (0.3, 0.0), kind="spring", k=10.0, c=0.1),
        "rod": Contact.rod("b", 0.2, 0.0127, name="rod"),
        "box": Contact.box("a", 0.1, 0.02, 0.05, name="box"),
        "arc": Contact.arc("a", 0.05, 0.0, 180.0, 0.02, at=(0.15, 0.0), name="arc"),
        "root": Root("free", link="a", position=(0.0, 0.2), velocity=(0.0, -1.0)),
    }


#: Fields that name another element: a bad one may surface where it is referred to.
_REFERENCES = frozenset({"name", "link", "parent", "child"})


def element_case(pick: Pick) -> Case:
    parts = _linkage_parts()
    which = pick(("link", "joint", "rod", "box", "arc", "root"), "element")
    element = parts[which]
    name = pick([f.name for f in dataclasses.fields(element)], "field")
    value = pick([*BAD, "pinned", "moving", "spring", "box", "arc", 0.05, (0.1, 0.0)], "value")

    def build() -> Any:
        parts[which] = dataclasses.replace(element, **{name: value})
        linkage = Linkage(
            links=[parts["link"], parts["link_b"]],
            joints=[parts["joint"]],
            contacts=[parts["rod"], parts["box"], parts["arc"]],
            root=parts["root"],
        )
        terms = [forces.gravity(), forces.rft(zeta=1e5, elements=2), forces.joint_springs()]
        return run(Scene(body=linkage, forces=terms, end="time", t_end=0.01))

    return Case("element", name, value, build, loose=name in _REFERENCES)


def sweep_case(pick: Pick) -> Case:
    names = [f.name for f in dataclasses.fields(Scene) if f.name != "body"]
    name = pick(names, "axis")
    default = granrs.scene._DEFAULTS.get(name)
    value = pick([*BAD, *good_variants(default, name)], "value")
    base = cases.free_link(q_deg=10.0, v0=1.5, t_end=0.01)

    def build() -> Any:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", StepSizeWarning)
            df = granrs.sweep(base, threads=1, progress=False, **{name: [value]})
        if (df["status"] == "failed").any():
            raise SimulationError(str(df.get("error", df["status"]).iloc[0]))
        return df

    return Case("sweep", name, value, build)


_TOML_BASE: dict[str, str] = {}


def toml_case(pick: Pick) -> Case:
    body = pick(granrs.scene.BODIES, "body")
    if body not in _TOML_BASE:
        _TOML_BASE[body] = scenefile.dumps(Scene(body=body, t_end=0.01))
    lines = _TOML_BASE[body].splitlines()
    keyed = [i for i, line in enumerate(lines) if "=" in line and not line.startswith("#")]
    i = pick(keyed, "line")
    key = lines[i].split("=", 1)[0].strip()
    value = pick(TOML_VALUES, "value")
    lines[i] = f"{key} = {value}"
    text = "\n".join(lines) + "\n"
    field = key.split(".")[-1]
    return Case("toml", field, value, lambda: run(granrs.scenefile.loads(text)))


#: Each shape in space from one parameter value (the others good).
SPACE_SHAPES: dict[str, Callable[[Any], Any]] = {
    "sphere.radius": lambda v: space.Sphere(radius=v),
    "capsule.radius": lambda v: space.Capsule(radius=v, length=0.05),
    "capsule.length": lambda v: space.Capsule(radius=0.01, length=v),
    "cylinder.length": lambda v: space.Cylinder(radius=0.01, length=v),
    "cuboid.size": lambda v: space.Cuboid(size=v),
    "cuboid.size[1]": lambda v: space.Cuboid(size=(0.02, v, 0.03)),
    "mesh.vertices": lambda v: space.Mesh(vertices=v, triangles=np.zeros((4, 3), dtype=int)),
    "mesh.triangles": lambda v: space.Mesh(vertices=np.eye(4, 3), triangles=v),
}


@dataclasses.dataclass
class _Terms:
    """A term to build inside the case's call (so that its own errors are the case's)."""

    name: str
    params: dict[str, Any]


def space_case(pick: Pick) -> Case:
    where = pick(("scene", "body", "shape", "term"), "where")
    value = pick([*BAD, 0.5, 0.02, 1e6, (0.0, 0.0, -1.0), (1.0, 0.0, 0.0, 0.0)], "value")
    kw: dict[str, Any] = {
        "body": space.Body(space.Sphere(0.02), density=7800.0),
        "forces": [forces.rft3d(zeta=2e5), forces.gravity()],
        "velocity": (0.3, 0.0, -1.0),
        "omega": (0.0, 2.0, 0.0),
        "t_end": 0.01,
    }
    if where == "scene":
        field = pick([f.name for f in dataclasses.fields(space.Scene) if f.init], "field")
        kw[field] = pick((value, *MEDIA), "medium") if field == "medium" else value
        names: tuple[str, ...] = (field,)
    elif where == "body":
        field = pick(("density", "mass", "inertia"), "field")
        body = (
            {"density": None, "mass": 0.1, field: value}
            if field != "density"
            else {"density": value}
        )
        kw["body"] = space.Body(space.Capsule(0.01, 0.04), **body)
        names = ("body", field)
    elif where == "shape":
        field = pick(list(SPACE_SHAPES), "field")
        make = SPACE_SHAPES[field]
        kw["body"] = lambda: space.Body(make(value), density=2000.0)  # built in build()
        names = ("body.shape", field.split(".")[-1].split("[")[0], "vertices", "triangles")
    else:
        name = pick(("rft3d", "rft3d_inertial", "poncelet"), "term")
        info = forces.info(name)
        field = pick([p.name for p in info.params], "parameter")
        params = {p.name: (2e5 if p.name == "zeta" else 1.0) for p in info.params if p.required}
        params[field] = value
        kw["forces"] = _Terms(name, params)
        names = (name, field, "forces")

    def build() -> Any:
        args = dict(kw)
        if callable(args["body"]):
            args["body"] = args["body"]()
        if isinstance(args["forces"], _Terms):
            t = args["forces"]
            args["forces"] = [forces.term(t.name, **t.params), forces.gravity()]
        return run(space.Scene(**args))

    return Case("space", field, value, build, names=names)


#: The entries of a medium card an input may set: the medium's numbers, terms'
#: parameters, a value's source and uncertainty, and the card's own keys.
MEDIUM_ENTRIES: tuple[str, ...] = (
    "name",
    "description",
    "rho_g",
    "g",
    "rho",
    "rft.zeta",
    "rft.elements",
    "rft.A00",
    "poncelet.c",
    "poncelet.k",
    "drag.eta_d",
    "static_v.lam",
    "rft3d.zeta",
    "rfx.zeta",
    "rft.zetta",
    "rft.zeta.source",
    "rft.zeta.sd",
    "rft.zeta.interval",
    "rft.zeta.level",
    "rft.zeta.samples",
)


def medium_case(pick: Pick) -> Case:
    entry = pick(MEDIUM_ENTRIES, "entry")
    value = pick([*BAD, 0.5, 1e6, 1650.0, "a source", [1.0, 2.0]], "value")
    data = media.load("thesis_sand").to_dict()
    data["name"] = "adversary"
    data["missing"] = {}
    parts = entry.split(".")
    if entry in ("name", "description"):
        data[entry] = value
    elif len(parts) == 1:
        data["medium"][entry] = {"value": value, "source": "adversary"}
    elif len(parts) == 2:
        data["terms"].setdefault(parts[0], {})[parts[1]] = {"value": value, "source": "s"}
    else:
        data["terms"][parts[0]][parts[1]][parts[2]] = value

    def build() -> Any:
        card = media.MediumCard.from_dict(data)
        scene = Scene(medium=card, forces=[forces.gravity(), forces.rft(elements=2)])
        return run(scene)

    return Case("medium", entry, value, build, names=(entry, *parts))


GENERATORS: dict[str, Callable[[Pick], Case]] = {
    "scene": scene_case,
    "case": case_case,
    "term": term_case,
    "element": element_case,
    "sweep": sweep_case,
    "toml": toml_case,
    "space": space_case,
    "medium": medium_case,
}


# --------------------------------------------------------------------------------------
# The property


def outcome(case: Case) -> str:
    """``"ok"`` (it ran to finite results), ``"typed:<class>"`` (a typed error naming the
    field), or ``"FAIL: ..."`` (anything else)."""
    try:
        result = case.build()
    except GranrsError as e:
        if isinstance(e, SimulationError):
            return f"typed:{type(e).__name__}"
        text = f"{e} {getattr(e, 'field', '') or ''}"
        names = (case.field.split(".")[-1], case.field, *case.names)
        if (case.loose and getattr(e, "field", None)) or any(n in text for n in names):
            return f"typed:{type(e).__name__}"
        return f"FAIL: {type(e).__name__} does not name {case.field}: {e}"
    except BaseException as e:  # a PanicException derives from BaseException
        if isinstance(e, KeyboardInterrupt):
            raise
        return f"FAIL: {type(e).__name__}: {e}"
    if hasattr(result, "summary") and not finite(result):
        return f"FAIL: non-finite results {result.summary}"
    return "ok"


def draw_case(rng: random.Random) -> Case:
    def pick(options: Sequence[Any], label: str) -> Any:
        return options[rng.randrange(len(options))]

    return GENERATORS[pick(list(GENERATORS), "target")](pick)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=2000, help="inputs to try (2000)")
    ap.add_argument("--seed", type=int, default=0, help="random seed (0)")
    args = ap.parse_args(argv)
    rng = random.Random(args.seed)
    counts: collections.Counter[str] = collections.Counter()
    by_target: collections.Counter[str] = collections.Counter()
    failures: list[str] = []
    t0 = time.perf_counter()
    for _ in range(args.n):
        case = draw_case(rng)
        got = outcome(case)
        by_target[case.target] += 1
        if got.startswith("FAIL"):
            failures.append(f"{case.target} {case.field} = {case.value!r}: {got}")
            counts["anything else"] += 1
        else:
            counts[got] += 1
    elapsed = time.perf_counter() - t0
    print(f"inputs tried: {args.n} (seed {args.seed}, {elapsed:.1f} s)")
    print("by target: " + ", ".join(f"{k} {v}" for k, v in sorted(by_target.items())))
    typed = {k: v for k, v in counts.items() if k.startswith("typed:")}
    print(f"typed errors: {sum(typed.values())}")
    for k, v in sorted(typed.items(), key=lambda kv: -kv[1]):
        print(f"  {k.removeprefix('typed:')}: {v}")
    print(f"runs ok: {counts['ok']}")
    print(f"anything else: {len(failures)}")
    for f in failures[:50]:
        print(f"  {f}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
