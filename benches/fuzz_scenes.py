"""Fuzz the scene loaders (issue 6): random and mutated inputs, no crash.

Three targets, taken in turn:

- ``toml``: TOML texts into :func:`granrs.scenefile.loads`: the templates of every body and
  dumps of random scenes, mutated (a value replaced by a random TOML value, a line deleted,
  duplicated or cut, a key renamed, bytes inserted or flipped, tables added), and random
  texts;
- ``dict``: scene dicts into ``granrs._granrs.validate`` (the Rust core's conversion and
  checks): ``Scene.to_dict()`` of every body with fields replaced by random Python values
  (NaN, infinities, huge ints, strings, bytes, lists, nested dicts, None, bools, objects),
  deleted, or unknown keys added;
- ``kw``: keyword sets into ``granrs.Scene(**kw)`` followed by ``.validate()``.

Accepted outcomes: the input loads, or a :class:`granrs.errors.GranrsError` subclass (the
documented errors for bad input). ``TypeError`` is accepted from the ``kw`` target only:
``Scene(**kw)`` with an unknown keyword, and ``Coefficients(**mapping)`` with a missing
key, are Python's own dataclass-constructor errors. Anything else is a failure and is
printed with its input: PanicException (a Rust panic), SystemError, any other exception,
or an input that takes longer than ``--timeout`` seconds (a hang). A segfault kills the
process (faulthandler prints where); tests/test_input_everywhere.py runs a short fuzz in a
subprocess for that reason.

Usage::

    python benches/fuzz_scenes.py --n 100000 [--seed 0] [--timeout 5]

Prints the counts per outcome and target, the elapsed time and ``failures: N``; exits 1
if there was any failure.
"""

from __future__ import annotations

import argparse
import collections
import faulthandler
import math
import pathlib
import random
import signal
import string
import sys
import time
from typing import Any

import granrs
from granrs import Scene, _granrs, cases, forces, scenefile
from granrs.bodies import Contact, Joint, Link, Linkage, Root
from granrs.errors import GranrsError

C_LEG = pathlib.Path(__file__).parent.parent / "examples" / "scenes" / "c_leg_rft.toml"
FIELDS = [
    name
    for name in Scene.__dataclass_fields__  # every Scene field
]
JOINT_FIELDS = ("pin_joint", "ankle", "knee", "hip")
NAMES = (
    "free_link chain leg tip centroid modes raw smooth rk4 dopri5 first_stop all_stops time "
    "state forces energy gravity drag static_h static_v joint_springs free locked box thesis "
    "rft rft_inertial poncelet axial_drag eta_a zeta elements c k A00 Bm11 driven table arc "
    "radius start_deg end_deg chords rate pinned moving medium thesis_sand thesis_fine_sand "
    "li2013_generic"
).split()


class Hang(Exception):
    """An input took longer than the time limit."""


def _alarm(signum: int, frame: Any) -> None:
    raise Hang()


# ---------------------------------------------------------------------------------------
# Random values


def rand_float(rng: random.Random) -> float:
    return rng.choice(
        [
            0.0,
            -0.0,
            1.0,
            -1.0,
            math.nan,
            math.inf,
            -math.inf,
            1e308,
            -1e308,
            5e-324,
            1e-300,
            89.999999,
            90.0,
            -90.0,
            rng.uniform(-1e3, 1e3),
            rng.uniform(-1.0, 1.0),
            10.0 ** rng.uniform(-12, 12),
            -(10.0 ** rng.uniform(-12, 12)),
        ]
    )


def rand_py(rng: random.Random, depth: int = 0) -> Any:
    """A random Python value of any type a user might pass."""
    kind = rng.randrange(14 if depth < 2 else 9)
    if kind == 0:
        return rand_float(rng)
    if kind == 1:
        return rng.choice([0, 1, -1, 2, 10**6, 10**30, -(10**30), 2**63, 2**64 + 1, 10**400])
    if kind == 2:
        return rng.choice(NAMES)
    if kind == 3:
        return "".join(rng.choice(string.printable) for _ in range(rng.randrange(0, 12)))
    if kind == 4:
        return rng.choice([True, False])
    if kind == 5:
        return None
    if kind == 6:
        return rng.choice([b"tip", bytearray(b"x"), 1j, object(), float, ...])
    if kind == 7:
        return rng.choice(["\x00", "\ud800", "é", "1e5", "nan", "", " "])
    if kind == 8:
        return rng.choice([(), [], {}, set(), frozenset()])
    if kind == 9:
        return [rand_py(rng, depth + 1) for _ in range(rng.randrange(0, 4))]
    if kind == 10:
        return tuple(rng.choice(NAMES) for _ in range(rng.randrange(0, 4)))
    if kind == 11:
        keys = rng.choice(
            [["k", "c"], ["k"], ["eta_h", "eta_d", "eta_v", "lam"], ["eta_h", "lambda"], ["x"]]
        )
        return {k: rand_py(rng, depth + 1) for k in keys}
    if kind == 12:
        return {rand_key(rng): rand_py(rng, 2)}
    return [rand_float(rng) for _ in range(rng.randrange(1, 4))]


def rand_key(rng: random.Random) -> Any:
    """A random dict key: usually a field name, else any hashable value."""
    if rng.random() < 0.7:
        return rng.choice(FIELDS)
    return rng.choice([rand_float(rng), 3, None, True, "", "x", ("q_deg",), b"mass", "lenght"])


def rand_toml_value(rng: random.Random) -> str:
    """A random TOML value (valid or not)."""
    kind = rng.randrange(12)
    if kind == 0:
        return rng.choice(["nan", "inf", "-inf", "+inf", "1e400", "-0.0", "0", "1_000", "0x10"])
    if kind == 1:
        return repr(rand_float(rng)).replace("nan", "nan").replace("inf", "inf")
    if kind == 2:
        return str(rng.choice([0, 1, -1, 10**30, 2**63, -(2**63) - 1, 10**19]))
    if kind == 3:
        return f'"{rng.choice(NAMES)}"'
    if kind == 4:
        return rng.choice(["true", "false"])
    if kind == 5:
        return rng.choice(["1979-05-27", "07:32:00", "1979-05-27T07:32:00Z"])
    if kind == 6:
        return "[" + ", ".join(rand_toml_value(rng) for _ in range(rng.randrange(0, 3))) + "]"
    if kind == 7:
        keys = rng.choice([["k", "c"], ["k"], ["eta_h", "eta_d", "eta_v", "lam"], ["q"]])
        return "{ " + ", ".join(f"{k} = {rand_toml_value(rng)}" for k in keys) + " }"
    if kind == 8:
        return f'"{"".join(rng.choice(string.ascii_letters) for _ in range(rng.randrange(6)))}"'
    if kind == 9:
        return rng.choice(['"\\u0000"', "'''a\nb'''", '"""x"""', "'lit'"])
    if kind == 10:
        return "".join(rng.choice("=[]{}\"',.#\n0123456789e+-") for _ in range(rng.randrange(1, 6)))
    return f"{rng.uniform(-1000, 1000)!r}"


# ---------------------------------------------------------------------------------------
# Inputs


def base_scenes() -> list[Scene]:
    return [
        cases.free_link(30.0, 2.0),
        cases.chain(case=2),
        cases.leg(v0=2.35, joints={"k": 300.0, "c": 5.0}),
        Scene(body="chain", pin_joint={"k": 1.0, "c": 0.1}, record=("state",)),
        Scene(method="dopri5", sign_model="smooth", end="time"),
        # Force terms as [[forces]] tables, per contact on the chain (issue 16).
        cases.free_link(45.0, 1.0, forces=[forces.gravity(), forces.static_v(eta_v=100.0)]),
        cases.chain(
            case=1, forces=[forces.gravity(), forces.drag(eta_d=(13.0, 10.0)), forces.static_h()]
        ),
        cases.leg(v0=3.28, forces=[]),
        # The field's laws (issue 17), on each body.
        cases.free_link(30.0, 2.0, forces=[forces.gravity(), forces.rft(zeta=1e6, elements=4)]),
        cases.chain(case=2, forces=[forces.gravity(), forces.poncelet(c=1.0, k=100.0)]),
        cases.free_link(
            30.0,
            2.0,
            forces=[
                forces.gravity(),
                forces.axial_drag(eta_a=6.0),
                *forces.select(forces.thesis(), "static_h", "static_v"),
            ],
        ),
        cases.leg(
            v0=2.0,
            forces=[forces.gravity(), forces.rft(zeta=1e6, elements=2), forces.rft_inertial()],
        ),
        # A linkage with a joint driven along a table (issue 19).
        Scene(
            body=Linkage(
                [Link("a", 1.0, 0.01, 0.3, (-0.15, 0.0)), Link("b", 0.5, 0.002, 0.2, (-0.1, 0.0))],
                [
                    Joint(
                        "j", "a", "b", (-0.3, 0.0), kind="driven", table=((0.0, 0.0), (0.01, 20.0))
                    )
                ],
                [Contact.rod("b", 0.2, 0.0127, at=(-0.2, 0.0))],
                Root("moving", link="a", position=(0.0, 0.5), velocity=(0.0, -1.0)),
            ),  # type: ignore[arg-type]
            end="time",
            t_end=0.02,
        ),
        # An arc contact on a driven root (issue 19): the C-leg scene file.
        scenefile.load(C_LEG).replace(t_end=0.05),
    ]


def mutate_toml(rng: random.Random, text: str) -> str:
    lines = text.splitlines()
    for _ in range(rng.randrange(1, 4)):
        op = rng.randrange(9)
        i = rng.randrange(len(lines)) if lines else 0
        if op == 0 and lines:  # replace a value
            key, sep, _ = lines[i].partition("=")
            if sep:
                lines[i] = f"{key}= {rand_toml_value(rng)}"
        elif op == 1 and lines:
            del lines[i]
        elif op == 2 and lines:
            lines.insert(i, lines[i])
        elif op == 3 and lines:
            lines[i] = lines[i][: rng.randrange(len(lines[i]) + 1)]
        elif op == 4:
            lines.insert(
                i, f"{rng.choice([*FIELDS, 'format', 'x', 'eta_h'])} = {rand_toml_value(rng)}"
            )
        elif op == 5 and lines:  # rename a key
            key, sep, rest = lines[i].partition("=")
            if sep:
                lines[i] = f"{rng.choice(FIELDS)}{rng.choice(['', 'x', '.k', '2'])} ={rest}"
        elif op == 6:
            lines.insert(
                i,
                rng.choice(
                    [
                        *("[coefficients]", "[coefficients2]", "[knee]", "[[q_deg]]", "[x.y]"),
                        *("[[forces]]", 'term = "drag"', 'term = "stati_v"', "eta_d = [1.0]"),
                        *('term = "rft"', 'term = "poncelet"', "elements = 0", "zeta = -1"),
                        *('term = "axial_drag"', "eta_a = 6.0", "eta_a = -1"),
                    ]
                ),
            )
        elif op == 7 and lines:  # insert or flip characters
            line = lines[i]
            j = rng.randrange(len(line) + 1)
            lines[i] = line[:j] + rng.choice(string.printable + "\x00é\u2028") + line[j + 1 :]
        elif op == 8:
            lines.append(f"format = {rand_toml_value(rng)}")
    return "\n".join(lines) + rng.choice(["\n", "", "\r\n"])


def random_text(rng: random.Random) -> str:
    parts = []
    for _ in range(rng.randrange(1, 8)):
        parts.append(f"{rng.choice([*FIELDS, 'format', 'zz'])} = {rand_toml_value(rng)}")
    if rng.random() < 0.3:
        parts.append("".join(rng.choice(string.printable) for _ in range(rng.randrange(20))))
    return "\n".join(parts) + "\n"


def toml_input(rng: random.Random, texts: list[str]) -> str:
    if rng.random() < 0.8:
        return mutate_toml(rng, rng.choice(texts))
    return random_text(rng)


def dict_input(rng: random.Random, dicts: list[dict[str, Any]]) -> dict[Any, Any]:
    d = dict(rng.choice(dicts))
    if rng.random() < 0.05:
        return {rand_key(rng): rand_py(rng) for _ in range(rng.randrange(5))}
    for _ in range(rng.randrange(1, 4)):
        op = rng.randrange(5)
        if op <= 2:
            d[rng.choice(FIELDS)] = rand_py(rng)
        elif op == 3 and d:
            del d[rng.choice(list(d))]
        else:
            d[rng.choice(["x", "lenght", "eta_h", "", "body "])] = rand_py(rng)
    return d


def kw_input(rng: random.Random) -> dict[str, Any]:
    kw: dict[str, Any] = {}
    if rng.random() < 0.5:
        kw["body"] = rng.choice(["free_link", "chain", "leg"])
    for _ in range(rng.randrange(1, 4)):
        name = rng.choice(FIELDS) if rng.random() < 0.95 else rng.choice(["x", "lenght"])
        kw[name] = rand_py(rng)
    return kw


# ---------------------------------------------------------------------------------------
# Running


def run_one(target: str, value: Any) -> None:
    if target == "toml":
        scenefile.loads(value, source="fuzz.toml")
    elif target == "dict":
        _granrs.validate(value)
    else:
        Scene(**value).validate()


def accepted(target: str, exc: BaseException) -> bool:
    if isinstance(exc, GranrsError):
        return True
    return target == "kw" and type(exc) is TypeError


def fuzz(n: int, seed: int, timeout: float, verbose: bool = True) -> int:
    rng = random.Random(seed)
    scenes = base_scenes()
    texts = [cases.template(b) for b in ("free_link", "chain", "leg")]
    texts += [scenefile.dumps(s) for s in scenes]
    dicts = [s.to_dict() for s in scenes]
    counts: collections.Counter[tuple[str, str]] = collections.Counter()
    failures = 0
    signal.signal(signal.SIGALRM, _alarm)
    t0 = time.perf_counter()
    for i in range(n):
        target = ("toml", "dict", "kw")[i % 3]
        if target == "toml":
            value: Any = toml_input(rng, texts)
        elif target == "dict":
            value = dict_input(rng, dicts)
        else:
            value = kw_input(rng)
        signal.setitimer(signal.ITIMER_REAL, timeout)
        try:
            run_one(target, value)
            outcome = "ok"
        except BaseException as exc:  # every escape is classified
            signal.setitimer(signal.ITIMER_REAL, 0)
            if isinstance(exc, KeyboardInterrupt):
                raise
            outcome = type(exc).__name__
            if isinstance(exc, Hang) or not accepted(target, exc):
                failures += 1
                kind = "hang" if isinstance(exc, Hang) else f"{type(exc).__module__}.{outcome}"
                print(f"FAILURE {kind} [{target} #{i}]: {exc!r}\n  input: {value!r}"[:4000])
                outcome = f"FAILURE {outcome}"
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
        counts[(target, outcome)] += 1
    elapsed = time.perf_counter() - t0
    if verbose:
        print(
            f"granrs {granrs.__version__}: {n} inputs, seed {seed}, {elapsed:.1f} s "
            f"({1e6 * elapsed / max(n, 1):.0f} us per input)"
        )
        print(f"{'target':<6} {'outcome':<28} {'count':>8}")
        for (target, outcome), count in sorted(counts.items()):
            print(f"{target:<6} {outcome:<28} {count:>8}")
        print(f"failures: {failures}")
    return failures


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--n", type=int, default=100_000, help="number of inputs (100000)")
    parser.add_argument("--seed", type=int, default=0, help="random seed (0)")
    parser.add_argument("--timeout", type=float, default=5.0, help="seconds per input (5)")
    args = parser.parse_args(argv)
    faulthandler.enable()
    return 1 if fuzz(args.n, args.seed, args.timeout) else 0


if __name__ == "__main__":
    sys.exit(main())
