"""The report's framework: the chapter registry (:data:`CHAPTERS`,
:func:`register_chapter`), what a chapter works with (:class:`ReportContext`), and
:func:`reproduce`, which runs the chapters asked for and writes the report.

It never imports a chapter: the chapters import it and register themselves, and the
package (:mod:`granrs.report`) imports them in report order.
"""

from __future__ import annotations

import os
import platform
import shutil
import sys
import tempfile
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

from .. import __version__, cases
from .._files import write_bytes
from .._progress import progress_bar
from ..api import simulate
from ..errors import InvalidParameterError, UnknownNameError
from ..result import Result
from ..scene import Scene

__all__ = [
    "CHAPTERS",
    "FIGURES_DIR",
    "REPORT_NAME",
    "Chapter",
    "ChapterBuilder",
    "ReportContext",
    "register_chapter",
    "reproduce",
]

#: The file name of the report inside the output directory.
REPORT_NAME = "README.md"
#: The folder of the figures inside the output directory.
FIGURES_DIR = "figures"

ChapterBuilder = Callable[["ReportContext"], str]
#: The resolution of the report's animations [dots per inch]: their smallest text (8 pt)
#: is 10 px high, and the narrowest is 648 px wide (granrs.animate's figures are at least
#: 7.2 in wide).
WATCH_DPI = 90.0


@dataclass(frozen=True)
class Chapter:
    """A chapter of the report.

    Attributes:
        key: the name used to ask for it (``"3"``).
        title: its heading, e.g. ``"Chapter 3: the free link"``.
        build: the function that runs it and returns its Markdown (headings from ``##``).
    """

    key: str
    title: str
    build: ChapterBuilder


#: The chapters :func:`reproduce` knows, by key, in registration order.
CHAPTERS: dict[str, Chapter] = {}


def register_chapter(key: str, title: str) -> Callable[[ChapterBuilder], ChapterBuilder]:
    """Decorator: register ``build`` as the chapter ``key`` of the report."""

    def decorator(build: ChapterBuilder) -> ChapterBuilder:
        """Register ``build`` and return it unchanged."""
        if key in CHAPTERS:
            raise ValueError(f"chapter {key!r} is already registered")
        CHAPTERS[key] = Chapter(key=key, title=title, build=build)
        return build

    return decorator


@dataclass
class ReportContext:
    """What a chapter works with: the run settings, and where its outputs go.

    Attributes:
        dt: the integration step of every scene [s].
        progress: whether to print progress lines (to stderr).
        figures: PNG bytes by file name (relative to ``figures/``), filled by
            :meth:`add_figure`.
        headlines: one-line findings for the report's summary, filled by
            :meth:`add_headline`.
        runs: the number of simulations run so far.
        sim_seconds: wall time spent in :func:`granrs.simulate` [s].
        settings: every (sign model, point of application) pair that was run.
        files: other files by name (relative to the output directory, e.g. a chapter's
            ``laws.json``), filled by :meth:`add_file`.
    """

    dt: float
    progress: bool = True
    figures: dict[str, bytes] = field(default_factory=dict)
    headlines: list[str] = field(default_factory=list)
    runs: int = 0
    sim_seconds: float = 0.0
    settings: set[tuple[str, str]] = field(default_factory=set)
    files: dict[str, bytes] = field(default_factory=dict)

    def log(self, message: str) -> None:
        """Print one progress line to stderr (nothing when ``progress`` is False)."""
        if self.progress:
            # Through tqdm, so that a line does not break the chapters' bar on a terminal.
            tqdm.write(f"granrs reproduce: {message}", file=sys.stderr)

    @contextmanager
    def step(self, label: str) -> Iterator[None]:
        """Time a step of a chapter and log ``label`` with its run count and duration."""
        runs, start = self.runs, time.perf_counter()
        yield
        n = self.runs - runs
        what = f"{n} run{'s' if n != 1 else ''}, " if n else ""
        self.log(f"{label} ({what}{time.perf_counter() - start:.2f} s)")

    def run(self, scene: Scene) -> Result:
        """Simulate ``scene`` and count it."""
        start = time.perf_counter()
        result = simulate(scene)
        self.sim_seconds += time.perf_counter() - start
        self.runs += 1
        self.settings.add((scene.sign_model, scene.apply_at))
        return result

    def free_link(self, q_deg: float, v0: float, **kwargs: Any) -> Result:
        """Run :func:`granrs.cases.free_link` at the context's ``dt``."""
        return self.run(cases.free_link(q_deg=q_deg, v0=v0, dt=self.dt, **kwargs))

    def chain(self, case: int, **kwargs: Any) -> Result:
        """Run :func:`granrs.cases.chain` case ``case`` at the context's ``dt``, until both
        links have stopped (``end="all_stops"`` unless ``kwargs`` says otherwise)."""
        kwargs.setdefault("end", "all_stops")
        return self.run(cases.chain(case=case, dt=self.dt, **kwargs))

    def leg(self, v0: float, **kwargs: Any) -> Result:
        """Run :func:`granrs.cases.leg` at ``v0`` [m/s] and the context's ``dt``."""
        return self.run(cases.leg(v0=v0, dt=self.dt, **kwargs))

    def add_figure(self, name: str, png: bytes, alt: str) -> str:
        """Keep the PNG ``png`` as ``figures/name``; return its Markdown image link."""
        if name in self.figures:
            raise ValueError(f"figure {name!r} was added twice")
        self.figures[name] = png
        self.log(f"figure {FIGURES_DIR}/{name}")
        return f"![{alt}]({FIGURES_DIR}/{name})"

    def add_file(self, name: str, content: bytes) -> str:
        """Keep ``content`` to be written as ``name`` in the output directory (next to the
        report, replaced like it); return the name."""
        if name in self.files or name == REPORT_NAME or "/" in name or name == FIGURES_DIR:
            raise ValueError(f"file {name!r} was added twice or is reserved")
        self.files[name] = content
        self.log(f"file {name}")
        return name

    def watch(self, name: str, scene: Scene, caption: str, frame_dt: float) -> str:
        """A chapter's "Watch it" section: run ``scene`` recording its state and forces,
        keep its animation (:func:`granrs.animate`, one frame per ``frame_dt`` of simulated
        time) as the GIF ``figures/name``, and return the section: a heading, ``caption``
        and the image (one animation per chapter)."""
        import tempfile

        from .._animation import animate

        with self.step(f"{name}: an animation"):
            result = self.run(scene.replace(record=("state", "forces")))
            with tempfile.TemporaryDirectory() as tmp:
                path = Path(tmp) / name
                animate(result, frame_dt=frame_dt, fps=10.0, dpi=WATCH_DPI, out=path)
                gif = path.read_bytes()
        link = self.add_figure(name, gif, caption)
        return f"### Watch it\n\n{caption}\n\n{link}\n"

    def add_headline(self, text: str) -> None:
        """Add a one-line finding to the report's summary."""
        self.headlines.append(text)


# --------------------------------------------------------------------------------------
# The report
# --------------------------------------------------------------------------------------


def _anchor(title: str) -> str:
    """The GitHub heading anchor of ``title``."""
    kept = "".join(c for c in title.lower() if c.isalnum() or c in " -_")
    return kept.replace(" ", "-")


def _header(ctx: ReportContext, chapters: Sequence[Chapter], dt: float, seconds: float) -> str:
    """The report's header: what was run, how to reproduce, summary, contents."""
    settings = sorted(ctx.settings)
    sign_models = ", ".join(sorted({s for s, _ in settings})) or "n/a"
    apply_at = ", ".join(sorted({a for _, a in settings})) or "n/a"
    date = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    chapter_args = "".join(f" --chapter {c.key}" for c in chapters)
    chapter_keys = repr(tuple(c.key for c in chapters)).replace("'", '"')
    contents = "\n".join(f"- [{c.title}](#{_anchor(c.title)})" for c in chapters)
    headlines = "\n".join(f"- {h}" for h in ctx.headlines) or "- (no findings)"
    return f"""# granrs reproduction report

granrs reproduces the simulations of the thesis "Bipedal impact with granular matter": a
resistance force of dynamic drag plus static depth-dependent terms acting on rods sinking
into sand. This report runs the thesis's cases and sets the results beside its tables.

## What was run

- granrs {__version__} (Python {platform.python_version()}, numpy {np.__version__},
  {platform.system()} {platform.machine()}), generated {date}
- chapters: {", ".join(c.key for c in chapters)}
- integrator: fixed-step RK4 with located events, dt = {dt:g} s ({1.0 / dt:g} Hz; the
  thesis ran at 10 kHz)
- sign model of the static terms: {sign_models}
- point of application of the resistance force: {apply_at} (the thesis's CAD runs, sec.
  3.3.2)
- {ctx.runs} simulations in {ctx.sim_seconds:.2f} s ({seconds:.1f} s with figures)
- reference numbers: the thesis's tables as shipped in `granrs.data` (see
  `granrs.data.provenance(name)`), and a few values the thesis gives only in its text
  (cited where used); nothing is edited to fit
- relative errors: the thesis's eq. 3.21, ε = |reference - granrs| / |reference|

## How to reproduce

```sh
granrs reproduce --out DIR --dt {dt:g}{chapter_args}
```

or, from Python, `granrs.report.reproduce("DIR", chapters={chapter_keys}, dt={dt:g})`.

## Summary and known gaps

{headlines}

## Contents

{contents}
"""


def _validate_out_dir(out_dir: Path, files: Sequence[str] = ()) -> None:
    """Reject an output path that exists and is not a directory, or in which the report,
    the ``figures`` folder or one of ``files`` exists as the wrong kind (a folder where the
    report goes, a file where the figures go): field ``out_dir``, nothing touched."""
    if out_dir.exists() and not out_dir.is_dir():
        raise InvalidParameterError(
            f"the output directory {str(out_dir)!r} exists and is not a directory",
            field="out_dir",
        )
    if not out_dir.is_dir():
        return
    for name in (FIGURES_DIR, REPORT_NAME, *files):
        path = out_dir / name
        want_dir = name == FIGURES_DIR
        if path.exists() and path.is_dir() != want_dir:
            raise InvalidParameterError(
                f"cannot write the report to {str(out_dir)!r}: {name} there is "
                f"{'not a directory' if want_dir else 'a directory'}; move it away",
                field="out_dir",
            )


def _write(
    out_dir: Path,
    report: str,
    figures: Mapping[str, bytes],
    files: Mapping[str, bytes] | None = None,
) -> Path:
    """Write the report and figures to a temporary directory, then move them into place,
    all or nothing.

    A new ``out_dir`` is created by one rename. In an existing ``out_dir`` the report file,
    the chapters' other ``files`` and the ``figures`` folder are replaced (the old folder is
    removed); other files are left alone. Every target is checked first
    (:func:`_validate_out_dir`); the old ones are moved aside, the new ones in, and if a
    move fails those done are undone, so that an error leaves ``out_dir`` as it was.
    """
    out_dir = out_dir.absolute()
    files = dict(files or {})
    _validate_out_dir(out_dir, tuple(files))
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.tmp-", dir=out_dir.parent))
    try:
        # mkdtemp's folder is private (0700); the report folder gets the usual umask.
        new = staging / "report"
        (new / FIGURES_DIR).mkdir(parents=True)
        for name, png in figures.items():
            write_bytes(new / FIGURES_DIR / name, png)
        write_bytes(new / REPORT_NAME, report.encode("utf-8"))
        for name, content in files.items():
            write_bytes(new / name, content)
        if not out_dir.exists():
            os.replace(new, out_dir)
            return out_dir / REPORT_NAME
        old = staging / "old"
        old.mkdir()
        _swap(out_dir, new, old, (FIGURES_DIR, *files, REPORT_NAME))
        return out_dir / REPORT_NAME
    finally:
        shutil.rmtree(staging, ignore_errors=True)


def _swap(out_dir: Path, new: Path, old: Path, names: Sequence[str]) -> None:
    """Move each of ``names`` from ``new`` into ``out_dir``, the one it replaces into
    ``old`` first; on an error undo every move made, in reverse order, and re-raise."""
    done: list[tuple[Path, Path]] = []
    try:
        for name in names:
            target = out_dir / name
            if target.exists() or target.is_symlink():
                os.replace(target, old / name)
                done.append((target, old / name))
            os.replace(new / name, target)
            done.append((new / name, target))
    except BaseException:
        for source, moved_to in reversed(done):
            os.replace(moved_to, source)
        raise


def reproduce(
    out_dir: str | os.PathLike[str],
    *,
    chapters: Sequence[str] | None = None,
    dt: float = 1e-4,
    progress: bool = True,
) -> Path:
    """Run the thesis's cases and write the reproduction report; return its path.

    Writes ``out_dir/README.md`` (Markdown) and its PNG figures in ``out_dir/figures/``.
    Everything is computed in memory before anything is written, and the files are moved
    into place at the end, all or nothing, so an error leaves ``out_dir`` as it was (a new
    ``out_dir`` is not created). In an existing ``out_dir`` the report and the ``figures``
    folder are replaced.

    Args:
        out_dir: the output directory (created if missing).
        chapters: the keys of the chapters to run, from :data:`CHAPTERS` (``"3"``: the free
            link, ``"4"``: the two-link chain, ``"5"``: the leg); None (the default) runs
            every chapter, as the command line does.
        dt: the integration step of every scene [s]; an invalid one raises the scene's
            :class:`~granrs.errors.InvalidParameterError` (``field="dt"``).
        progress: print one line per table and figure to stderr, and on a terminal a bar
            of the chapters done.

    Returns:
        The path of the report, ``out_dir/README.md``.

    Raises:
        UnknownNameError: an unknown chapter (``field="chapters"``).
        InvalidParameterError: an invalid ``dt`` (``field="dt"``), or an ``out_dir`` that is
            a file or holds a folder named ``README.md`` or a file named ``figures``
            (``field="out_dir"``), before any run.
    """
    out_path = Path(out_dir)
    if chapters is None:
        chapters = tuple(CHAPTERS)
    elif isinstance(chapters, str):
        chapters = (chapters,)
    selected = []
    for key in chapters:
        if key not in CHAPTERS:
            raise UnknownNameError(
                f"unknown chapter {key!r}; available: {', '.join(CHAPTERS)}", field="chapters"
            )
        selected.append(CHAPTERS[key])
    if not selected:
        raise InvalidParameterError("no chapter selected", field="chapters")
    # The step is checked by a scene, the same rule every run uses (field "dt").
    cases.free_link(q_deg=0.0, v0=1.0, dt=dt)
    _validate_out_dir(out_path)

    start = time.perf_counter()
    ctx = ReportContext(dt=dt, progress=progress)
    bodies = []
    # A bar of the chapters on a terminal (stderr), beside the lines of each table and figure.
    bar = progress_bar(len(selected), None if progress else False, "granrs reproduce", "chapter")
    try:
        for chapter in selected:
            ctx.log(f"{chapter.title}")
            bodies.append(f"## {chapter.title}\n\n{chapter.build(ctx).strip()}\n")
            bar.update(1)
    finally:
        bar.close()
    seconds = time.perf_counter() - start
    report = _header(ctx, selected, dt, seconds) + "\n" + "\n".join(bodies)
    path = _write(out_path, report, ctx.figures, ctx.files)
    ctx.log(f"wrote {path} and {len(ctx.figures)} figures in {seconds:.1f} s")
    return path
